"""The batch script and the examples refuse at once what cannot work: an --out nowhere to be
written (checked before the .blend is loaded or anything rendered), a Python without bpy (one
line saying what to run instead, no traceback), and every bad option that needs no scene (refused
before ``import bpy``: a typo costs no Blender load; ``--help`` neither)."""

import subprocess
import sys

import pytest

import pipeline_helpers as wh


@pytest.fixture
def plain_blend(factory_blender, tmp_path):
    bpy = factory_blender
    wh.new_scene(bpy, samples=1)
    return wh.save_blend(bpy, tmp_path / "plain.blend")


def _assert_refused_before_loading(result, out):
    wh.assert_fails_with(result, str(out))
    # Nothing was loaded or rendered: Blender prints these when it opens the file and renders.
    assert "Read blend" not in result.stdout, result.stdout[-2000:]
    assert not [line for line in result.stdout.splitlines() if line.startswith("Fra:")], result.stdout[-2000:]
    assert "render.py: frame" not in result.stdout


@pytest.mark.parametrize("below", ["out.png", "sub/out.png"])
def test_out_under_a_file(plain_blend, tmp_path, below):
    not_a_folder = tmp_path / "notes.txt"
    not_a_folder.write_text("a file, not a folder\n")
    out = not_a_folder / below
    result = wh.run_render_script(plain_blend, "--beta=0,0,-0.5", "--samples=1", f"--out={out}")
    _assert_refused_before_loading(result, out)
    assert f"{not_a_folder} is a file" in wh.error_lines(result)[0]
    assert not_a_folder.read_text() == "a file, not a folder\n"


@pytest.mark.parametrize("out", ["/proc/relativity-out.png", "/proc/relativity-folder/out.png"])
def test_out_where_no_file_can_be_created(plain_blend, out):
    """/proc takes no new files, even from root (the tests run as root, for whom permission bits
    do not count)."""
    result = wh.run_render_script(plain_blend, "--beta=0,0,-0.5", "--samples=1", f"--out={out}")
    _assert_refused_before_loading(result, out)
    assert "cannot create files in /proc" in wh.error_lines(result)[0]


BLOCK_BPY = """
import runpy, sys
sys.modules["bpy"] = None  # a Python without Blender's module
script = sys.argv[1]
sys.argv = sys.argv[1:]
runpy.run_path(script, run_name="__main__")
"""


@pytest.mark.parametrize(
    "script, options",
    [
        ("render.py", ["scene.blend", "--out=out.png"]),
        ("demo_still.py", ["--out=out.png"]),
        ("flythrough.py", []),
        ("gallery.py", []),
    ],
)
def test_examples_without_bpy_say_what_to_run(script, options, tmp_path):
    path = wh.REPO_ROOT / "examples" / script
    result = subprocess.run(
        [sys.executable, "-c", BLOCK_BPY, str(path), *options],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert result.returncode == 1, (result.returncode, result.stderr[-2000:])
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "needs Blender's Python or the bpy module" in lines[0], result.stderr[-2000:]
    assert "./dev.sh demo" in lines[0] and f"--python examples/{script}" in lines[0]
    assert "Traceback" not in result.stdout + result.stderr


# Runs a script in a Python where importing bpy ends the process loudly (status 97); the names in
# the first argument (comma-separated) are hidden, as if not installed.
LOUD_BPY = """
import importlib.abc, importlib.util, os, runpy, sys


class LoudLoader(importlib.abc.Loader):
    def create_module(self, spec):
        return None

    def exec_module(self, module):
        sys.stderr.write("bpy was imported\\n")
        sys.stderr.flush()
        os._exit(97)


class LoudFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        return importlib.util.spec_from_loader(name, LoudLoader()) if name == "bpy" else None


sys.meta_path.insert(0, LoudFinder())
for hidden in filter(None, sys.argv[1].split(",")):
    sys.modules[hidden] = None
script = sys.argv[2]
sys.argv = sys.argv[2:]
runpy.run_path(script, run_name="__main__")
"""


def _run_without_bpy(blend, *options, hidden=()):
    command = [sys.executable, "-c", LOUD_BPY, ",".join(hidden), str(wh.RENDER_SCRIPT), str(blend), *options]
    return subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=blend.parent)


@pytest.fixture
def any_blend(tmp_path):
    """A file named .blend: nothing here opens it."""
    path = tmp_path / "scene.blend"
    path.write_bytes(b"")
    return path


@pytest.mark.parametrize(
    "options, reason",
    [
        # the bad options test_batch_script checked with a real .blend (one subprocess each, loading
        # Blender): refused the same way, before bpy
        (("--frames=4-2",), "last frame before first"),
        (("--frames=x",), "FIRST-LAST"),
        (("--frame=1", "--frames=1-2"), "not allowed with"),
        (("--frame=two",), "invalid int"),
        (("--resolution=64by48",), "WIDTHxHEIGHT"),
        (("--resolution=0x48",), "positive"),
        (("--samples=0",), "positive integer"),
        (("--method=fast",), "invalid choice"),
        (("--beta=0.8,0.6,0",), "Observer velocity beta: speed |beta| = 1 must be below 1"),
        (("--beta=0,0,-1.5",), "Observer velocity beta: speed |beta| = 1.5 must be below 1"),
        (("--beta=inf,0,0",), "--beta must be finite"),
        (("--beta=0,0,-0.5", "--velocity-from-animation"), "not both"),
        (("--unknown-option",), "unrecognized"),
        # and the rest that needs no scene
        (("--out=x.jpg",), "--out must end in .png or .exr, got 'x.jpg'"),
        (("--bake-to=baked.txt",), "--bake-to must name a .blend file"),
        (("--beta=0,0,0.5",), "the following arguments are required: --out (or --bake-to)"),
        (("--stereo=anaglyph", "--spectral=2"), "--stereo and --spectral cannot be combined"),
        (("--reference", "--spectral=2"), "--spectral needs the exact camera"),
        (("--reference", "--proper-time"), "--proper-time steps a relativistic observer's clock"),
        (("--shutter-plane-normal=0,nan,1",), "--shutter-plane-normal must be finite"),
        (("--window-time=inf",), "--window-time must be finite"),
    ],
)
def test_bad_option_refused_before_loading_bpy(any_blend, options, reason):
    if not any(option.startswith(("--out", "--bake-to")) for option in options) and "--out" not in reason:
        options = (*options, "--out=never.png")
    result = _run_without_bpy(any_blend, *options)
    assert "bpy was imported" not in result.stderr, (options, result.stderr[-2000:])
    wh.assert_fails_with(result, reason)
    assert not (any_blend.parent / "never.png").exists()


def test_missing_blend_and_missing_dask_refused_before_loading_bpy(tmp_path, any_blend):
    result = _run_without_bpy(tmp_path / "nope.blend", "--out=x.png")
    assert "bpy was imported" not in result.stderr, result.stderr[-2000:]
    wh.assert_fails_with(result, f"no such .blend file: {tmp_path / 'nope.blend'}")
    for where in ("--workers=2", "--scheduler=tcp://127.0.0.1:8786"):
        result = _run_without_bpy(any_blend, "--frames=1-2", "--out=x.png", where, hidden=("dask",))
        assert "bpy was imported" not in result.stderr, result.stderr[-2000:]
        wh.assert_fails_with(result, "--workers and --scheduler need Dask: pip install 'dask[distributed]'")


def test_help_needs_no_blender(any_blend):
    result = _run_without_bpy(any_blend, "--help")
    assert result.returncode == 0, result.stderr[-2000:]
    assert "usage: render.py" in result.stdout and "--velocity-from-animation" in result.stdout
    assert "bpy was imported" not in result.stderr


def test_a_good_command_line_does_load_bpy(any_blend):
    """The loud bpy is reached once the options pass: the tests above would see it."""
    result = _run_without_bpy(any_blend, "--beta=0,0,-0.5", "--out=x.png")
    assert result.returncode == 97 and "bpy was imported" in result.stderr, result.stderr[-2000:]


def test_speed_refused_before_loading_in_the_scene_words(factory_blender):
    """The check before the load says what the scene's own check says after it, on the speed as
    the scene stores it (32-bit floats: 0.6, 0.79999999 is light speed there, not in
    64 bits)."""
    import relativity_addon
    from relativity_addon import batch
    from relativity_addon.batch import options as batch_options
    from relativity_addon.blender.scene import snapshot
    from relativity_addon.errors import BatchError, RelativityError

    relativity_addon.register()
    try:
        scene, camera, _ = wh.new_scene(factory_blender)
        for beta in ("0,0,-1.5", "0.8,0.6,0", "0.6,0.79999999,0", "0.6,0.7999999,0", "0.1,0,0"):
            options = batch.build_parser(False).parse_args([f"--beta={beta}", "--out=x.png"])
            try:
                batch_options.check_combinations(options)
                before = None
            except BatchError as error:
                before = str(error)
            scene.relativity.velocity_source = "MANUAL"
            scene.relativity.beta = options.beta
            try:
                snapshot.observer_velocity(scene, camera, 1.0)
                after = None
            except RelativityError as error:
                after = str(error)
            assert before == after, beta
    finally:
        relativity_addon.unregister()
