"""Issue 28: "a Flamenco job type variant renders a baked file with plain Blender", run for real.

A file baked for Render Anywhere by the add-on (the ``bpy`` wheel) is rendered by Debian's plain
Blender executable, with no add-on installed and scripts disabled, through exactly the commands
that flamenco/relativistic_render_baked.js compiles for Flamenco's workers (compiled by node in the
same root, as Flamenco's Manager compiles job types; the tasks' ``blender-render`` commands run as
a worker runs them: ``{blender} {blenderArgs} argsBefore blendfile args``, with Flamenco's default
blenderArgs ``-b -y``). Each frame must equal the add-on's own render of it (same seed) to well
below the render noise, measured as the difference the seed alone makes.

Debian's Blender has no OSL, so the scene is one whose bake needs none: the Apparent Geometry bake
tests' box keyframed at 0.8c across the view of a camera at rest, lit by a lamp at rest (its final
render is the scene-frame retarded meshes, played back per frame from the file).
"""

import json
import shlex
import shutil
from pathlib import Path

import numpy as np
from bake_scenes import FRAMES, build_moving_box
from flamenco_harness import HARNESS

from pipeline_helpers import ch

JOB_TYPE = Path(__file__).resolve().parents[2] / "flamenco" / "relativistic_render_baked.js"
FLAMENCO_BLENDER_ARGS = ["-b", "-y"]  # Flamenco's default {blenderArgs}


def test_flamenco_baked_job_type_renders_with_debian_s_plain_blender(
    relativity_addon, factory_blender, tmp_path, root_work
):
    bpy = factory_blender
    work, inside, run = root_work
    scene = build_moving_box(bpy, fly=False)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    own = []
    for frame in FRAMES:
        scene.frame_set(frame)
        own.append(ch.render_exr(bpy, scene, tmp_path / f"own_{frame}.exr"))
    scene.cycles.seed = 8  # the render noise: the same frame with another seed
    noise = float(np.abs(ch.render_exr(bpy, scene, tmp_path / "own_seed8.exr") - own[-1]).mean())
    scene.cycles.seed = 7
    scene.render.use_file_extension = True  # as a file is saved for a farm (render_exr turned it off)
    bpy.ops.wm.save_as_mainfile(filepath=str(work / "unbaked.blend"), check_existing=False, copy=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(work / "baked.blend"), check_existing=False)
    assert bpy.ops.relativity.bake_render_anywhere(frame_start=FRAMES[0], frame_end=FRAMES[-1]) == {"FINISHED"}
    bpy.ops.wm.save_as_mainfile(filepath=str(work / "baked.blend"), check_existing=False)

    # the job, compiled in the root by node the way Flamenco's Manager compiles it
    (work / "harness.js").write_text("process.argv.splice(1, 1);\n" + HARNESS)
    shutil.copy(JOB_TYPE, work / JOB_TYPE.name)
    settings = {
        "frames": f"{FRAMES[0]}-{FRAMES[-1]}",
        "chunk_size": 2,  # two tasks: frames 1-2, then 3 alone (a chunk starting inside the range)
        "render_output_root": f"{inside}/out",
        "file_format": "exr",
        "blendfile": f"{inside}/baked.blend",
    }
    compiled = run(
        f"node {inside}/harness.js {inside}/{JOB_TYPE.name} '{json.dumps(settings)}' > {inside}/job.json",
    )
    assert compiled.returncode == 0, compiled.stderr[-3000:]
    tasks = json.loads((work / "job.json").read_text())["tasks"]
    assert len(tasks) == 2

    commands = []
    for task in tasks:
        (command,) = task["commands"]
        parameters = command["parameters"]
        assert command["type"] == "blender-render" and parameters["exe"] == "{blender}"
        line = ["blender", *FLAMENCO_BLENDER_ARGS, *parameters["argsBefore"], parameters["blendfile"]]
        commands.append(shlex.join([*line, *parameters["args"]]))
    # the control: the first task on the file before the bake, into another folder
    control = commands[0].replace(f"{inside}/baked.blend", f"{inside}/unbaked.blend").replace("/out/", "/control/")
    # a worker of its own: a fresh home, so no add-on is installed and no preferences are read
    script = f"export HOME={inside}/home LANG=C.UTF-8\nmkdir -p $HOME\n" + "\n".join([*commands, control]) + "\n"
    rendered = run(script)
    log = rendered.stdout + rendered.stderr
    assert rendered.returncode == 0, log[-4000:]
    assert "Traceback" not in log and "Relativity:" not in log, log[-4000:]  # nothing of the add-on ran

    plain = [ch.read_exr(bpy, work / "out" / "shot" / f"frame_{frame:04d}.exr") for frame in FRAMES]
    differences = [float(np.abs(p - o).mean()) for p, o in zip(plain, own, strict=True)]
    moving = float(np.abs(own[-1] - own[0]).mean())
    stale = float(np.abs(ch.read_exr(bpy, work / "control" / "shot" / "frame_0001.exr") - own[0]).mean())
    print(
        f"mean |Debian's Blender - add-on| {differences}, not baked {stale:.4g}, noise {noise:.4g}, moving {moving:.4g}"
    )
    assert moving > 2.0 * noise, "the frames differ (the box moves)"
    assert stale > 0.1 * noise, "the same commands on the file not baked render something else"
    assert max(differences) < 0.1 * noise, f"Debian's frames differ: {differences} (noise {noise:.4g})"
