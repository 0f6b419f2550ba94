"""The OSL operations Cycles runs per camera sample: the exact camera's against a minimal camera's.

    .venv-5.2/bin/python tools/osl_camera_ops.py [--projection PERSP|EQUIRECTANGULAR|...]
                                                 [--camera exact|minimal] [--beta X,Y,Z] [--print]

Cycles hands every OSL shader to OSL's runtime optimiser before it is compiled to machine code:
the parameters, constant for a render, are folded in, branches on them resolved and unused code
dropped. What is left is what runs per camera sample. OSL prints it when the environment has
``OSL_OPTIONS=debug=2`` (read when Cycles creates its shading system, once per process), so each
count runs a fresh process that renders one sample of a 4 x 2 image and parses the printed listing.

A count of operations does not depend on the machine's load, unlike a render time: it is the
load-independent check beside ``benchmarks/panorama_overhead.py`` (this machine's virtual CPUs
have no hardware counters for ``perf stat -e instructions``). ``work_ops`` leaves out what costs
nothing once compiled: markers (``useparam``, ``functioncall``, ``return``, ``end``) and copies
(``assign``).

The minimal cameras (``MINIMAL_SHADERS``) trace the same rays as Blender's perspective camera and
equirectangular panorama with nothing else: what any OSL camera costs, the floor under the exact
camera's.
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MINIMAL_SHADERS = {
    # The image window on the plane z = 1, as the exact camera's frame_* parameters (Cycles
    # normalises the direction and its derivatives itself).
    "PERSP": """
shader minimal_perspective(float frame_left = -0.36, float frame_right = 0.36, float frame_bottom = -0.27,
                           float frame_top = 0.27, output point position = point(0.0),
                           output vector direction = vector(0.0, 0.0, 1.0), output color throughput = color(1.0))
{
  point raster = camera_shader_raster_position();
  direction = vector(mix(frame_left, frame_right, raster[0]), mix(frame_bottom, frame_top, raster[1]), 1.0);
}
""",
    "EQUIRECTANGULAR": """
shader minimal_equirectangular(output point position = point(0.0), output vector direction = vector(0.0, 0.0, 1.0),
                               output color throughput = color(1.0))
{
  point raster = camera_shader_raster_position();
  float longitude = mix(-M_PI, M_PI, raster[0]);
  float latitude = mix(-M_PI_2, M_PI_2, raster[1]);
  direction = vector(cos(latitude) * sin(longitude), sin(latitude), cos(latitude) * cos(longitude));
}
""",
}

FREE_OPS = frozenset({"useparam", "functioncall", "return", "end", "assign"})
_OP_LINE = re.compile(r"^\s*\d+:\s+(\w+)\b")


def minimal_camera(scene, projection):
    """Turn ``scene``'s camera into the minimal OSL camera for ``projection`` (``PERSP`` or
    ``EQUIRECTANGULAR``), its perspective window the exact camera's; returns the undo."""
    import bpy

    from relativity_addon.blender.camera import exact_camera
    from relativity_addon.blender.common import osl

    data = scene.camera.data
    window = exact_camera.camera_frame_window(scene, data) if projection == "PERSP" else None
    own_type = data.type
    name = f"minimal_{projection.lower()}.osl"
    text = bpy.data.texts.get(name) or bpy.data.texts.new(name)
    text.from_string(MINIMAL_SHADERS[projection])
    data.type, data.custom_mode, data.custom_shader = "CUSTOM", "INTERNAL", text
    errors = osl.compile_custom_camera(data)
    if errors:
        raise RuntimeError(f"minimal OSL camera: {errors[0]}")
    if window is not None:
        for key, value in zip(("frame_left", "frame_right", "frame_bottom", "frame_top"), window, strict=True):
            data.cycles_custom[key] = float(value)
        data.update_tag()

    def undo():
        data.type = own_type

    return undo


def parse_optimised_camera(output: str) -> list[str]:
    """The opcodes of the optimised camera layer in OSL's ``debug=2`` listing, in order."""
    start = output.find('After optimizing layer 0 "camera"')
    if start < 0:
        raise ValueError("no optimised camera shader in the output (OSL_OPTIONS=debug=2 not honoured?)")
    code = output.find("code:", start)
    end = output.find("Layers used", code)
    ops = []
    for line in output[code:end].splitlines()[1:]:
        match = _OP_LINE.match(line)
        if match:
            ops.append(match.group(1))
    if not ops:
        raise ValueError("the optimised camera shader listing has no operations")
    return ops


def work_ops(ops: list[str]) -> collections.Counter[str]:
    """The operations that cost something per sample, counted by name."""
    return collections.Counter(op for op in ops if op not in FREE_OPS)


def optimised_camera_ops(
    projection: str, camera: str = "exact", beta: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> list[str]:
    """Opcodes Cycles runs per camera sample for ``camera`` (``exact``: the add-on at ``beta``;
    ``minimal``) and ``projection`` (``PERSP`` or a Blender panorama type), from a fresh process."""
    env = dict(os.environ, OSL_OPTIONS="debug=2")
    env.pop("PYTHONPATH", None)
    command = [
        sys.executable,
        os.path.abspath(__file__),
        f"--projection={projection}",
        f"--camera={camera}",
        "--beta=" + ",".join(repr(float(b)) for b in beta),
        "--render",
    ]
    result = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env, cwd=ROOT)
    if result.returncode != 0:
        raise RuntimeError(f"osl_camera_ops.py failed ({result.returncode}): {result.stderr.strip()[-2000:]}")
    return parse_optimised_camera(result.stdout + result.stderr)


def _render(projection, camera, beta):
    """In the child process: one sample of a 4 x 2 image through ``camera``."""
    sys.path.insert(0, ROOT)
    import bpy

    import relativity_addon
    from relativity_addon.blender.pipeline import effect

    relativity_addon.register()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 1
    scene.render.resolution_x, scene.render.resolution_y = 4, 2
    camera_object = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object
    if projection != "PERSP":
        camera_object.data.type = "PANO"
        camera_object.data.panorama_type = projection
    if camera == "minimal":
        minimal_camera(scene, projection)
    else:
        scene.relativity.beta = beta
        effect.apply(scene)
    scene.render.filepath = os.path.join(bpy.app.tempdir, "osl_camera_ops.png")
    bpy.ops.render.render(write_still=False)
    sys.stdout.flush()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--projection", default="PERSP")
    parser.add_argument("--camera", choices=("exact", "minimal"), default="exact")
    parser.add_argument("--beta", default="0,0,0")
    parser.add_argument("--render", action="store_true", help=argparse.SUPPRESS)  # the child process
    parser.add_argument("--print", action="store_true", help="print every operation, not only the counts")
    options = parser.parse_args()
    beta = tuple(float(b) for b in options.beta.split(","))
    if options.render:
        from relativity_addon.blender.common import compat

        compat.run_main(lambda: _render(options.projection, options.camera, beta))
        return
    ops = optimised_camera_ops(options.projection, options.camera, beta)
    if options.print:
        print(" ".join(ops))
    counts = work_ops(ops)
    print(f"{options.camera} camera, {options.projection}, beta {beta}: {sum(counts.values())} operations per sample")
    print("  " + ", ".join(f"{name} {count}" for name, count in sorted(counts.items())))


if __name__ == "__main__":
    sys.path.insert(0, ROOT)
    main()
