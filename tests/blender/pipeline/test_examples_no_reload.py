"""The example scripts enable the add-on once: no "module changed on disk ... reloading" line.

addon_utils prints that line and reloads the package's ``__init__`` when it enables a package that
was imported without it (the scripts import the add-on's helpers first); what follows then runs on
a package half old, half new.
"""

import subprocess
import sys

import pipeline_helpers as wh

RELOAD_LINE = "changed on disk"


def _run(*command):
    result = subprocess.run(
        [sys.executable, *[str(part) for part in command]],
        capture_output=True,
        text=True,
        timeout=300,
        env=wh._env(),
        cwd=wh.REPO_ROOT,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    return result.stdout + result.stderr


def test_demo_enables_the_addon_once(tmp_path):
    out = tmp_path / "demo.png"
    output = _run(
        wh.REPO_ROOT / "examples" / "demo_still.py",
        f"--out={out}",
        "--width=16",
        "--height=12",
        "--samples=1",
    )
    assert out.is_file()
    assert f"wrote {out}" in output
    assert RELOAD_LINE not in output, [line for line in output.splitlines() if RELOAD_LINE in line]


def test_gallery_enables_the_addon_once(tmp_path):
    output = _run(
        wh.REPO_ROOT / "examples" / "gallery.py",
        "--only=gray_fig1a_rest",
        f"--out={tmp_path}",
        "--size=16x12",
        "--samples=1",
    )
    assert (tmp_path / "gray_fig1a_rest.png").is_file()
    assert RELOAD_LINE not in output, [line for line in output.splitlines() if RELOAD_LINE in line]


def test_batch_render_enables_the_addon_once(factory_blender, tmp_path):
    wh.new_scene(factory_blender, resolution=(16, 12), samples=1)
    blend = wh.save_blend(factory_blender, tmp_path / "plain.blend")
    out = tmp_path / "frame.png"
    output = _run(wh.RENDER_SCRIPT, blend, "--beta=0,0,-0.5", "--samples=1", f"--out={out}")
    assert out.is_file()
    assert RELOAD_LINE not in output, [line for line in output.splitlines() if RELOAD_LINE in line]
