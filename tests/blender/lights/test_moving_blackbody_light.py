"""A 3000 K point light moving at 0.5c above a white floor, camera at rest (exact camera, stand-in
lamps): the floor's colour follows eq. 18, ``D^5 B(lambda D, T) = B(lambda, D T)``, with ``D`` the
lamp-to-floor Doppler factor of each floor point, in the fast mode and in the spectral mode.

Expected values: the retarded positions and ``D`` of ``test_moving_point_light`` (numpy,
fixed-point iteration) and colour-science's Planck spectra through the CIE 1931 observer: the
floor's radiance is ``a / pi cos(alpha) / r^2`` times the lamp's luminance in its own frame times
the blackbody at ``D T`` over ``Y(T)`` (Weiskopf et al. 1999 eqs. 18-19, docs/moving-lights.md).
Every channel of a pixel shares its light paths, so the chromaticity needs few samples.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import test_moving_point_light as mp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "colour"))
import colour_helpers as dh  # noqa: E402

TEMPERATURE = 3000.0
RESOLUTION = (80, 60)
ROWS = slice(28, 32)
SAMPLES = 16
PASSES = 3


def _scene(bpy, rows_only=True):
    scene, camera, lamp = mp._floor_scene(bpy, samples=SAMPLES)
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    if rows_only:  # the rows :func:`_compare` reads
        mp._render_rows(scene, ROWS)
    lamp.data.use_temperature = True
    lamp.data.temperature = TEMPERATURE
    return scene, camera, lamp


def _geometry(points, lamp):
    """Per pixel ``a / pi cos / r^2`` times the lamp's luminance over ``Y(T)``, and the
    lamp-to-floor ``D``, from the lamp's retarded positions."""
    _radiance, source, doppler = mp._expected_radiance(points, mp.BETA)
    ray = points - source
    r = np.linalg.norm(ray, axis=-1)
    cosine = np.maximum(-ray[..., 2] / r, 0.0)
    colour = np.array(lamp.data.temperature_color)
    luminance = mp.POWER / (4.0 * math.pi) * float(colour @ (0.2126729, 0.7151522, 0.0721750))
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    return mp.ALBEDO / math.pi * cosine / r**2 * luminance / y_t, doppler


def _blackbodies(doppler):
    """XYZ of the blackbody at ``D T`` for every ``D``."""
    return dh.blackbody_xyz_colour_science(np.asarray(doppler) * TEMPERATURE)


def _expected_xyz(points, lamp):
    """Floor radiance (XYZ) per pixel: a / pi cos / r^2 times the lamp's luminance times B(D T) / Y(T)."""
    geometry, doppler = _geometry(points, lamp)
    return geometry[..., None] * _blackbodies(doppler), doppler


def _compare(image, expected, doppler, label):
    """Delta E 2000 and luminance ratio per column band of the lit floor (along the motion)."""
    measured = dh.linear_rec709_to_xyz(image[ROWS].reshape(-1, 3)).reshape(ROWS.stop - ROWS.start, -1, 3).mean(0)
    wanted = expected[ROWS].mean(0)
    lit = wanted[:, 1] > 0.03 * wanted[:, 1].max()
    results = []
    for band in np.array_split(np.flatnonzero(lit), 6):
        got, want = measured[band].sum(0), wanted[band].sum(0)
        results.append((float(doppler[ROWS][:, band].mean()), dh.delta_e_2000_normalised(got, want), got[1] / want[1]))
    for d, delta_e, ratio in results:
        print(f"{label}: D {d:.3f}: Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
    return results


def test_floor_under_a_moving_blackbody_lamp_is_lit_by_the_blackbody_at_d_t(
    relativity_addon, factory_blender, tmp_path
):
    bpy = factory_blender
    scene, camera, lamp = _scene(bpy)
    mp._effect().apply(scene)
    points = mp._floor_points(bpy, scene, camera)
    expected, doppler = _expected_xyz(points, lamp)
    assert doppler[ROWS].min() < 0.9 and doppler[ROWS].max() > 1.2, "the view must hold red and blue shifts"

    fast = mp._render(bpy, scene, tmp_path / "fast.exr")
    assert np.all(np.isfinite(fast)) and fast.min() >= 0.0
    for _d, delta_e, ratio in _compare(fast, expected, doppler, "fast mode"):
        assert delta_e < 1.0
        assert ratio == pytest.approx(1.0, abs=0.08)  # noise: 16 samples

    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, info = spectral_render.render(scene, PASSES)
    spectral = pixels[::-1, :, :3].astype(float)
    assert np.all(np.isfinite(spectral))
    for _d, delta_e, ratio in _compare(spectral, expected, doppler, f"spectral mode, {PASSES} passes"):
        assert delta_e < 1.0
        assert ratio == pytest.approx(1.0, abs=0.08)
    assert tuple(lamp.data.color) == (1.0, 1.0, 1.0) and lamp.data.use_temperature, "the user's lamp is restored"


OBSERVER = np.array([-0.3, 0.0, 0.0])  # against the lamp's motion


def _observed_floor_points(bpy, scene, camera, observer=OBSERVER, offset=(0.5, 0.5), origin=mp.CAMERA):
    """The floor point each pixel centre (or the point ``offset`` from its corner) sees through the
    exact camera moving with ``observer`` (its rays leave ``origin`` in the scene frame), and the
    pixel's observer Doppler factor ``D_o = 1 / (gamma (1 - beta . d'))`` (``d'`` its direction in
    the observer's frame, aberrated into the scene frame to find the point: docs/physics.md)."""
    view = -dh.pixel_photon_directions(bpy, scene, camera, offset)
    gamma = 1.0 / math.sqrt(1.0 - observer @ observer)
    observer_doppler = 1.0 / (gamma * (1.0 - view @ observer))
    scene_photon = mp.ch.aberrate(-view, -observer)
    scene_view = -scene_photon
    t = -origin[2] / scene_view[..., 2]
    return origin + t[..., None] * scene_view, observer_doppler


@pytest.mark.parametrize("observer", [OBSERVER, np.array([-0.5, 0.0, 0.0])], ids=["0.3c", "0.5c"])
def test_moving_blackbody_lamp_seen_by_a_moving_observer(relativity_addon, factory_blender, tmp_path, observer):
    """Lamp at 0.5c, observer at 0.3c and 0.5c against it: each floor pixel is the blackbody at
    ``D_o D_L T`` (``D_L`` lamp to floor, ``D_o`` floor to observer). The spectral mode carries the
    lamp's shifted spectrum through the passes; in the fast mode the stand-in lamps' shader shifts
    their light by the observer's ``D_o`` too, in a light group of their own whose pass the
    compositor shifts only by the floor's own reflectance shift (none for a grey floor): within
    Delta E 1 of the blackbody and of the spectral render (issue 27: before,
    the compositor read that light as lit by white light, Delta E up to 18)."""
    bpy = factory_blender
    scene, camera, lamp = _scene(bpy)
    scene.relativity.beta = tuple(observer)
    mp._effect().apply(scene)
    points, observer_doppler = _observed_floor_points(bpy, scene, camera, observer)
    geometry, lamp_doppler = _geometry(points, lamp)
    total = observer_doppler * lamp_doppler
    expected = geometry[..., None] * _blackbodies(total)  # D_o^5 B(lambda D_o, D_L T) = B(lambda, D_o D_L T)

    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, info = spectral_render.render(scene, PASSES + 1)
    spectral = pixels[::-1, :, :3].astype(float)
    print(
        f"D_o {observer_doppler[ROWS].min():.3f} .. {observer_doppler[ROWS].max():.3f}; "
        f"D_L {lamp_doppler[ROWS].min():.3f} .. {lamp_doppler[ROWS].max():.3f}"
    )
    label = f"moving observer, spectral mode, {PASSES + 1} passes"
    for _d, delta_e, ratio in _compare(spectral, expected, total, label):
        assert delta_e < 1.0
        assert ratio == pytest.approx(1.0, abs=0.08)
    fast = mp._render(bpy, scene, tmp_path / "fast.exr")
    assert np.all(np.isfinite(fast)) and fast.min() >= 0.0
    for _d, delta_e, ratio in _compare(fast, expected, total, "moving observer, fast mode"):
        assert delta_e <= 1.0
        assert ratio == pytest.approx(1.0, abs=0.08)  # noise: 16 samples
    # the fast mode against the spectral render itself (the acceptance), the same bands
    spectral_xyz = dh.linear_rec709_to_xyz(spectral.reshape(-1, 3)).reshape(spectral.shape)
    for _d, delta_e, ratio in _compare(fast, spectral_xyz, total, "fast mode against the spectral render"):
        assert delta_e <= 1.0
        assert ratio == pytest.approx(1.0, abs=0.1)


def test_moving_blackbody_lamp_on_a_coloured_floor_seen_by_a_moving_observer(
    relativity_addon, factory_blender, tmp_path
):
    """The same lamp over an orange floor, observer at 0.5c against it: the surface's own
    reflectance shifts too, ``R(lambda D_o)``. The fast mode scales the observed light group's pass
    by the reflectance's shift relative to white (the Diffuse Color pass through the emitters'
    table, compositing.py); against the spectral render within Delta E 2.5 (before: up to 8.5, read
    in white light; with the pass kept as rendered: up to 21)."""
    bpy = factory_blender
    scene, camera, lamp = _scene(bpy)
    bpy.data.materials["White"].node_tree.nodes["Diffuse BSDF"].inputs["Color"].default_value = (0.8, 0.4, 0.1, 1.0)
    observer = np.array([-0.5, 0.0, 0.0])
    scene.relativity.beta = tuple(observer)
    mp._effect().apply(scene)
    points, observer_doppler = _observed_floor_points(bpy, scene, camera, observer)
    _geometry_factor, lamp_doppler = _geometry(points, lamp)
    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, _info = spectral_render.render(scene, PASSES + 1)
    spectral = pixels[::-1, :, :3].astype(float)
    spectral_xyz = dh.linear_rec709_to_xyz(spectral.reshape(-1, 3)).reshape(spectral.shape)
    fast = mp._render(bpy, scene, tmp_path / "fast.exr")
    assert np.all(np.isfinite(fast)) and fast.min() >= 0.0
    total = observer_doppler * lamp_doppler
    for _d, delta_e, ratio in _compare(
        fast, spectral_xyz, total, "orange floor, fast mode against the spectral render"
    ):
        assert delta_e <= 2.5
        assert ratio == pytest.approx(1.0, abs=0.1)
    layer = scene.view_layers[0]
    assert layer.use_pass_diffuse_color and any(group.name == "Relativity Observed" for group in layer.lightgroups)
    mp._effect().remove(scene)  # gives back the pass and the light groups
    assert not layer.use_pass_diffuse_color and not layer.lightgroups
    assert not any(obj.name.startswith("Relativity") for obj in scene.objects)


def test_moving_blackbody_lamp_bounce_light_is_approximate(relativity_addon, factory_blender, tmp_path):
    """What is left (docs/moving-lights.md): the stand-ins' shader shifts their light by the ``D_o``
    of the lit point, so light reaching the camera by a second bounce carries the wrong one. A white
    slope turned away from the lamp (lit only by the floor) and the floor in its shadow (lit only
    by bounces), observer at 0.5c, 128 samples: the fast mode against the spectral render there,
    printed and held to its documented size (measured: Delta E 0.95 on Blender 5.2 and 0.98 on
    4.5, luminance 0.94 and 0.93 of the spectral render's; at 256 samples 0.93 and 0.94 on both)."""
    bpy = factory_blender
    scene, _camera, _lamp = _scene(bpy, rows_only=False)  # the slope and its shadow: every row
    scene.cycles.samples = 128
    mesh = bpy.data.meshes.new("Slope")  # facing +x and up: away from the lamp's retarded positions
    mesh.from_pydata([(0.0, -1.0, 1.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 1.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(bpy.data.materials["White"])
    slope = bpy.data.objects.new("Slope", mesh)
    scene.collection.objects.link(slope)
    scene.relativity.beta = (-0.5, 0.0, 0.0)
    mp._effect().apply(scene)
    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, _info = spectral_render.render(scene, PASSES + 1)
    spectral = dh.linear_rec709_to_xyz(pixels[::-1, :, :3].astype(float).reshape(-1, 3)).reshape(-1, RESOLUTION[0], 3)
    fast = dh.linear_rec709_to_xyz(mp._render(bpy, scene, tmp_path / "fast.exr").reshape(-1, 3)).reshape(spectral.shape)
    slope.hide_render = True  # where the slope changes the picture: itself and its shadow
    scene.cycles.samples = 64  # this render only picks the pixels (a change of half or more), not compared
    floor_only = mp._render(bpy, scene, tmp_path / "floor.exr")
    without = dh.linear_rec709_to_xyz(floor_only.reshape(-1, 3))[:, 1].reshape(spectral.shape[:2])
    bounce_only = np.abs(fast[..., 1] - without) > 0.5 * np.abs(without) + 1e-3
    assert bounce_only.sum() > 500
    got, want = fast[bounce_only].sum(0), spectral[bounce_only].sum(0)
    delta_e, ratio = dh.delta_e_2000_normalised(got, want), got[1] / want[1]
    print(f"bounce light only ({bounce_only.sum()} px): Delta E {delta_e:.3f}, Y / spectral {ratio:.4f}")
    # held near what it measures (0.93-0.98 / 0.93-0.94): a return to the old 0.61-0.64 fails
    assert delta_e < 1.5
    assert 0.85 < ratio < 1.05
