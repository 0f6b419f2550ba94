"""The batch script and the examples refuse at once what cannot work: an --out nowhere to be
written (checked before the .blend is loaded or anything rendered), and a Python without bpy (one
line saying what to run instead, no traceback)."""

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
