"""Helpers for the workflow tests: small scenes, the batch script run as a user would, image reading.

Physics expectations are written out here from PHYSICS.md (aberration), independently of the add-on.
"""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parents[3]
RENDER_SCRIPT = REPO_ROOT / "examples" / "render.py"
FLYTHROUGH_SCRIPT = REPO_ROOT / "examples" / "flythrough.py"


def aberrate(k, beta):
    """PHYSICS.md: propagation direction k (scene frame) -> k' in the frame moving with beta."""
    k, beta = np.asarray(k, float), np.asarray(beta, float)
    b2 = beta @ beta
    gamma = 1.0 / math.sqrt(1.0 - b2)
    bhat = beta / math.sqrt(b2)
    return (k + (gamma - 1.0) * (bhat @ k) * bhat - gamma * beta) / (gamma * (1.0 - beta @ k))


def emission_material(bpy, name="Emitter", strength=1.0):
    material = bpy.data.materials.new(name)
    tree = material.node_tree
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = strength
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material


def add_sphere(bpy, scene, location, radius, material, name="Marker"):
    import bmesh

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def new_scene(bpy, resolution=(64, 48), samples=2, with_camera=True):
    """Cycles scene with a black world, an emissive sphere off-axis and (optionally) a camera at
    the origin looking down -Z. Returns (scene, camera or None, sphere)."""
    scene = bpy.context.scene
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("Black")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    camera = None
    if with_camera:
        data = bpy.data.cameras.new("Camera")
        data.clip_start, data.clip_end = 0.001, 1000.0
        camera = bpy.data.objects.new("Camera", data)
        scene.collection.objects.link(camera)
        scene.camera = camera
    sphere = add_sphere(bpy, scene, (1.0, 0.5, -5.0), 0.5, emission_material(bpy))
    bpy.context.view_layer.update()
    return scene, camera, sphere


def keyframe_camera_path(camera, frames_and_positions, interpolation="LINEAR"):
    """Keyframe the camera's location; linear interpolation makes the velocity on each segment
    exactly (x1 - x0) / (t1 - t0), known independently of the add-on."""
    for frame, position in frames_and_positions:
        camera.location = position
        camera.keyframe_insert("location", frame=frame)
    from bpy_extras import anim_utils

    channelbag = anim_utils.animdata_get_channelbag_for_assigned_slot(camera.animation_data)
    for fcurve in channelbag.fcurves:
        for point in fcurve.keyframe_points:
            point.interpolation = interpolation


def save_blend(bpy, path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    return Path(path)


def _env():
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    return env


def run_render_script(blend, *options, timeout=300):
    """``python examples/render.py blend options...`` as a user runs it."""
    command = [sys.executable, str(RENDER_SCRIPT), str(blend), *[str(o) for o in options]]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_env())


def run_python(code, *args, timeout=300):
    """Run ``code`` in a fresh Python process (fresh Blender), with ``args`` as sys.argv[1:]."""
    command = [sys.executable, "-c", code, *[str(a) for a in args]]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_env(), cwd=REPO_ROOT)


def error_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("render.py: error")]


def assert_fails_with(result, reason):
    lines = error_lines(result)
    assert result.returncode == 1, (result.returncode, result.stderr[-2000:])
    assert len(lines) == 1 and reason in lines[0], (reason, result.stderr[-2000:])
    assert "Traceback" not in result.stderr + result.stdout


def read_image(bpy, path):
    """RGBA float pixels [row (top first), column, channel] of a PNG or EXR file."""
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1]


def luminance(rgba):
    return rgba[..., 0] * 0.2126 + rgba[..., 1] * 0.7152 + rgba[..., 2] * 0.0722


def centroid(intensity):
    total = intensity.sum()
    rows, columns = np.mgrid[0 : intensity.shape[0], 0 : intensity.shape[1]]
    return np.array([((columns + 0.5) * intensity).sum() / total, ((rows + 0.5) * intensity).sum() / total])
