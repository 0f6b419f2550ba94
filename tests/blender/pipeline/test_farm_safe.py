"""Farm safety: a frame rendered alone in a fresh process equals the same frame rendered in a
sequence, pixel for pixel (fixed seed), whether the sequence is Blender's own animation render
(what Flamenco runs) or the batch script; everything the render needs is in the .blend."""

import numpy as np
import pytest

import pipeline_helpers as wh

# Blender's own animation render in a fresh process, as a farm worker runs it: open the file,
# enable the add-on (installed on the worker), render frames FIRST..LAST to OUT (#### = frame).
FARM_WORKER = """
import sys
import bpy
blend, out, first, last = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
bpy.ops.wm.open_mainfile(filepath=blend)
sys.path.insert(0, ".")
from relativity_addon import batch
batch.enable_addon()
scene = bpy.context.scene
scene.frame_start, scene.frame_end = first, last
scene.render.filepath = out
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
bpy.ops.render.render(animation=True)
"""

FRAMES = (1, 3)  # the sequence; frame 2 is the one compared


def _build_scene(bpy, method):
    scene, camera, sphere = wh.new_scene(bpy, resolution=(64, 48), samples=2)
    scene.cycles.seed = 7
    scene.frame_start, scene.frame_end = FRAMES
    # Accelerating camera (linear keys): 0.2 c, then 0.5 c, then 0.8 c (c = 10, 24 fps).
    wh.keyframe_camera_path(
        camera,
        [(0, (0, 0, 0)), (1, (0, 0, -1 / 12)), (2, (0, 0, -1 / 12 - 5 / 24)), (3, (0, 0, -1 / 12 - 5 / 24 - 1 / 3))],
    )
    settings = scene.relativity
    settings.speed_of_light = 10.0
    settings.velocity_source = "CAMERA_ANIMATION"
    settings.method = method
    if method == "GEOMETRY":
        sphere.relativity.enabled = True
    return scene


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
def test_frame_alone_equals_frame_in_sequence(relativity_addon, factory_blender, tmp_path, method):
    bpy = factory_blender
    scene = _build_scene(bpy, method)
    scene.frame_set(2)
    result = bpy.ops.relativity.setup_scene()
    assert result == {"FINISHED"}
    blend = wh.save_blend(bpy, tmp_path / "farm.blend")

    images = {}
    # Blender's animation render: the whole sequence, then frame 2 alone, each in a fresh process.
    for name, (first, last) in {"sequence": FRAMES, "alone": (2, 2)}.items():
        result = wh.run_python(FARM_WORKER, blend, tmp_path / name / "f_####", first, last)
        assert result.returncode == 0, result.stderr[-2000:]
        images[name] = {f: wh.read_image(bpy, tmp_path / name / f"f_{f:04d}.exr") for f in range(first, last + 1)}
    # The batch script, the same two ways.
    for name, option in {"batch_sequence": "--frames=1-3", "batch_alone": "--frame=2"}.items():
        result = wh.run_render_script(blend, option, f"--out={tmp_path / name / 'b.exr'}", f"--method={method.lower()}")
        assert result.returncode == 0, result.stderr[-2000:]
    sequence = tmp_path / "batch_sequence"
    images["batch_sequence"] = {f: wh.read_image(bpy, sequence / f"b_{f:04d}.exr") for f in (1, 2, 3)}
    images["batch_alone"] = {2: wh.read_image(bpy, tmp_path / "batch_alone" / "b.exr")}

    reference = images["sequence"][2]
    assert np.isfinite(reference).all() and reference[..., :3].max() > 0.1
    for name in ("alone", "batch_sequence", "batch_alone"):
        np.testing.assert_array_equal(images[name][2], reference, err_msg=name)
    # The frames really differ (the velocity changes), so equality above is not trivial.
    for frame in (1, 3):
        assert np.abs(images["sequence"][frame] - reference).max() > 0.05
        np.testing.assert_array_equal(images["batch_sequence"][frame], images["sequence"][frame])


def test_rotating_camera_frame_independent_of_saved_frame(relativity_addon, factory_blender, tmp_path):
    """A farm worker opens the file at whatever frame it was saved at: a frame of Blender's own
    animation render must not depend on it (camera turning while it moves). Blender's animation
    render does not re-evaluate the original camera object, so the camera's rotation is read
    from its keyframes at the frame (camera.camera_world_matrix)."""
    bpy = factory_blender
    scene = _build_scene(bpy, "CAMERA")
    camera = scene.camera
    for frame, angle in ((0, 0.0), (3, 0.3)):
        camera.rotation_euler = (0.0, angle, 0.0)
        camera.keyframe_insert("rotation_euler", frame=frame)
    scene.frame_set(1)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    images = []
    for saved_at in (1, 3):
        scene.frame_set(saved_at)
        blend = wh.save_blend(bpy, tmp_path / f"saved_{saved_at}.blend")
        result = wh.run_python(FARM_WORKER, blend, tmp_path / f"saved_{saved_at}" / "f_####", 2, 2)
        assert result.returncode == 0, result.stderr[-2000:]
        images.append(wh.read_image(bpy, tmp_path / f"saved_{saved_at}" / "f_0002.exr"))
    np.testing.assert_array_equal(images[0], images[1])
