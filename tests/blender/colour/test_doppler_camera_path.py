"""Doppler colour stage of the exact camera: F12 / batch renders give final colours.

Renders go through ``examples/render.py`` in a subprocess, as a user runs them (the camera
shader's D^4, the materials' blackbody shift and the compositor's Doppler matrix all come from
the .blend). A static emitter fills the view; the observer moves. Expected Doppler factors per
pixel: D = gamma (1 - beta . k), k the photon direction in the scene frame, equivalently
D = 1 / (gamma (1 - beta . d')) with d' the pixel's camera-frame viewing direction (docs/physics.md).
"""

import math

import numpy as np
import pytest

import colour_helpers as dh
from colour_helpers import ch

COLOUR = (0.3, 0.6, 0.2)


def _wall_scene(bpy, tmp_path, colour=COLOUR, temperature=None, name="wall", **settings):
    """One big emitter wall at z = -5 (covers the aberrated view at every speed used here);
    ``settings`` go into ``scene.relativity`` (needs the add-on registered)."""
    scene, camera = dh.emitter_scene(bpy)
    dh.add_emitter_plane(
        bpy, scene, "Wall", (-400.0, 400.0), (-400.0, 400.0), colour, beta=None, temperature=temperature
    )
    for key, value in settings.items():
        setattr(scene.relativity, key, value)
    blend = ch.save_blend(bpy, tmp_path / f"{name}.blend")
    return scene, camera, blend


def _camera_frame_doppler(bpy, scene, camera, beta):
    """D per pixel centre: 1 / (gamma (1 - beta . d)), d the camera-frame viewing direction."""
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    beta = np.asarray(beta, float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    return 1.0 / (gamma * (1.0 - view @ beta))


def _render(bpy, blend, out, beta, *options):
    return ch.render_image(bpy, blend, out, f"--beta={','.join(str(b) for b in beta)}", "--samples=4", *options)


def test_rest_is_identity_and_hue_moves_the_right_way(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, blend = _wall_scene(bpy, tmp_path)
    rest = _render(bpy, blend, tmp_path / "rest.exr", (0.0, 0.0, 0.0))
    print("rest: max |rgb - input| =", np.abs(rest - COLOUR).max())
    assert np.abs(rest - COLOUR).max() < 1e-3

    forward = _render(bpy, blend, tmp_path / "forward.exr", (0.0, 0.0, -0.5))  # toward the wall: D > 1
    backward = _render(bpy, blend, tmp_path / "backward.exr", (0.0, 0.0, 0.5))  # away: D < 1
    centre = (slice(20, 28), slice(28, 36))
    f, b = forward[centre].reshape(-1, 3).mean(0), backward[centre].reshape(-1, 3).mean(0)
    ratio = COLOUR[2] / COLOUR[0]
    print(f"b/r: rest {ratio:.3f}, forward {f[2] / f[0]:.3f}, backward {b[2] / b[0]:.3f}")
    assert f[2] / f[0] > 1.25 * ratio
    assert b[2] / b[0] < 0.8 * ratio


def test_colour_matches_doppler_matrix_per_pixel(factory_blender, tmp_path):
    from relativity_addon.physics import spectral

    bpy = factory_blender
    scene, camera, blend = _wall_scene(bpy, tmp_path)
    beta = (0.3, 0.0, -0.5)
    image = _render(bpy, blend, tmp_path / "oblique.exr", beta)
    d = _camera_frame_doppler(bpy, scene, camera, beta)
    expected = spectral.doppler_shift_rgb(COLOUR, d)
    inner = (slice(4, -4), slice(4, -4))
    error = np.abs(image[inner] - expected[inner]) / expected[inner].sum(-1, keepdims=True)
    print(f"D from {d.min():.3f} to {d.max():.3f}: max relative error {error.max():.4f}, mean {error.mean():.5f}")
    assert d.max() / d.min() > 1.3
    assert error.mean() < 0.005
    assert error.max() < 0.03


@pytest.mark.parametrize("chang", [False, True], ids=["d4", "chang_d1"])
def test_searchlight_ratio_without_doppler_colour(relativity_addon, factory_blender, tmp_path, chang):
    """D^4 (Weiskopf et al.); with Chang et al.'s labelled comparison option, one power of D."""
    bpy = factory_blender
    name = "chang" if chang else "grey"
    scene, camera, blend = _wall_scene(bpy, tmp_path, colour=(0.5, 0.5, 0.5), name=name, use_chang_searchlight=chang)
    beta = (0.6, 0.0, 0.0)
    image = _render(bpy, blend, tmp_path / f"{name}.exr", beta, "--no-doppler")
    d = _camera_frame_doppler(bpy, scene, camera, beta)
    bright, dim = (slice(20, 28), slice(58, 62)), (slice(20, 28), slice(2, 6))
    measured = image[bright][..., 1].mean() / image[dim][..., 1].mean()
    d4_ratio = (d[bright] ** 4).mean() / (d[dim] ** 4).mean()
    expected = d[bright].mean() / d[dim].mean() if chang else d4_ratio
    print(
        f"D {d[bright].mean():.4f} vs {d[dim].mean():.4f}: ratio {measured:.4f}, expected {expected:.4f}, "
        f"D^4 ratio {d4_ratio:.4f}"
    )
    assert d4_ratio > 1.5
    assert measured == pytest.approx(expected, rel=0.02)
    if chang:
        assert abs(measured - d4_ratio) > 0.5
    grey_spread = np.abs(image[4:-4, 4:-4] - image[4:-4, 4:-4].mean(-1, keepdims=True)).max()
    assert grey_spread < 1e-4 * image.max()


@pytest.mark.parametrize("beta_z, grouped", [(-0.5, None), (0.5, None), (0.5, "inner group"), (0.5, "passed group")])
def test_blackbody_seen_at_dt_by_moving_observer(factory_blender, tmp_path, beta_z, grouped):
    """Also with the Emission inside a node group (grouped_colours.py): its colour group, inside
    the group or in front of it, shifts the blackbody for camera rays and marks the pixel done."""
    bpy = factory_blender
    temperature = 5762.0
    scene, camera, blend = _wall_scene(bpy, tmp_path, temperature=temperature)
    if grouped:
        dh.emission_in_group(bpy, bpy.data.materials["Wall"], grouped, temperature)
        blend = ch.save_blend(bpy, tmp_path / "grouped.blend")
    beta = (0.0, 0.0, beta_z)
    rest = _render(bpy, blend, tmp_path / "sun_rest.exr", (0.0, 0.0, 0.0))
    image = _render(bpy, blend, tmp_path / "sun.exr", beta)
    d = _camera_frame_doppler(bpy, scene, camera, beta)
    window = (slice(22, 26), slice(30, 34))
    rendered = image[window].reshape(-1, 3).mean(0)
    d_mean = d[window].mean()
    xyz = dh.linear_rec709_to_xyz(rendered)
    expected_xyz = dh.blackbody_xyz_colour_science(d_mean * temperature)
    delta_e = dh.delta_e_2000_normalised(xyz, expected_xyz)
    measured_ratio = xyz[1] / dh.linear_rec709_to_xyz(rest[window].reshape(-1, 3).mean(0))[1]
    expected_ratio = expected_xyz[1] / dh.blackbody_xyz_colour_science(temperature)[1]
    print(f"D = {d_mean:.4f}: Delta E 2000 = {delta_e:.3f}; Y ratio {measured_ratio:.4f} vs {expected_ratio:.4f}")
    assert delta_e < 1.0
    assert measured_ratio == pytest.approx(expected_ratio, rel=0.02)


@pytest.mark.parametrize("lit", [False, True], ids=["emitters", "lit"])
@pytest.mark.parametrize("beta_z", [-0.9998, 0.9998])
def test_deep_shift_is_finite(factory_blender, tmp_path, beta_z, lit):
    """D reaches ~100 (toward the wall) or ~0.01 (away) at the image centre. Lit: one wall is
    diffuse, lit by a 1500 K area light and a grey world (the fast mode's light-group tables)."""
    bpy = factory_blender
    scene, camera = dh.emitter_scene(bpy, samples=2)
    for i, colour in enumerate(((1.0, 1.0, 1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))):
        wall = dh.add_emitter_plane(
            bpy, scene, f"Wall{i}", (-400.0 + 266.0 * i, -134.0 + 266.0 * i), (-400.0, 400.0), colour, beta=None
        )
        if lit and i == 1:
            wall.data.materials[0] = ch.diffuse_material(bpy, "Diffuse", (0.8, 0.5, 0.2))
    if lit:
        light = bpy.data.lights.new("Lamp", "AREA")
        light.size, light.energy, light.use_temperature, light.temperature = 20.0, 2000.0, True, 1500.0
        scene.collection.objects.link(bpy.data.objects.new("Lamp", light))
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    dh.add_emitter_plane(bpy, scene, "Sun", (-0.2, 0.2), (-0.2, 0.2), beta=None, temperature=5762.0, depth=4.0)
    blend = ch.save_blend(bpy, tmp_path / "deep.blend")
    image = _render(bpy, blend, tmp_path / "deep.exr", (0.0, 0.0, beta_z))
    d = _camera_frame_doppler(bpy, scene, camera, (0.0, 0.0, beta_z))
    print(f"D from {d.min():.4g} to {d.max():.4g}: pixels from {image.min():.4g} to {image.max():.4g}")
    assert np.all(np.isfinite(image))
    assert image.min() >= 0.0
