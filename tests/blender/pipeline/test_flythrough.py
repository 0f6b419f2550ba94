"""The fly-through example end to end at a tiny size: scene, keyframed acceleration, PNG frames."""

import subprocess
import sys

import numpy as np

import pipeline_helpers as wh


def test_flythrough_renders_a_short_sequence(factory_blender, tmp_path):
    out = tmp_path / "fly"
    command = [
        sys.executable,
        str(wh.FLYTHROUGH_SCRIPT),
        f"--out={out}",
        "--frames=3",
        "--resolution=64x48",
        "--samples=1",
        "--beta-max=0.9",
    ]
    result = subprocess.run(command, capture_output=True, text=True, timeout=300, env=wh._env())
    assert result.returncode == 0, result.stderr[-2000:]
    assert "ffmpeg -framerate 24 -i" in result.stdout and "fly_%04d.png" in result.stdout
    assert (out / "flythrough.blend").is_file()
    frames = [wh.read_image(factory_blender, out / f"fly_{frame:04d}.png") for frame in (1, 2, 3)]
    for image in frames:
        assert image.shape == (48, 64, 4) and np.isfinite(image).all()
        assert image[..., :3].mean() > 0.05  # lit street, not a black frame
    # The camera speeds up: the view ahead contracts, so consecutive frames differ.
    assert np.abs(frames[0] - frames[1]).mean() > 0.01 and np.abs(frames[1] - frames[2]).mean() > 0.01

    bad = subprocess.run(
        [sys.executable, str(wh.FLYTHROUGH_SCRIPT), f"--out={out}", "--beta-max=1.2"],
        capture_output=True,
        text=True,
        timeout=120,
        env=wh._env(),
    )
    assert bad.returncode == 1 and bad.stderr.strip().splitlines()[-1].startswith("flythrough.py: error:")
