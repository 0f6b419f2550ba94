"""Lit scenes on the exact-camera path: a wall lit by a blackbody lamp at rest, coloured patches
under a 5762 K sun, and two bounces between coloured surfaces, observer moving.

Everything is at rest in the scene frame, so the light arriving at a pixel is the scene-frame
spectrum ``L(lambda)`` of whatever lit it, seen by the moving camera as ``D^5 L(lambda D)``
(Weiskopf et al. 1999 eq. 14, docs/physics.md) with the pixel's own ``D = 1 / (gamma (1 - beta.d))``.
References come from colour-science (Planck spectra, the CIE 1931 functions, Mallett & Yuksel's
basis) integrated here on a 1 nm grid; the one number taken from a render is the scene's
brightness at rest (the lamp's absolute scale, or a geometric factor of the bounce), measured on
a rest render of the same scene in white.
"""

import math

import numpy as np
import pytest

import doppler_helpers as dh
from doppler_helpers import ch

RESOLUTION = (48, 36)
CENTRE = (slice(14, 22), slice(20, 28))  # 8 x 8 pixels around the optical axis
LAMP_TEMPERATURE = 2700.0
PASSES = 4


# --- references (colour-science, 1 nm) ------------------------------------------------------------


def _cmfs():
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    return cmfs.wavelengths, cmfs.values


def _planck(wavelength_nm, temperature):
    from colour.colorimetry import planck_law

    with np.errstate(over="ignore"):
        return planck_law(np.asarray(wavelength_nm) * 1e-9, temperature)


def _mallett_reflectance(rgb, wavelength_nm):
    """Mallett & Yuksel's sRGB basis with weights ``rgb``, held at the 420-655 nm band's edge values
    outside it (the add-on's documented extension, docs/spectral-model.md)."""
    import colour

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    clipped = np.clip(wavelength_nm, 420.0, 655.0)
    values = np.stack([np.interp(clipped, basis.wavelengths, basis.values[:, i]) for i in range(3)], -1)
    return values @ np.asarray(rgb, float)


def _observed_xyz(spectrum, doppler):
    """XYZ of ``D^5 L(lambda D)`` for a scene-frame spectral radiance ``spectrum(mu)``."""
    wavelengths, cmfs = _cmfs()
    observed = doppler**5 * spectrum(wavelengths * doppler)
    return observed @ cmfs


def _xyz(rgb):
    return dh.linear_rec709_to_xyz(rgb)


def _pixel_doppler(bpy, scene, camera, beta):
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    beta = np.asarray(beta, float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    return 1.0 / (gamma * (1.0 - view @ beta))


# --- scenes ---------------------------------------------------------------------------------------


def _diffuse(bpy, name, colour):
    material = bpy.data.materials.new(name)
    tree = ch.compat.material_node_tree(material)
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*colour, 1.0)
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
    return material


def _quad(bpy, scene, name, corners, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(corners, [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def _wall_under_blackbody_lamp(bpy, samples=32):
    """A white diffuse wall at z = -5 facing the camera, lit by a large emitting panel with a
    Blackbody node behind the camera (invisible to camera rays)."""
    scene, camera = dh.emitter_scene(bpy, samples=samples, resolution=RESOLUTION)
    _quad(bpy, scene, "Wall", [(-40, -40, -5), (40, -40, -5), (40, 40, -5), (-40, 40, -5)],
          _diffuse(bpy, "White", (1.0, 1.0, 1.0)))
    lamp_material = ch.emission_material(bpy, "Lamp", strength=1.0)
    tree = lamp_material.node_tree
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = LAMP_TEMPERATURE
    tree.links.new(blackbody.outputs[0], tree.nodes["Emission"].inputs["Color"])
    lamp = _quad(bpy, scene, "Lamp", [(-60, -60, 1), (-60, 60, 1), (60, 60, 1), (60, -60, 1)], lamp_material)
    lamp.visible_camera = False
    return scene, camera


def _set_up(bpy, scene, beta):
    scene.relativity.beta = beta
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}


def _render_f12(bpy, scene, tmp_path, name):
    return dh.render(bpy, scene, tmp_path / f"{name}.exr")


def _render_spectral(bpy, addon, scene, passes=PASSES):
    spectral_render = dh.addon_module(addon, "spectral_render")
    pixels, info = spectral_render.render(scene, passes)
    return pixels[::-1, :, :3].astype(float), info  # top row first, like the EXR reader


def test_wall_under_blackbody_lamp_is_a_blackbody_at_d_t(relativity_addon, tmp_path):
    """Wall and lamp at rest together: the wall's light is the lamp's blackbody times a constant,
    seen as a blackbody at ``D T`` with luminance ``Y(D T) / Y(T)`` times its luminance at rest."""
    bpy = __import__("bpy")
    scene, camera = _wall_under_blackbody_lamp(bpy)
    rest = _render_f12(bpy, scene, tmp_path, "rest")[CENTRE].reshape(-1, 3)
    rest_luminance = _xyz(rest)[:, 1]
    assert rest_luminance.std() / rest_luminance.mean() < 0.05, "the wall must be evenly lit"
    y_rest = rest_luminance.mean()

    beta = (0.0, 0.0, -0.6)  # toward the wall: D = 2 on the axis
    _set_up(bpy, scene, beta)
    doppler = _pixel_doppler(bpy, scene, camera, beta)[CENTRE].ravel()
    y_lamp = dh.blackbody_xyz_colour_science(LAMP_TEMPERATURE)[1]
    expected = np.mean([dh.blackbody_xyz_colour_science(d * LAMP_TEMPERATURE) / y_lamp * y_rest for d in doppler],
                       axis=0)

    spectral, info = _render_spectral(bpy, relativity_addon, scene)
    measured = _xyz(spectral[CENTRE].reshape(-1, 3)).mean(axis=0)
    delta_e = dh.delta_e_2000_normalised(measured, expected)
    print(f"D in [{info['doppler_range'][0]:.3f}, {info['doppler_range'][1]:.3f}]; spectral: Delta E {delta_e:.2f}, "
          f"Y / expected {measured[1] / expected[1]:.4f}")
    assert delta_e < 2.0
    assert measured[1] / expected[1] == pytest.approx(1.0, abs=0.05)

    fast = _xyz(_render_f12(bpy, scene, tmp_path, "fast")[CENTRE].reshape(-1, 3)).mean(axis=0)
    print(f"fast (RGB) mode: Delta E {dh.delta_e_2000_normalised(fast, expected):.2f}, "
          f"Y / expected {fast[1] / expected[1]:.4f}")
    assert np.all(np.isfinite(spectral)) and spectral.min() >= 0.0
