"""``demo_still.py --panels`` (what ``./dev.sh demo`` runs) writes the README's image: the three
runs the README names, at rest (``--speed 0``), the default (moving) and ``--doppler``, side by
side with 4 px of white between them."""

import subprocess
import sys

import numpy as np

import pipeline_helpers as wh

DEMO_SCRIPT = wh.REPO_ROOT / "examples" / "demo_still.py"
SIZE = ["--width=16", "--height=12", "--samples=1"]


def _demo(out, *options):
    result = subprocess.run(
        [sys.executable, str(DEMO_SCRIPT), f"--out={out}", *SIZE, *options],
        capture_output=True,
        text=True,
        timeout=300,
        env=wh._env(),
    )
    assert result.returncode == 0, result.stderr[-2000:]
    return out


def test_demo_panels_are_the_three_runs(factory_blender, tmp_path):
    runs = [
        _demo(tmp_path / f"{name}.png", *options)
        for name, options in (
            ("rest", ["--speed=0"]),
            ("moving", []),
            ("doppler", ["--doppler"]),
        )
    ]
    panels = wh.read_image(factory_blender, _demo(tmp_path / "panels.png", "--panels"))
    assert panels.shape == (12, 3 * 16 + 2 * 4, 4)
    singles = [wh.read_image(factory_blender, path) for path in runs]
    for index, single in enumerate(singles):
        panel = panels[:, index * 20 : index * 20 + 16]
        assert np.abs(panel - single).max() < 2.5 / 255, index
    for gap in (panels[:, 16:20], panels[:, 36:40]):
        assert (gap[..., :3] == 1.0).all()
    # the three differ: motion shrinks and darkens the view, Doppler colour changes it again
    assert np.abs(singles[0] - singles[1]).mean() > 0.02
    assert np.abs(singles[1] - singles[2]).mean() > 0.02
