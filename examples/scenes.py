"""Small scenes built from scratch with the data API (no operators, so they work headless).

``build_demo_scene(scene)`` fills a scene with a checkered floor, a few coloured spheres and boxes,
a glowing sphere, an area light and a camera, and returns the camera object. Lengths are in metres.
"""

import bmesh
import bpy
from mathutils import Vector

from relativity_addon.blender.common import compat

# Colours are linear Rec.709 base colours.
RED = (0.8, 0.06, 0.05)
GREEN = (0.08, 0.6, 0.12)
BLUE = (0.05, 0.15, 0.8)
YELLOW = (0.85, 0.65, 0.05)


def _link(scene, name, mesh, material, location):
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def _mesh_from_bmesh(name, build):
    bm = bmesh.new()
    build(bm)
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    return mesh


def principled_material(name, base_color, roughness=0.4):
    material = bpy.data.materials.new(name)
    compat.material_node_tree(material)
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base_color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    return material


def checker_material(name, color1=(0.8, 0.8, 0.8), color2=(0.05, 0.05, 0.05), scale=10.0):
    """Diffuse checkerboard in generated coordinates: ``scale`` squares across the object."""
    material = principled_material(name, color1, roughness=0.8)
    nodes, links = material.node_tree.nodes, material.node_tree.links
    checker = nodes.new("ShaderNodeTexChecker")
    checker.inputs["Color1"].default_value = (*color1, 1.0)
    checker.inputs["Color2"].default_value = (*color2, 1.0)
    checker.inputs["Scale"].default_value = scale
    links.new(checker.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return material


def emission_material(name, color, strength):
    """Emission only; ``strength`` in W/m^2 as Blender's Emission node defines it."""
    material = bpy.data.materials.new(name)
    compat.material_node_tree(material)
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*color, 1.0)
    emission.inputs["Strength"].default_value = strength
    links.new(emission.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    return material


def add_floor(scene, size=20.0, squares=20):
    mesh = _mesh_from_bmesh("Floor", lambda bm: bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=size / 2))
    return _link(scene, "Floor", mesh, checker_material("Checker", scale=squares), (0.0, 0.0, 0.0))


def add_sphere(scene, name, location, radius, material):
    mesh = _mesh_from_bmesh(
        name,
        lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=radius),
    )
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    return _link(scene, name, mesh, material, location)


def add_box(scene, name, location, size, material):
    mesh = _mesh_from_bmesh(name, lambda bm: bmesh.ops.create_cube(bm, size=size))
    return _link(scene, name, mesh, material, location)


def add_area_light(scene, location, power_w=800.0, size=3.0):
    light = bpy.data.lights.new("Key", type="AREA")
    light.energy = power_w
    light.size = size
    obj = bpy.data.objects.new("Key", light)
    obj.location = location
    aim(obj, Vector((0.0, 0.0, 0.0)))
    scene.collection.objects.link(obj)
    return obj


def aim(obj, target):
    """Point an object's local -Z (the view direction of cameras and lights) at ``target``."""
    direction = Vector(target) - Vector(obj.location)
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def add_camera(scene, location, target, lens_mm=28.0):
    camera = bpy.data.cameras.new("Camera")
    camera.lens = lens_mm
    obj = bpy.data.objects.new("Camera", camera)
    obj.location = location
    aim(obj, target)
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


def set_world_color(scene, color, strength=1.0):
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    compat.world_node_tree(world)
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    return world


def build_demo_scene(scene):
    """Fill ``scene`` with the demo content and make its camera active; return the camera object."""
    add_floor(scene)
    add_sphere(scene, "Red sphere", (-1.6, 0.6, 0.7), 0.7, principled_material("Red", RED))
    add_sphere(scene, "Green sphere", (0.2, 1.6, 0.9), 0.9, principled_material("Green", GREEN, 0.2))
    add_sphere(scene, "Blue sphere", (1.9, -0.2, 0.5), 0.5, principled_material("Blue", BLUE))
    add_box(scene, "Yellow box", (0.2, -1.2, 0.4), 0.8, principled_material("Yellow", YELLOW))
    add_sphere(scene, "Lamp", (1.4, -2.4, 0.3), 0.3, emission_material("Glow", (1.0, 0.55, 0.2), 20.0))
    add_area_light(scene, (3.0, -3.0, 5.0))
    set_world_color(scene, (0.05, 0.07, 0.1))
    return add_camera(scene, (6.0, -6.5, 3.2), (0.0, 0.3, 0.5))
