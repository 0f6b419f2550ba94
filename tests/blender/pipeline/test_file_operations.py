"""File operations on a set-up scene (issue 25): after Remove the file equals the file before Set Up.

For both Methods (Apparent Geometry: a mesh with its own velocity, a lamp at rest, a material;
Exact Camera: the observer moving, a mesh with a material, a lamp) the whole file is dumped
(``scene_dump.py``: objects, meshes and attributes, materials and node trees, modifiers, cameras,
world, compositor, view layers, render settings, texts, images, node groups), set up, operated on
(delete, rename, duplicate, save and reopen with and without the add-on, undo, append and link),
then Remove is pressed and the file dumped again. The operation's own intended change is taken
back by hand before comparing (a renamed datablock renamed back, a duplicate deleted, a deleted
object left out), so every other difference is something the add-on left behind.

Undo works in the bpy module (``bpy.ops.ed.undo_push`` / ``ed.undo``, global memfile undo).
"""

import importlib

import pytest

import scene_dump
from blender_support import ADDON_MODULE, disable_addon, enable_addon
from pipeline_helpers import ch


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _build(bpy, method):
    """A tiny Cycles scene: camera at -Y looking at a cube with a diffuse material, a point lamp.
    Apparent Geometry: the cube moves at 0.5c along +X; Exact Camera: the observer does."""
    scene, camera = ch.new_scene(bpy, resolution=(32, 24), samples=2, location=(0.0, -8.0, 0.0))
    camera.rotation_euler = (1.5707963, 0.0, 0.0)
    camera.data.name = "CameraData"
    scene.relativity.speed_of_light = 10.0
    material = ch.diffuse_material(bpy, "Paint", (0.6, 0.4, 0.2))
    mesh = bpy.data.meshes.new("CubeMesh")
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(corners, [], faces)
    mesh.materials.append(material)
    cube = bpy.data.objects.new("Cube", mesh)
    scene.collection.objects.link(cube)
    light = bpy.data.lights.new("LampData", "POINT")
    light.energy = 2000.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (0.0, -6.0, 4.0)
    scene.collection.objects.link(lamp)
    scene.relativity.method = method
    if method == "GEOMETRY":
        cube.relativity.enabled = True
        cube.relativity.motion = "CONSTANT"
        cube.relativity.beta = (0.5, 0.0, 0.0)
    else:
        scene.relativity.beta = (0.5, 0.0, 0.0)
    bpy.context.view_layer.update()
    return scene


def _set_up(bpy):
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}


def _remove(bpy):
    assert bpy.ops.relativity.remove_all.poll(), "Remove is not available in a file holding the add-on's pieces"
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}


def _assert_same(before, after):
    lines = scene_dump.differences(before, after)
    assert not lines, f"{len(lines)} differences after Remove:\n" + "\n".join(lines[:40])


METHODS = ("GEOMETRY", "CAMERA")


@pytest.mark.parametrize("method", METHODS)
def test_set_up_then_remove_gives_the_file_back(relativity_addon, factory_blender, method):
    """The baseline of every operation below: nothing between Set Up and Remove."""
    bpy = factory_blender
    _build(bpy, method)
    before = scene_dump.dump(bpy)
    _set_up(bpy)
    assert scene_dump.differences(before, scene_dump.dump(bpy)), "Set Up changed nothing the dump sees"
    _remove(bpy)
    _assert_same(before, scene_dump.dump(bpy))
