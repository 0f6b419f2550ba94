"""The batch script as a pipeline uses it: frames, output names, progress, both invocation forms,
every option reaching the scene, and one-line failures with exit code 1."""

import re

import numpy as np
import pytest

import pipeline_helpers as wh
from relativity_addon.blender.common import compat

C_SLOW = 10.0  # scene units per second for the animated tests (fps 24)


@pytest.fixture
def plain_blend(factory_blender, tmp_path):
    """A .blend never set up for relativity: camera, emissive sphere; camera keyframed along -Z."""
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    scene.frame_start, scene.frame_end = 1, 5
    # 0.25 units per frame at 24 fps = 6 units/s = 0.6 c for c = 10.
    wh.keyframe_camera_path(camera, [(1, (0.0, 0.0, 0.0)), (5, (0.0, 0.0, -1.0))])
    return wh.save_blend(bpy, tmp_path / "plain.blend")


def test_frames_written_with_numbers_and_progress(plain_blend, tmp_path):
    result = wh.run_render_script(
        plain_blend, "--frames", "2-4", "--beta=0,0,-0.5", "--samples=1", f"--out={tmp_path / 'out' / 'shot.png'}"
    )
    assert result.returncode == 0, result.stderr[-2000:]
    for frame in (2, 3, 4):
        assert (tmp_path / "out" / f"shot_{frame:04d}.png").is_file()
    assert not (tmp_path / "out" / "shot.png").exists()
    progress = [line for line in result.stdout.splitlines() if line.startswith("render.py: frame")]
    assert len(progress) == 3
    for done, (line, frame) in enumerate(zip(progress, (2, 3, 4), strict=True), start=1):
        assert re.match(rf"render\.py: frame {frame} \({done}/3\) in [\d.]+ s, about [\d.]+ s left: ", line), line
    assert progress[-1].split("about ")[1].startswith("0.0 s left")

    # A run of '#' is replaced by the zero-padded frame number (Blender's convention), EXR output.
    result = wh.run_render_script(
        plain_blend, "--frame=3", "--beta=0,0,-0.5", "--samples=1", f"--out={tmp_path / 'hash' / 'f_###.exr'}"
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert (tmp_path / "hash" / "f_003.exr").is_file()


def _pinhole_pixel(bpy, scene, camera, direction):
    corners = camera.data.view_frame(scene=scene)
    xs = [c.x / -c.z for c in corners]
    ys = [c.y / -c.z for c in corners]
    u, v = direction[0] / -direction[2], direction[1] / -direction[2]
    width, height = scene.render.resolution_x, scene.render.resolution_y
    return np.array([(u - min(xs)) / (max(xs) - min(xs)) * width, (max(ys) - v) / (max(ys) - min(ys)) * height])


def test_plain_blend_renders_relativistically_with_beta(factory_blender, tmp_path):
    """A file never set up: --beta alone gives the aberrated image (docs/physics.md), --reference the
    ordinary one; the sphere's centroid lands where the aberration formula puts it."""
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy, resolution=(160, 120))
    sphere.scale = (0.4, 0.4, 0.4)
    blend = wh.save_blend(bpy, tmp_path / "plain.blend")
    beta = np.array([0.0, 0.0, -0.9])
    moving = tmp_path / "moving.exr"
    still = tmp_path / "still.exr"
    common = ("--samples=4", "--no-searchlight")
    assert wh.run_render_script(blend, "--beta=0,0,-0.9", f"--out={moving}", *common).returncode == 0
    assert wh.run_render_script(blend, "--reference", f"--out={still}", *common).returncode == 0
    center = np.array(sphere.location)
    k = -center / np.linalg.norm(center)  # photon from the sphere to the camera at the origin
    expected_moving = _pinhole_pixel(bpy, scene, camera, -wh.aberrate(k, beta))
    expected_still = _pinhole_pixel(bpy, scene, camera, center)
    measured_moving = wh.centroid(wh.luminance(wh.read_image(bpy, moving)))
    measured_still = wh.centroid(wh.luminance(wh.read_image(bpy, still)))
    assert np.linalg.norm(measured_still - expected_still) < 0.5, (measured_still, expected_still)
    assert np.linalg.norm(measured_moving - expected_moving) < 0.5, (measured_moving, expected_moving)
    assert np.linalg.norm(expected_moving - expected_still) > 20.0  # the effect is large


BLENDER_FORM = """
import runpy, sys
import bpy
blend, script = sys.argv[1], sys.argv[2]
options = sys.argv[3:]
bpy.ops.wm.open_mainfile(filepath=blend)
# What Blender leaves in sys.argv for: blender -b file.blend --python examples/render.py -- options
sys.argv = ["blender", "-b", blend, "--python", script, "--", *options]
try:
    runpy.run_path(script, run_name="__main__")
except SystemExit as exit:
    sys.exit(exit.code)
"""


def test_blender_command_line_form_equals_python_form(plain_blend, tmp_path, factory_blender):
    options = ("--frame=2", "--beta=0.3,0,-0.6", "--samples=2", "--seed=3")
    direct = tmp_path / "direct.exr"
    inside = tmp_path / "inside.exr"
    assert wh.run_render_script(plain_blend, *options, f"--out={direct}").returncode == 0
    result = wh.run_python(BLENDER_FORM, plain_blend, wh.RENDER_SCRIPT, *options, f"--out={inside}")
    assert result.returncode == 0, result.stderr[-2000:]
    assert "render.py: frame 2 (1/1)" in result.stdout
    np.testing.assert_array_equal(wh.read_image(factory_blender, direct), wh.read_image(factory_blender, inside))

    result = wh.run_python(BLENDER_FORM, plain_blend, wh.RENDER_SCRIPT, "--beta=0,0,-1", f"--out={inside}")
    wh.assert_fails_with(result, "below 1")
    # In Blender's form the .blend is already open: a positional file name is a bad option.
    result = wh.run_python(BLENDER_FORM, plain_blend, wh.RENDER_SCRIPT, str(plain_blend), f"--out={inside}")
    wh.assert_fails_with(result, "bad option")


def test_missing_out_bad_extension_missing_file_and_camera(plain_blend, tmp_path, factory_blender):
    wh.assert_fails_with(wh.run_render_script(plain_blend, "--beta=0,0,-0.5"), "--out")
    wh.assert_fails_with(wh.run_render_script(plain_blend, f"--out={tmp_path / 'x.jpg'}"), ".png or .exr")
    wh.assert_fails_with(
        wh.run_render_script(tmp_path / "nope.blend", f"--out={tmp_path / 'x.png'}"), "no such .blend file"
    )
    bpy = factory_blender
    wh.new_scene(bpy, with_camera=False)
    no_camera = wh.save_blend(bpy, tmp_path / "no_camera.blend")
    wh.assert_fails_with(
        wh.run_render_script(no_camera, "--beta=0,0,-0.5", f"--out={tmp_path / 'x.png'}"), "no active camera"
    )
    wh.assert_fails_with(
        wh.run_render_script(no_camera, "--velocity-from-animation", f"--out={tmp_path / 'x.png'}"), "no active camera"
    )


def test_animation_faster_than_light_is_refused_with_its_frame(factory_blender, tmp_path):
    """Linear keys: 0.1 units/frame up to frame 6 (2.4 units/s = 0.24 c), then 0.5 units/frame
    (1.2 c). At frame 6 itself the central difference straddles the kink ((0.24 + 1.2) / 2 =
    0.72 c), so the first instant checked at or above c is the quarter frame 6.25."""
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    scene.frame_start, scene.frame_end = 1, 10
    wh.keyframe_camera_path(camera, [(1, (0, 0, 0)), (6, (0, 0, -0.5)), (10, (0, 0, -2.5))])
    blend = wh.save_blend(bpy, tmp_path / "fast.blend")
    out = tmp_path / "fast.png"
    light = f"--speed-of-light={C_SLOW}"
    result = wh.run_render_script(blend, "--velocity-from-animation", light, "--frames=1-10", f"--out={out}")
    wh.assert_fails_with(result, "at frame 6 (sub-frame 6.25)")
    assert "1.2 c" in wh.error_lines(result)[0]
    assert not list(tmp_path.glob("fast*.png"))
    # The slow part alone renders; the fast part alone is refused at its first frame.
    result = wh.run_render_script(
        blend, "--velocity-from-animation", light, "--frames=1-5", "--samples=1", f"--out={out}"
    )
    assert result.returncode == 0, result.stderr[-2000:]
    result = wh.run_render_script(blend, "--velocity-from-animation", light, "--frame=8", f"--out={out}")
    wh.assert_fails_with(result, "at frame 8")


def test_options_reach_the_scene(factory_blender):
    """Every option maps onto its scene setting (the render tests above cover the pixels)."""
    from relativity_addon import batch

    bpy = factory_blender
    import relativity_addon

    relativity_addon.register()
    try:
        scene, _, _ = wh.new_scene(bpy)
        parser = batch.build_parser(with_blend_file=False)
        options = parser.parse_args(
            [
                "--out=x.exr",
                "--beta=0.1,0.2,-0.3",
                "--method=camera",
                "--shutter=DETECTOR_PLANE",
                "--shutter-time=-2.5",
                "--speed-of-light=7",
                "--no-doppler",
                "--no-searchlight",
                "--no-geometry",
                "--lorentz-window",
                "--lens=phase-hologram",
                "--shutter-plane-point=0.5,0,-2",
                "--shutter-plane-normal=0,0.6,-0.8",
            ]
        )
        batch._apply_options(scene, options)
        settings = scene.relativity
        assert tuple(settings.beta) == pytest.approx((0.1, 0.2, -0.3))
        assert settings.velocity_source == "MANUAL"
        assert settings.shutter_model == "DETECTOR_PLANE" and settings.shutter_time == -2.5
        assert settings.speed_of_light == 7.0
        assert not (settings.use_doppler or settings.use_searchlight or settings.use_geometry)
        assert settings.use_lorentz_window and settings.lorentz_window_shutter == "WINDOW_PLANE"
        assert settings.imaging_element == "PHASE_HOLOGRAM"
        assert tuple(settings.shutter_plane_point) == pytest.approx((0.5, 0.0, -2.0))
        assert tuple(settings.shutter_plane_normal) == pytest.approx((0.0, 0.6, -0.8))
        batch._apply_options(scene, parser.parse_args(["--out=x.exr", "--window-time=-1.5", "--lens=ideal"]))
        assert settings.lorentz_window_shutter == "SHUTTER_MODEL" and settings.lorentz_window_time == -1.5
        assert settings.imaging_element == "IDEAL_LENS"
        options = parser.parse_args(["--out=x.png", "--velocity-from-animation", "--method=geometry"])
        batch._apply_options(scene, options)
        assert settings.velocity_source == "CAMERA_ANIMATION" and settings.method == "GEOMETRY"
        assert batch.frame_output_path("/a/b.png", 7, several=False) == "/a/b.png"
        assert batch.frame_output_path("/a/b.png", 7, several=True) == "/a/b_0007.png"
        assert batch.frame_output_path("/a/b_##.exr", 7, several=False) == "/a/b_07.exr"
        assert batch.frame_output_path("/a/b.png", -3, several=True) == "/a/b_-003.png"
    finally:
        relativity_addon.unregister()


def test_seed_samples_resolution_reference_and_searchlight_change_pixels(plain_blend, tmp_path, factory_blender):
    bpy = factory_blender

    def render(name, *options):
        out = tmp_path / f"{name}.exr"
        result = wh.run_render_script(plain_blend, "--frame=1", "--beta=0,0,-0.6", f"--out={out}", *options)
        assert result.returncode == 0, result.stderr[-2000:]
        return wh.read_image(bpy, out)

    # (With one sample Cycles' first sample ignores the seed, measured: use two.)
    base = render("base", "--samples=2", "--seed=1")
    np.testing.assert_array_equal(base, render("again", "--samples=2", "--seed=1"))
    assert not np.array_equal(base, render("seed", "--samples=2", "--seed=2"))
    assert not np.array_equal(base, render("samples", "--samples=8", "--seed=1"))
    assert render("size", "--samples=1", "--resolution=32x20").shape == (20, 32, 4)
    # Searchlight off: moving towards the sphere it is dimmer (no D^4 > 1 boost).
    moving = render("moving", "--samples=4")  # (also the moving render the reference is compared with)
    lit = wh.luminance(moving).sum()
    unlit = wh.luminance(render("unlit", "--samples=4", "--no-searchlight")).sum()
    assert lit > 1.5 * unlit
    reference = render("reference", "--samples=4", "--reference")
    assert not np.allclose(wh.centroid(wh.luminance(reference)), wh.centroid(wh.luminance(moving)), atol=2.0)
    assert np.isfinite(base).all()


def test_frame_whose_geometry_update_fails_is_not_rendered(relativity_addon, factory_blender, tmp_path):
    """An object keyframed faster than light from frame 3 on (c = 100 units/s; linear keys: 0.1
    then 5 units a frame, 0.024 c then 1.2 c; light takes 1.2 frames from the sphere): frames
    whose light left before the fast part render; the batch stops at the first frame whose
    apparent geometry cannot be computed, naming it, instead of rendering stale shapes."""
    bpy = factory_blender
    scene, _, sphere = wh.new_scene(bpy)
    scene.frame_start, scene.frame_end = 1, 6
    sphere.relativity.motion = "ANIMATION"
    x, y, z = sphere.location
    wh.keyframe_camera_path(sphere, [(1, (x, y, z)), (3, (x + 0.2, y, z)), (6, (x + 15.2, y, z))])
    blend = wh.save_blend(bpy, tmp_path / "fast_object.blend")
    out = tmp_path / "fast_object.png"
    result = wh.run_render_script(
        blend,
        "--method=geometry",
        "--beta=0,0,0",
        "--speed-of-light=100",
        "--frames=1-6",
        "--samples=1",
        f"--out={out}",
    )
    wh.assert_fails_with(result, "frame ")
    line = wh.error_lines(result)[0]
    print(line)
    assert sphere.name in line
    failed_frame = int(re.search(r"frame (\d+)", line).group(1))
    assert 3 <= failed_frame <= 5
    rendered = sorted(path.name for path in tmp_path.glob("fast_object*.png"))
    assert rendered == [f"fast_object_{frame:04d}.png" for frame in range(1, failed_frame)]


def test_panel_lines_are_printed_once_as_notes(relativity_addon, factory_blender, tmp_path):
    """What the N-panel says of a set-up scene reaches a pipeline user too: a moving sphere under a
    lit world (the world's light reaches it unshifted: docs/lamp-doppler.md) gets the panel's line as
    one ``render.py: note:`` line, once for two frames, in one process and on a Dask farm; the same
    file with a black world gets none of it."""
    bpy = factory_blender
    scene, _, sphere = wh.new_scene(bpy)
    scene.frame_start, scene.frame_end = 1, 2
    sphere.relativity.enabled = True
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = (0.5, 0.0, 0.0)
    black = wh.save_blend(bpy, tmp_path / "black_world.blend")
    scene.world.color = (0.2, 0.2, 0.2)  # Blender 4.5 without world nodes, and the tree's Background
    background = compat.world_node_tree(scene.world).nodes["Background"]
    background.inputs["Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    background.inputs["Strength"].default_value = 1.0
    lit = wh.save_blend(bpy, tmp_path / "lit_world.blend")
    common = ("--method=geometry", "--beta=0,0,0", "--speed-of-light=10", "--frames=1-2", "--samples=1")
    notes = {}
    for name, blend in (("lit", lit), ("black", black)):
        result = wh.run_render_script(blend, *common, f"--out={tmp_path / name / 'shot.png'}")
        assert result.returncode == 0, result.stderr[-2000:]
        notes[name] = [line for line in result.stdout.splitlines() if line.startswith("render.py: note: ")]
    print(notes)
    world_lines = [line for line in notes["lit"] if "the world" in line and "unshifted" in line]
    assert len(world_lines) == 1, notes["lit"]
    assert len(notes["lit"]) == len(set(notes["lit"]))  # each line once over the two frames
    assert not [line for line in notes["black"] if "the world" in line], notes["black"]

    # On a Dask farm (two workers, a frame each): the workers' Blender processes send the lines with
    # each frame's reply; the coordinator prints each once.
    result = wh.run_render_script(lit, *common, f"--out={tmp_path / 'farm' / 'shot.png'}", "--workers=2", "--threads=1")
    assert result.returncode == 0, result.stderr[-2000:]
    farm_notes = [line for line in result.stdout.splitlines() if line.startswith("render.py: note: ")]
    print(farm_notes)
    assert "Dask cluster" in result.stdout and "2 rendered" in result.stdout, result.stdout[-3000:]
    assert farm_notes == notes["lit"], result.stdout[-3000:]
