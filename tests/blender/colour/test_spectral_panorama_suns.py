"""Weiskopf's Suns through a panorama in the spectral mode (issue 27): blackbody spheres at rest
around an observer moving at 0.5c, photographed by the exact camera as an equirectangular panorama
with Render Spectral. A blackbody at ``T`` seen with Doppler factor ``D`` has the spectrum
``D^5 B(lambda D, T) = B(lambda, D T)`` (docs/physics.md, "Radiance"; docs/spectral-model.md):
each Sun's pixels must show the colour of the blackbody at ``D T`` and, the emitter being
normalised to luminance 1 at rest, the luminance ``Y(D T) / Y(T)``, with ``D = 1 / (gamma (1 -
beta . d'))`` at each pixel's camera-frame viewing direction ``d'``. The reference is
colour-science's Planck spectrum through the CIE 1931 observer, not the add-on's tables.
Before the spectral mode read the panorama's per-pixel ``D`` it weighed the panorama with a
perspective window's: on that code this test measured the Sun behind at Delta E 10.7 and 2.25x the
expected luminance; now Delta E at most 0.07 and luminance within 7 %.
"""

import math

import numpy as np
from test_world_doppler import _doppler, _equirectangular_directions

import colour_helpers as dh

TEMPERATURE = 5762.0
BETA = (0.5, 0.0, 0.0)  # the observer moves along +X; the camera looks down -Z
LONGITUDES = (-150.0, -90.0, -30.0, 30.0, 90.0)  # scene-frame directions of the five Suns (degrees)
DISTANCE, RADIUS = 10.0, 1.2


def _blackbody_material(bpy):
    material = dh.ch.emission_material(bpy, "Sun surface")
    tree = material.node_tree
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = TEMPERATURE
    tree.links.new(blackbody.outputs[0], tree.nodes["Emission"].inputs["Color"])
    return material


def _column_runs(mask):
    """Contiguous runs of image columns holding a lit pixel: one per Sun, left to right."""
    lit = mask.any(axis=0)
    runs, start = [], None
    for column, on in enumerate([*lit, False]):
        if on and start is None:
            start = column
        elif not on and start is not None:
            runs.append(slice(start, column))
            start = None
    return runs


def test_spectral_equirectangular_render_of_five_suns(relativity_addon):
    bpy = __import__("bpy")
    width, height = 256, 128
    scene, camera = dh.emitter_scene(bpy, samples=4, resolution=(width, height))
    camera.data.type = "PANO"
    camera.data.panorama_type = "EQUIRECTANGULAR"
    material = _blackbody_material(bpy)
    for i, longitude in enumerate(map(math.radians, LONGITUDES)):
        location = (DISTANCE * math.sin(longitude), 0.0, -DISTANCE * math.cos(longitude))
        dh.ch.add_sphere(bpy, scene, location, RADIUS, material, name=f"Sun {i}")
    scene.relativity.beta = BETA
    scene.relativity.use_doppler = True
    scene.relativity.use_searchlight = True
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 4)
    image = pixels[::-1, :, :3].astype(float)  # top row first
    assert np.all(np.isfinite(image))
    d = _doppler(_equirectangular_directions(width, height), BETA)
    rest = dh.blackbody_xyz_colour_science(TEMPERATURE)
    dark = int(np.flatnonzero(~(dh.ch.luminance(image) > 0.02).any(axis=0))[0])
    image, d = np.roll(image, -dark, axis=1), np.roll(d, -dark, axis=1)  # no Sun across the image's edge
    luminance = dh.ch.luminance(image)
    runs = _column_runs(luminance > 0.02)
    assert len(runs) == len(LONGITUDES), runs
    seen = []
    for columns in runs:
        patch = luminance[:, columns]
        inner = patch > 0.6 * patch.max()  # whole pixels of the disc, away from its antialiased rim
        measured = dh.linear_rec709_to_xyz(image[:, columns][inner].sum(axis=0))
        expected = (dh.blackbody_xyz_colour_science(d[:, columns][inner] * TEMPERATURE) / rest[1]).sum(axis=0)
        delta_e = dh.delta_e_2000_normalised(measured, expected)
        ratio = measured[1] / expected[1]
        mean_d = float(d[:, columns][inner].mean())
        seen.append(mean_d)
        print(f"Sun at D {mean_d:.3f} ({inner.sum()} px): Delta E {delta_e:.2f}, Y/expected {ratio:.3f}")
        assert delta_e < 1.0
        assert abs(ratio - 1.0) < 0.08
    assert max(seen) / min(seen) > 2.5  # from the Sun behind (D < 1) to the one ahead
