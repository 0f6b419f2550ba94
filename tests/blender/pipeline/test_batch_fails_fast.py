"""The batch script and the examples refuse at once what cannot work: an --out nowhere to be
written (checked before the .blend is loaded or anything rendered), and a Python without bpy (one
line saying what to run instead, no traceback)."""

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
