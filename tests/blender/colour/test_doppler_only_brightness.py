"""Doppler colour without the searchlight, both definitions (scene.relativity.doppler_only_brightness).

- SPECTRUM, Weiskopf et al. (1999) Fig. 8's "Doppler only": the shifted spectrum ``L(lambda D)``
  with no further factor. A blackbody at ``T`` becomes ``D^-5 B(lambda, D T)`` (Planck's law,
  docs/spectral-model.md), so its visible luminance is ``Y(D T) / (D^5 Y(T))`` of the rest value.
- REST (the default): the colour of the blackbody at ``D T`` at the rest luminance.

A blackbody wall fills the view of the exact camera; renders go through ``examples/render.py``.
Expected ratios from colour-science (Planck spectra through the CIE 1931 observer) at the
Doppler factor of each pixel's camera-frame viewing direction (docs/physics.md).
"""

import pytest
from test_doppler_camera_path import _camera_frame_doppler, _render, _wall_scene

import colour_helpers as dh
from colour_helpers import ch

TEMPERATURE = 5762.0
WINDOW = (slice(22, 26), slice(30, 34))


@pytest.mark.parametrize("beta_z", [-0.5, 0.5], ids=["approaching", "receding"])
def test_doppler_only_spectrum_and_rest_brightness(relativity_addon, factory_blender, tmp_path, beta_z):
    bpy = factory_blender
    scene, camera, blend = _wall_scene(
        bpy, tmp_path, temperature=TEMPERATURE, name="spectrum", doppler_only_brightness="SPECTRUM"
    )
    scene.relativity.doppler_only_brightness = "REST"
    rest_blend = ch.save_blend(bpy, tmp_path / "rest_brightness.blend")
    beta = (0.0, 0.0, beta_z)
    at_rest = _render(bpy, blend, tmp_path / "at_rest.exr", (0.0, 0.0, 0.0))
    spectrum = _render(bpy, blend, tmp_path / "spectrum.exr", beta, "--no-searchlight")
    rest_brightness = _render(bpy, rest_blend, tmp_path / "rest_brightness.exr", beta, "--no-searchlight")

    def y(image):
        return dh.linear_rec709_to_xyz(image[WINDOW].reshape(-1, 3).mean(0))[1]

    d = _camera_frame_doppler(bpy, scene, camera, beta)[WINDOW].mean()
    y_dt = dh.blackbody_xyz_colour_science(d * TEMPERATURE)[1]
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    expected = y_dt / (d**5 * y_t)
    measured = y(spectrum) / y(at_rest)
    kept = y(rest_brightness) / y(at_rest)
    delta_e = dh.delta_e_2000_normalised(
        dh.linear_rec709_to_xyz(spectrum[WINDOW].reshape(-1, 3).mean(0)),
        dh.blackbody_xyz_colour_science(d * TEMPERATURE),
    )
    print(
        f"D = {d:.4f}: SPECTRUM Y ratio {measured:.4f} vs Y(DT)/(D^5 Y(T)) {expected:.4f} "
        f"(D^-5 = {d**-5:.4f}, Y(DT)/Y(T) = {y_dt / y_t:.4f}); REST {kept:.4f}; Delta E 2000 {delta_e:.3f}"
    )
    assert abs(expected - 1.0) > 0.2  # the two definitions differ here
    assert measured == pytest.approx(expected, rel=0.02)
    assert kept == pytest.approx(1.0, rel=0.02)
    assert delta_e < 1.0  # the colour is the same in both: the blackbody at D T
