"""Fly-through: a camera accelerating from rest to near the speed of light down a street at rest.

    python examples/flythrough.py --out out/flythrough [--frames 48] [--beta-max 0.95]
        [--speed-of-light 10] [--resolution 320x240] [--samples 16] [--no-searchlight]

Builds a street (floor, two rows of coloured blocks, glowing lamps, a sun), keyframes the camera
along the street (+Y) on a hyperbolic world line (constant proper acceleration, so it approaches
``--beta-max`` smoothly and never reaches c) and saves it as ``<out>/flythrough.blend`` with the
observer velocity taken from the camera animation (``velocity_source = 'CAMERA_ANIMATION'``).
Light is slow (10 m/s by default) so that the speeds are reached within a few metres. It then
renders the frames through the batch script (``<out>/fly_0001.png`` ...), one progress line per
frame, and prints the ffmpeg command that turns them into a video.

The saved .blend holds everything a render needs (camera shader, settings, keyframes): each frame
can be rendered alone on a farm, see docs/farm.md. Exits non-zero with one line on failure.
"""

import argparse
import math
import sys
from pathlib import Path

try:
    import bpy
except ImportError:
    sys.exit(
        "flythrough.py needs Blender's Python or the bpy module: run ./dev.sh demo (which sets up .venv-5.2), "
        "or blender -b --python examples/flythrough.py -- OPTIONS"
    )

EXAMPLES_DIR = Path(__file__).resolve().parent
REPO_ROOT = EXAMPLES_DIR.parent
sys.path[:0] = [str(REPO_ROOT), str(EXAMPLES_DIR)]

import scenes  # noqa: E402
from relativity_addon import batch  # noqa: E402
from relativity_addon.blender.common import compat  # noqa: E402

EYE_HEIGHT = 1.6  # metres
BLOCK_COLOURS = (scenes.RED, scenes.GREEN, scenes.BLUE, scenes.YELLOW, (0.7, 0.7, 0.7))


def hyperbolic_position(t, c, acceleration, t_cruise):
    """Distance (m) at time t (s) of a world line with constant proper acceleration up to
    ``t_cruise``, then constant velocity: x = (c^2/a)(sqrt(1 + (a t / c)^2) - 1)."""

    def accelerating(time):
        return c * c / acceleration * (math.sqrt(1.0 + (acceleration * time / c) ** 2) - 1.0)

    if t <= t_cruise:
        return accelerating(max(t, 0.0))
    u = acceleration * t_cruise / c  # gamma * beta at cruise
    return accelerating(t_cruise) + c * u / math.sqrt(1.0 + u * u) * (t - t_cruise)


def build_street(scene, length=60.0):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scenes.add_floor(scene, size=2.0 * length, squares=int(length))
    lamp_material = scenes.emission_material("Lamp", (1.0, 0.75, 0.4), 30.0)
    for index, y in enumerate(range(6, int(length), 6)):
        for side in (-1, 1):
            colour = BLOCK_COLOURS[(index + (side > 0)) % len(BLOCK_COLOURS)]
            material = scenes.principled_material(f"Block {index} {side}", colour)
            block = scenes.add_box(scene, f"Block {index} {side}", (side * 5.0, float(y), 1.5), 3.0, material)
            block.scale.z = 1.0 + (index % 3) * 0.5
        scenes.add_sphere(scene, f"Lamp {index}", (-2.8 if index % 2 else 2.8, y + 3.0, 2.5), 0.25, lamp_material)
    sun = bpy.data.lights.new("Sun", type="SUN")
    sun.energy = 3.0
    sun_object = bpy.data.objects.new("Sun", sun)
    sun_object.rotation_euler = (0.8, 0.2, 0.6)
    scene.collection.objects.link(sun_object)
    scenes.set_world_color(scene, (0.15, 0.2, 0.3))


def keyframe_camera(scene, camera, frames, c, beta_max, searchlight):
    """Keyframe every frame (linear) on the hyperbolic world line; cruise after 60% of the shot.

    One key past the last frame keeps the last frame's velocity (a central difference there would
    otherwise see the camera stop). With the searchlight on, the exposure is the add-on's
    Compensated one (docs/camera.md, "Exposure")."""
    fps = scene.render.fps / scene.render.fps_base
    t_cruise = 0.6 * (frames - 1) / fps
    u_max = beta_max / math.sqrt(1.0 - beta_max * beta_max)
    acceleration = c * u_max / t_cruise
    positions = [hyperbolic_position((frame - 1) / fps, c, acceleration, t_cruise) for frame in range(1, frames + 2)]
    for frame, y in enumerate(positions, start=1):
        camera.location = (0.0, y, EYE_HEIGHT)
        camera.keyframe_insert("location", frame=frame)
    for fcurve in compat.action_fcurves(camera.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    if searchlight:
        # One exposure per frame from the observer's velocity (the add-on's Compensated exposure,
        # in each file's metadata), so that the brightening ahead does not burn the film out.
        scene.relativity.exposure_mode = "COMPENSATED"


def build(out_dir, frames, beta_max, c, resolution, samples, searchlight=True):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    batch.enable_addon()
    scene = bpy.context.scene
    build_street(scene)
    camera = scenes.add_camera(scene, (0.0, 0.0, EYE_HEIGHT), (0.0, 10.0, EYE_HEIGHT), lens_mm=24.0)
    scene.frame_start, scene.frame_end = 1, frames
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.cycles.samples = samples
    scene.cycles.seed = 0
    scene.cycles.use_animated_seed = False  # frames are deterministic (farm: alone == in sequence)
    keyframe_camera(scene, camera, frames, c, beta_max, searchlight)
    settings = scene.relativity
    settings.use_searchlight = searchlight
    settings.speed_of_light = c
    settings.velocity_source = "CAMERA_ANIMATION"
    settings.method = "CAMERA"
    from relativity_addon.blender.pipeline import effect

    scene.frame_set(1)
    effect.apply(scene)
    blend = out_dir / "flythrough.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), check_existing=False)
    return blend


def _resolution(text):
    width, height = (int(part) for part in text.lower().split("x"))
    return width, height


def main(argv=None):
    parser = argparse.ArgumentParser(prog="flythrough.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/flythrough", help="output folder")
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--beta-max", type=float, default=0.95, help="cruise speed, fraction of c")
    parser.add_argument("--speed-of-light", type=float, default=10.0, help="metres per second")
    parser.add_argument("--resolution", type=_resolution, default=(320, 240), help="WIDTHxHEIGHT")
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--no-searchlight", action="store_true", help="no D^4 brightening (geometry only)")
    options = parser.parse_args(argv)
    if not 0.0 < options.beta_max < 1.0:
        print("flythrough.py: error: --beta-max must be between 0 and 1", file=sys.stderr)
        return 1
    if options.frames < 2:
        print("flythrough.py: error: --frames must be at least 2", file=sys.stderr)
        return 1
    out_dir = Path(options.out).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    try:
        blend = build(
            out_dir,
            options.frames,
            options.beta_max,
            options.speed_of_light,
            options.resolution,
            options.samples,
            searchlight=not options.no_searchlight,
        )
    except Exception as error:  # noqa: BLE001 - one line, never a traceback
        print(f"flythrough.py: error: {error}", file=sys.stderr)
        return 1
    status = batch.main(["render.py", str(blend), f"--frames=1-{options.frames}", f"--out={out_dir / 'fly_####.png'}"])
    if status != 0:
        return status
    print(f"flythrough.py: saved {blend}")
    print("flythrough.py: make a video with:")
    print(
        f"  ffmpeg -framerate {bpy.context.scene.render.fps} -i {out_dir / 'fly_%04d.png'} "
        f"-c:v libx264 -pix_fmt yuv420p {out_dir / 'flythrough.mp4'}"
    )
    return 0


if __name__ == "__main__":
    compat.run_main(main)
