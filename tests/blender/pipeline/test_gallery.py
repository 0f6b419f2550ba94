"""The gallery (examples/gallery.py) end to end at a tiny size: every figure renders, and one
physical number per family is right.

Expected values come from docs/physics.md and docs/spectral-model.md: the searchlight ratio of
two renders that differ only in it is the brightness-weighted mean of D^4 (D^1 for Chang et
al.'s), a blackbody seen at D shows Y(D T) / (D^5 Y(T)) of its rest brightness under the
paper's "Doppler only" (Y from colour-science here) and Y(D T) / Y(T) with the searchlight,
Gray's detector-plane shutter images the sphere array sharply at the grid points while the
aperture-plane one (and the phase hologram of the lens) blurs it, the fixed-point-surface shutter
keeps the focus plane in place, the Lorentz window gives the photo (and the stereo pair) at rest (with
the detector-plane shutter only nearly), and time of flight alone puts a sphere where the light-delay
geometry x_seen = x + beta r does.
"""

import json
import re
import subprocess
import sys

import numpy as np
import pytest

import pipeline_helpers as wh

GALLERY_SCRIPT = wh.REPO_ROOT / "examples" / "gallery.py"
TEMPERATURE = 5762.0
# Blender prints log lines of its own to stdout (this one in a Debian root without /proc/mounts)
NOISY_PYTHON = """
import runpy, sys
print("Could not get a list of mounted file-systems", flush=True)
script = sys.argv[1]
sys.argv = sys.argv[1:]
runpy.run_path(script, run_name="__main__")
"""


def _figure_names(python, tmp_path):
    """The gallery's figure names as a script reads them (``python``: the interpreter's command),
    from the file ``--list-file`` writes, where Blender's own log lines cannot go."""
    list_file = tmp_path / "figures.txt"
    result = subprocess.run(
        [*python, str(GALLERY_SCRIPT), f"--list-file={list_file}"],
        capture_output=True,
        text=True,
        timeout=120,
        env=wh._env(),
    )
    assert result.returncode == 0, result.stderr[-2000:]
    return list_file.read_text().split()


def test_gallery_figure_names_ignore_blender_log_lines(tmp_path):
    """The names are those of the figures in docs/gallery, whatever Blender prints besides."""
    names = _figure_names([sys.executable, "-c", NOISY_PYTHON], tmp_path)
    in_docs = [path.stem for path in (wh.REPO_ROOT / "docs" / "gallery").glob("*.png") if path.stem != "contact_sheet"]
    assert len(in_docs) == 27
    assert sorted(names) == sorted(in_docs)
    assert all(re.fullmatch(r"(weiskopf|gray|cockpit)_[a-z0-9_]+", name) for name in names), names


def _y(temperature):
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    return colour.sd_to_XYZ(colour.sd_blackbody(temperature, shape), cmfs, method="Integration")[1]


CONTACT_SHEET = """
import json, sys
from pathlib import Path
import bpy
import numpy as np
out = Path(sys.argv[1])
sys.argv = ["gallery.py"]
sys.path.insert(0, "examples")
import gallery
names = list(gallery.FIGURES)
for index, name in enumerate(names):  # flat tiles, each its own dark colour
    image = bpy.data.images.new(name, 24, 18)
    image.pixels.foreach_set(np.tile([(index + 1) / 64, 0.1, 0.3, 1.0], 24 * 18).astype(np.float32))
    image.filepath_raw = str(out / f"{name}.png")
    image.file_format = "PNG"
    image.save()
gallery.contact_sheet(out, names)
(out / "names.json").write_text(json.dumps(names))
"""


def test_contact_sheet_labels_every_panel(factory_blender, tmp_path):
    """Below each panel, light text as wide as the figure's name is long (the panels are flat dark
    colours here, so only a label can put light pixels under them)."""
    result = wh.run_python(CONTACT_SHEET, tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    names = json.loads((tmp_path / "names.json").read_text())
    sheet = wh.read_image(factory_blender, tmp_path / "contact_sheet.png")[..., :3]
    ink = sheet.min(axis=-1) > 0.5
    widths = []
    for name in names:
        colour = wh.read_image(factory_blender, tmp_path / f"{name}.png")[0, 0, :3]
        panel = (np.abs(sheet - colour) < 0.5 / 255).all(axis=-1)
        rows, columns = np.nonzero(panel)
        assert rows.size > 1000, name  # the panel, scaled up
        below = ink[rows.max() + 1 : rows.max() + 19, columns.min() : columns.max() + 1]
        assert below.sum() > 30, f"no label under {name}"
        inked = np.nonzero(below.any(axis=0))[0]
        widths.append(inked.max() - inked.min())
    lengths = [len(name) for name in names]
    assert np.corrcoef(lengths, widths)[0, 1] > 0.95, list(zip(names, widths, strict=True))


def test_gallery_renders_every_figure(factory_blender, tmp_path):
    names = _figure_names([sys.executable], tmp_path)
    assert len(names) == 27
    result = subprocess.run(
        [sys.executable, str(GALLERY_SCRIPT), f"--out={tmp_path}", "--size=64x48", "--samples=2"],
        capture_output=True,
        text=True,
        timeout=600,
        env=wh._env(),
    )
    assert result.returncode == 0, result.stderr[-2000:]
    for name in names:
        image = wh.read_image(factory_blender, tmp_path / f"{name}.png")
        assert image.shape == (48, 64, 4) and np.isfinite(image).all(), name
        assert image[..., :3].max() > 0.2, f"{name} is black"
    sheet = wh.read_image(factory_blender, tmp_path / "contact_sheet.png")
    assert sheet.shape[0] > 48 and sheet[..., :3].max() > 0.2
    numbers = json.loads((tmp_path / "measurements.json").read_text())["numbers"]
    print(json.dumps(numbers, indent=1))

    # Weiskopf Figs. 5-7: searchlight ratio D^4 (D at the centre ~2.8), Chang's D^1
    fig7, fig6 = numbers["weiskopf_fig7_street_searchlight"], numbers["weiskopf_fig6_street_chang"]
    assert fig7["centre brightness / Fig. 5"] == pytest.approx(fig7["centre expected <D^4>"], rel=0.15)
    assert fig6["centre brightness / Fig. 5"] == pytest.approx(fig6["centre expected <D^1>"], rel=0.1)
    assert fig7["centre brightness / Fig. 5"] > 10 * fig6["centre brightness / Fig. 5"] > 10

    # Weiskopf Figs. 8-9: blackbody brightness against colour-science at each Sun's D
    fig8, fig9 = numbers["weiskopf_fig8_sun_doppler"], numbers["weiskopf_fig9_sun_doppler_searchlight"]
    suns = [key.split(" mean D")[0] for key in fig8 if key.endswith("mean D")]
    assert len(suns) >= 4
    ds = []
    for sun in suns:
        d = fig8[f"{sun} mean D"]
        ds.append(d)
        ratio = _y(d * TEMPERATURE) / _y(TEMPERATURE)
        assert fig8[f"{sun} brightness / rest"] == pytest.approx(ratio / d**5, rel=0.05), sun
        if f"{sun} mean D" in fig9:
            assert fig9[f"{sun} brightness / rest"] == pytest.approx(
                _y(fig9[f"{sun} mean D"] * TEMPERATURE) / _y(TEMPERATURE), rel=0.05
            ), sun
    assert min(ds) < 0.8 and max(ds) > 1.1

    # Gray Fig. 1(b): a sphere where aberration puts it; Figs. 4-5: coma versus sharp
    fig1b = numbers["gray_fig1b_pinhole"]
    assert abs(fig1b["red sphere centroid x (px)"] - fig1b["pinhole aberration formula x (px)"]) < 0.5
    assert abs(fig1b["red sphere centroid y (px)"] - fig1b["pinhole aberration formula y (px)"]) < 0.5
    assert numbers["gray_fig5_detector_plane"]["spot centroid to grid pixel, max (px)"] < 1.0
    assert numbers["gray_fig4_aperture_plane_huge"]["RMS radius / Fig. 5's (same aperture 0.2), median"] > 1.2
    # Fig. 6(b): the phase hologram blurs the array the ideal lens (Figs. 5, 6a) keeps sharp
    assert numbers["gray_fig6b_phase_hologram"]["RMS radius / Fig. 5's (same aperture 0.2), median"] > 1.2
    # Gray Fig. 1(c): time of flight only puts the sphere where x_seen = x + beta r does
    fig1c = numbers["gray_fig1c_time_of_flight_enlarged"]
    assert abs(fig1c["red sphere centroid x (px)"] - fig1c["time-of-flight formula x (px)"]) < 0.5
    assert abs(fig1c["red sphere centroid y (px)"] - fig1c["time-of-flight formula y (px)"]) < 0.5
    # Gray Fig. 8: the focus plane stays put; Fig. 9: the Lorentz window gives the photo at rest
    fig8b = numbers["gray_fig8b_fixed_point_surface"]
    assert fig8b["red discs found"] == 4
    assert fig8b["red discs in the focus plane, max shift from Fig. 8(a) (px)"] < 0.25
    assert fig8b["mean |Fig. 8(b) - Fig. 8(a)|, whole image"] > 0.01
    window, moving = numbers["gray_fig9c_lorentz_window"], numbers["gray_fig9b_moving"]
    assert window["mean |image - Fig. 9(a)|"] < 0.05 * moving["mean |image - Fig. 9(a)|"]
    # Fig. 10: the window with the detector-plane shutter undoes the distortion only imperfectly
    fig10 = numbers["gray_fig10_window_detector_plane"]
    assert (
        10 * window["mean |image - Fig. 9(a)|"]
        < fig10["mean |image - Fig. 9(a)|"]
        < 0.5 * moving["mean |image - Fig. 9(a)|"]
    )
    # ... where the physics core's window rays put the backdrop
    assert (
        fig10["strips: mean |Fig. 10 - Fig. 9(a) moved by the physics core|"]
        < 0.5 * fig10["strips: mean |Fig. 10 - Fig. 9(a)|"]
    )
    # Gray Fig. 11: the stereo pair through the window is the pair at rest
    window, moving = numbers["gray_fig11c_stereo_lorentz_window"], numbers["gray_fig11b_stereo_moving"]
    assert window["mean |image - Fig. 11(a)|"] < 0.05 * moving["mean |image - Fig. 11(a)|"]
