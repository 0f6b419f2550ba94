"""Helpers for the workflow tests: small scenes, the batch script run as a user would, image reading.

Physics expectations (aberration) are the camera tests' own, written out from docs/physics.md in
tests/blender/camera/camera_helpers.py independently of the add-on; scenes are built with the
same helpers.
"""

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil

from relativity_addon.blender.common import compat

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402

REPO_ROOT = Path(__file__).resolve().parents[3]
RENDER_SCRIPT = REPO_ROOT / "examples" / "render.py"
FLYTHROUGH_SCRIPT = REPO_ROOT / "examples" / "flythrough.py"


aberrate = ch.aberrate
emission_material = ch.emission_material


def add_sphere(bpy, scene, location, radius, material, name="Marker"):
    return ch.add_sphere(bpy, scene, location, radius, material, name=name, segments=32, rings=16)


def new_scene(bpy, resolution=(64, 48), samples=2, with_camera=True):
    """Cycles scene with a black world, an emissive sphere off-axis and (optionally) a camera at
    the origin looking down -Z. Returns (scene, camera or None, sphere)."""
    scene = ch.reset_cycles_scene(bpy, resolution, samples)
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
    for fcurve in compat.action_fcurves(camera.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = interpolation


def save_blend(bpy, path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    return Path(path)


def moving_camera_blend(bpy, path, last_frame):
    """A saved file: the camera keyframed from the origin along -Z over frames 1 to ``last_frame``
    (each frame sees the emissive sphere from elsewhere), 32x32."""
    scene, camera, _ = new_scene(bpy, resolution=(32, 32))
    scene.frame_start, scene.frame_end = 1, last_frame
    keyframe_camera_path(camera, [(1, (0.0, 0.0, 0.0)), (last_frame, (0.3, 0.15, -1.5))])
    return save_blend(bpy, path)


def _env():
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    return env


def run_render_script(blend, *options, timeout=300):
    """``python examples/render.py blend options...`` as a user runs it."""
    command = [sys.executable, str(RENDER_SCRIPT), str(blend), *[str(o) for o in options]]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_env())


def watch_render_script(blend, options, look, interval=0.01, timeout=240):
    """``python examples/render.py blend options...`` in a process of its own, whose process tree
    (every descendant, as ``psutil`` processes) is handed to ``look(tree)`` every ``interval``
    seconds until ``look`` returns True, the job ends or ``timeout`` seconds pass; then the job is
    waited for, ``timeout`` seconds at most (killed if the test fails first). Returns the finished
    ``Popen``, stdout and stderr."""
    command = [sys.executable, str(RENDER_SCRIPT), str(blend), *[str(o) for o in options]]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
    try:
        root, deadline = psutil.Process(process.pid), time.monotonic() + timeout
        while process.poll() is None and time.monotonic() < deadline:
            try:
                tree = root.children(recursive=True)
            except psutil.NoSuchProcess:
                break
            if look(tree):
                break
            time.sleep(interval)
        stdout, stderr = process.communicate(timeout=timeout)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    return process, stdout, stderr


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


read_image = ch.read_image


def luminance(rgba):
    return rgba[..., 0] * 0.2126 + rgba[..., 1] * 0.7152 + rgba[..., 2] * 0.0722


def centroid(intensity):
    total = intensity.sum()
    rows, columns = np.mgrid[0 : intensity.shape[0], 0 : intensity.shape[1]]
    return np.array([((columns + 0.5) * intensity).sum() / total, ((rows + 0.5) * intensity).sum() / total])


def render_plain_animation(blend, out_dir, frames, name="plain", chunk=None):
    """``blender -b blend -a`` in a fresh process: no add-on, no colour-science, scripts disabled.
    Returns the paths of ``frames`` (the file's frame range) as OpenEXR files in ``out_dir``.
    ``chunk``: (first, last) rendered instead of the file's range, as a Flamenco task's
    ``--frame-start A --frame-end B --render-anim`` (flamenco/relativistic_render_baked.js)."""
    frame_range = "" if chunk is None else f"scene.frame_start, scene.frame_end = {chunk[0]}, {chunk[1]}\n"
    worker = (
        "import os, sys\n"
        "sys.modules['colour'] = None\n"
        "import bpy\n"
        "bpy.context.preferences.filepaths.use_scripts_auto_execute = False\n"
        f"bpy.ops.wm.open_mainfile(filepath={str(blend)!r}, use_scripts=False)\n"
        "scene = bpy.context.scene\n"
        "assert not hasattr(scene, 'relativity'), 'add-on unexpectedly enabled'\n"
        "assert not bpy.app.handlers.frame_change_pre and not bpy.app.handlers.render_pre, 'handlers installed'\n"
        f"{frame_range}scene.render.filepath = {str(out_dir / (name + '_####'))!r}\n"
        "scene.render.use_file_extension = True\n"
        "scene.render.image_settings.file_format = 'OPEN_EXR'\n"
        "scene.render.image_settings.color_depth = '32'\n"
        "bpy.ops.render.render(animation=True)\n"
        "sys.stdout.flush()\nsys.stderr.flush()\nos._exit(0)\n"  # bpy 4.5 can hang in exit()
    )
    result = subprocess.run([sys.executable, "-c", worker], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    return [out_dir / f"{name}_{frame:04d}.exr" for frame in frames]
