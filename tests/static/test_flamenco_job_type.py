"""The Flamenco 3 job type (flamenco/relativistic_render.js): valid JavaScript (esprima, a parser
from the Python registry, always; node's own parser where node is installed), and, run in node
with stand-ins for Flamenco's ``author``/``path``/``print``, its tasks' command lines are ones the
batch script accepts, covering the frame range once in chunks."""

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from flamenco_harness import compile_job

REPO_ROOT = Path(__file__).resolve().parents[2]
JOB_TYPE = REPO_ROOT / "flamenco" / "relativistic_render.js"
NODE = shutil.which("node") or shutil.which("nodejs")


def test_job_type_parses_as_javascript():
    import esprima  # pinned in requirements/blender-*.txt: this check runs everywhere

    program = esprima.parseScript(JOB_TYPE.read_text(encoding="utf-8"))
    names = {node.id.name for node in program.body if node.type == "FunctionDeclaration"}
    declared = {
        declaration.id.name
        for node in program.body
        if node.type == "VariableDeclaration"
        for declaration in node.declarations
    }
    assert "compileJob" in names and "JOB_TYPE" in declared  # what Flamenco's job compiler calls
    with pytest.raises(esprima.Error):
        esprima.parseScript(JOB_TYPE.read_text(encoding="utf-8") + "\nfunction broken( {")


@pytest.mark.skipif(NODE is None, reason="no node (JavaScript engine) on PATH; the esprima parse above still runs")
def test_job_type_compiles_tasks_the_batch_script_accepts():
    from relativity_addon import batch

    assert subprocess.run([NODE, "--check", str(JOB_TYPE)], capture_output=True).returncode == 0
    settings = {
        "frames": "3-12",
        "chunk_size": 4,
        "render_script": "/farm/relativity/examples/render.py",
        "render_output_root": "/farm/out",
        "file_format": "exr",
        "beta": "0, 0.9, 0",
        "velocity_from_animation": False,
        "method": "geometry",
        "samples": 16,
        "spectral_passes": 0,
        "resume": True,
        "extra_args": "--seed=3  --no-searchlight",
        "blendfile": "/farm/shot.blend",
    }
    result = compile_job([NODE], JOB_TYPE, settings)
    assert result.returncode == 0, result.stderr
    compiled = json.loads(result.stdout)
    assert set(settings) <= set(compiled["keys"])
    parser = batch.build_parser(with_blend_file=False)
    covered = []
    for task in compiled["tasks"]:
        (command,) = task["commands"]
        assert task["type"] == "blender" and command["type"] == "blender-render"
        parameters = command["parameters"]
        assert parameters["blendfile"] == "/farm/shot.blend" and parameters["exe"] == "{blender}"
        args = parameters["args"]
        assert args[:3] == ["--python", "/farm/relativity/examples/render.py", "--"]
        options = parser.parse_args(args[3:])  # the batch script's parser, Blender form
        assert options.out == "/farm/out/shot/frame_####.exr"
        assert options.beta == (0.0, 0.9, 0.0) and options.method == "geometry" and options.samples == 16
        assert options.seed == 3 and options.no_searchlight and options.resume
        assert not options.velocity_from_animation and options.spectral is None
        first, last = options.frames
        covered += range(first, last + 1)
    assert covered == list(range(3, 13)) and len(compiled["tasks"]) == 3  # 3-6, 7-10, 11-12

    bad = compile_job([NODE], JOB_TYPE, {**settings, "frames": "1,5"})
    assert bad.returncode != 0 and "frames must be FIRST-LAST" in bad.stderr


BAKED_JOB_TYPE = REPO_ROOT / "flamenco" / "relativistic_render_baked.js"


def test_baked_job_type_parses_as_javascript():
    import esprima

    program = esprima.parseScript(BAKED_JOB_TYPE.read_text(encoding="utf-8"))
    names = {node.id.name for node in program.body if node.type == "FunctionDeclaration"}
    assert "compileJob" in names


@pytest.mark.skipif(NODE is None, reason="no node (JavaScript engine) on PATH; the esprima parse above still runs")
def test_baked_job_type_renders_with_plain_blender_and_scripts_disabled():
    """The variant for baked files: each task is plain Blender's animation render of its chunk
    (no --python), with scripts disabled after Flamenco's own arguments, covering the range once."""
    assert subprocess.run([NODE, "--check", str(BAKED_JOB_TYPE)], capture_output=True).returncode == 0
    settings = {
        "frames": "1-10",
        "chunk_size": 4,
        "render_output_root": "/farm/out",
        "file_format": "exr",
        "blendfile": "/farm/shot_baked.blend",
    }
    result = compile_job([NODE], BAKED_JOB_TYPE, settings)
    assert result.returncode == 0, result.stderr
    compiled = json.loads(result.stdout)
    assert set(settings) <= set(compiled["keys"])
    covered = []
    for task in compiled["tasks"]:
        (command,) = task["commands"]
        parameters = command["parameters"]
        assert parameters["blendfile"] == "/farm/shot_baked.blend" and parameters["exeArgs"] == "{blenderArgs}"
        assert parameters["argsBefore"] == ["--disable-autoexec"]
        args = parameters["args"]
        assert "--python" not in args and args[-1] == "--render-anim"
        values = dict(zip(args[:-1:2], args[1:-1:2], strict=True))
        assert values["--render-output"] == "/farm/out/shot/frame_####"
        assert values["--render-format"] == "OPEN_EXR"
        covered += range(int(values["--frame-start"]), int(values["--frame-end"]) + 1)
    assert covered == list(range(1, 11)) and len(compiled["tasks"]) == 3
