"""Bake for Render Anywhere (issue 28, part 2): a baked file renders the add-on's frames without it.

A fly-through on the exact camera: the camera accelerates along its view to 0.9c (keyframed, the
observer velocity taken from its animation, so the shader's velocity, origin and the world's ln D
image change every frame), a keyframed box crosses the view and a lamp moves at 0.3c (stand-in
lamps on its path, placed anew each frame). The add-on renders frames 1-3 itself; then the file is
baked, saved, and rendered as an animation in a fresh process where the add-on is neither enabled
nor installed, colour-science is missing and the file's scripts are disabled (what
``blender -b baked.blend -a`` does on a farm). Each frame must equal the add-on's own render (same
seed) to well below the render noise, measured as the difference the seed alone makes.
"""

import importlib
import subprocess
import sys

import numpy as np
import pytest
import scene_dump

from blender_support import ADDON_MODULE
from pipeline_helpers import ch, render_plain_animation

FRAMES = (1, 2, 3)
FPS = 24.0
C = 10.0  # m/s: slow light, so 0.9c is reached within a few metres


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _quad(bpy, scene, name, corners, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(corners, [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def build_flythrough(bpy):
    """Camera at 1.6 m looking along +Y, speeds 0.6c, 0.75c, 0.9c over the frame steps (linear keys:
    velocity per step known exactly), a floor, a wall ahead, a keyframed box, a lamp moving at 0.3c
    along +X, a grey world (seen above the wall)."""
    scene, camera = ch.new_scene(bpy, resolution=(48, 36), samples=8, location=(0.0, 0.0, 1.6))
    camera.rotation_euler = (1.5707963, 0.0, 0.0)
    camera.data.lens = 20.0
    scene.render.fps, scene.render.fps_base = int(FPS), 1.0
    scene.cycles.seed = 7
    scene.cycles.use_animated_seed = False
    world_tree = ch.compat.world_node_tree(scene.world)
    background = next(node for node in world_tree.nodes if node.type == "BACKGROUND")
    background.inputs["Color"].default_value = (0.2, 0.25, 0.3, 1.0)
    background.inputs["Strength"].default_value = 1.0
    grey = ch.diffuse_material(bpy, "Floor", (0.5, 0.5, 0.5))
    _quad(bpy, scene, "Floor", [(-20, -5, 0), (20, -5, 0), (20, 40, 0), (-20, 40, 0)], grey)
    _quad(bpy, scene, "Wall", [(-20, 14, 0), (20, 14, 0), (20, 14, 3), (-20, 14, 3)], grey)
    red = ch.diffuse_material(bpy, "Red", (0.8, 0.1, 0.1))
    box = _quad(bpy, scene, "Box", [(-0.6, 0, 0), (0.6, 0, 0), (0.6, 0, 1.2), (-0.6, 0, 1.2)], red)
    for frame, x in ((1, 2.0), (3, -1.0)):
        box.location = (x, 8.0, 0.3)
        box.keyframe_insert("location", frame=frame)
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 800.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (-1.0, 6.0, 2.5)
    scene.collection.objects.link(lamp)
    lamp.relativity.enabled = True
    lamp.relativity.motion = "CONSTANT"
    lamp.relativity.beta = (0.3, 0.0, 0.0)
    step = C / FPS
    y = 0.0
    path = [(1, (0.0, 0.0, 1.6))]
    for frame, speed in ((2, 0.6), (3, 0.75), (4, 0.9)):
        y += speed * step
        path.append((frame, (0.0, y, 1.6)))
    for frame, position in path:
        camera.location = position
        camera.keyframe_insert("location", frame=frame)
    for fcurve in ch.compat.action_fcurves(camera.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    settings = scene.relativity
    settings.speed_of_light = C
    settings.velocity_source = "CAMERA_ANIMATION"
    settings.method = "CAMERA"
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
    scene.frame_set(FRAMES[0])
    return scene


def test_baked_flythrough_renders_the_same_frames_without_the_add_on(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene = build_flythrough(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    own = []
    for frame in FRAMES:
        scene.frame_set(frame)
        own.append(ch.render_exr(bpy, scene, tmp_path / f"own_{frame}.exr"))
    scene.cycles.seed = 8  # the render noise: the same frame with another seed
    noise = float(np.abs(ch.render_exr(bpy, scene, tmp_path / "own_seed8.exr") - own[-1]).mean())
    scene.cycles.seed = 7
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "unbaked.blend"), check_existing=False, copy=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "baked.blend"), check_existing=False)
    assert bpy.ops.relativity.bake_render_anywhere(frame_start=FRAMES[0], frame_end=FRAMES[-1]) == {"FINISHED"}
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "baked.blend"), check_existing=False)
    plain = [ch.read_exr(bpy, path) for path in render_plain_animation(tmp_path / "baked.blend", tmp_path, FRAMES)]
    differences = [float(np.abs(p - o).mean()) for p, o in zip(plain, own, strict=True)]
    # the control: the same file not baked, rendered the same way, plays frame 3's state only (its
    # first frame, the one the control reads, alone)
    unbaked = render_plain_animation(tmp_path / "unbaked.blend", tmp_path, FRAMES[:1], "unbaked", chunk=FRAMES[:1] * 2)
    stale = [float(np.abs(ch.read_exr(bpy, u) - o).mean()) for u, o in zip(unbaked, own[:1], strict=True)]
    moving = float(np.abs(own[-1] - own[0]).mean())
    print(
        f"mean |baked - add-on| per frame {differences}, not baked {stale}, seed noise {noise:.4g}, "
        f"frame 3 - frame 1 {moving:.4g}"
    )
    assert moving > 2.0 * noise, "the frames differ (the fly-through moves)"
    assert stale[0] > noise, "without the bake the first frame is wrong (the control)"
    assert max(differences) < 0.1 * noise, f"baked frames differ from the add-on's: {differences} (noise {noise:.4g})"


def test_remove_takes_the_bake_out(relativity_addon, factory_blender, tmp_path):
    """Remove after a bake: no F-curve, action, image or file of the bake is left, the user's keys stay."""
    bpy = factory_blender
    scene = build_flythrough(bpy)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "fly.blend"), check_existing=False)
    before = scene_dump.dump(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert bpy.ops.relativity.bake_render_anywhere() == {"FINISHED"}
    camera_data = scene.camera.data
    assert camera_data.animation_data is not None and camera_data.animation_data.action is not None
    assert any((tmp_path / "fly_relativity_bake").iterdir())
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert camera_data.animation_data is None
    assert not (tmp_path / "fly_relativity_bake").exists()
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, f"{len(lines)} differences after Remove:\n" + "\n".join(lines[:40])


def test_bake_refused_with_the_reason(relativity_addon, factory_blender, monkeypatch):
    """No OSL in this Blender: the exact camera cannot be baked (it is an OSL shader). One line,
    nothing added. (Apparent Geometry: test_bake_apparent_geometry.py.)"""
    bpy = factory_blender
    scene = build_flythrough(bpy)
    effect = _effect()
    osl = importlib.import_module(f"{ADDON_MODULE}.blender.common.osl")
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    monkeypatch.setattr(osl, "unavailable_reason", lambda: "This Blender build has no OSL (Open Shading Language)")
    with pytest.raises(effect.RelativityError, match="OSL"):
        effect.bake_for_render_anywhere(scene, 1, 3)
    assert "relativity_render_anywhere" not in scene.keys()


def test_render_script_bakes_a_file_that_renders_its_frames_without_the_add_on(
    relativity_addon, factory_blender, tmp_path
):
    """``render.py fly.blend --frames 1-3 --bake-to baked.blend`` (a file never set up): plain Blender
    renders the frames ``render.py --frames 1-3 --out`` renders with the add-on, at the same seed."""
    bpy = factory_blender
    build_flythrough(bpy)
    blend = ch.save_blend(bpy, tmp_path / "fly.blend")
    options = ("--frames=1-3", "--seed=7", "--samples=8")
    command = [sys.executable, str(ch.RENDER_SCRIPT), str(blend), f"--bake-to={tmp_path / 'baked.blend'}", *options]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "baked frames 1-3" in result.stdout, result.stdout[-2000:]
    ch.run_render_script(blend, tmp_path / "own.exr", *options, timeout=600)
    own = [ch.read_exr(bpy, tmp_path / f"own_{frame:04d}.exr") for frame in FRAMES]
    plain = [ch.read_exr(bpy, path) for path in render_plain_animation(tmp_path / "baked.blend", tmp_path, FRAMES)]
    differences = [float(np.abs(p - o).mean()) for p, o in zip(plain, own, strict=True)]
    print(f"mean |baked - render.py| per frame {differences}")
    assert max(differences) < 1e-3 * float(np.mean([o.mean() for o in own])), differences


def test_unsaved_file_is_refused_before_anything_is_added(relativity_addon, factory_blender):
    """The world's per-frame image goes beside the file: an unsaved file is refused in one line, and
    nothing of a bake is left (no record, no F-curve on the camera)."""
    bpy = factory_blender
    scene = build_flythrough(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    with pytest.raises(_effect().RelativityError, match="Save the file first"):
        _effect().bake_for_render_anywhere(scene, 1, 3)
    assert "relativity_render_anywhere" not in scene.keys()
    assert scene.camera.data.animation_data is None


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        ((), "--out"),
        (("--bake-to=baked.blend", "--spectral=2"), "not with --spectral"),
        (("--bake-to=baked.png",), "must name a .blend"),
    ],
)
def test_render_script_bake_options(options, expected):
    from relativity_addon import batch

    with pytest.raises(batch.BatchError, match=expected):
        batch.parse(["render.py", "scene.blend", *options])
