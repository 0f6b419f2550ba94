"""Doppler colour and searchlight on the mesh path: emitters carrying ``relativity_beta``.

Real Cycles renders (CPU, 64x48). The camera looks down -Z from the origin; each emitter is a
flat quad at z = -5 whose point attribute ``relativity_beta`` is its velocity relative to the
observer. Expected Doppler factors are computed per pixel from the pixel's viewing direction
(docs/physics.md: D = 1 / (gamma_s (1 - beta_s . k))).
"""

import numpy as np
import pytest

import colour_helpers as dh

GREY = (0.5, 0.5, 0.5)


def _setup(bpy, addon, **settings):
    scene, camera = dh.emitter_scene(bpy)
    for name, value in settings.items():
        setattr(scene.relativity, name, value)
    return scene, camera


def _apply(addon, scene):
    """The mesh path's colour stage alone (emitters carry a hand-written ``relativity_beta``):
    what ``effect.apply`` and ``effect.sync`` do for method GEOMETRY, without the modifier.
    tests/blender/pipeline/test_settings_reach_render.py covers the whole path from the panel."""
    scene.relativity.method = "GEOMETRY"
    materials = dh.addon_module(addon, "colour.materials")
    materials.attach_scene(scene, camera_path=False)
    materials.write_settings(dh.addon_module(addon, "scene.snapshot").read(scene))


def _region(image, rows, cols):
    return image[rows[0] : rows[1], cols[0] : cols[1]].reshape(-1, 3)


def test_identity_at_rest_and_hue_direction(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera = _setup(bpy, relativity_addon)
    colour = (0.3, 0.6, 0.2)
    # Three emitters, left to right: receding, at rest, approaching (along the line of sight).
    dh.add_emitter_plane(bpy, scene, "Receding", (-1.75, -0.65), (-1.0, 1.0), colour, dh.beta_for_doppler(0.6))
    dh.add_emitter_plane(bpy, scene, "Rest", (-0.5, 0.5), (-1.0, 1.0), colour, (0.0, 0.0, 0.0))
    dh.add_emitter_plane(bpy, scene, "Approaching", (0.65, 1.75), (-1.0, 1.0), colour, dh.beta_for_doppler(1.6))
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "hue.exr")
    assert np.all(np.isfinite(image))

    rest = _region(image, (16, 32), (28, 36))
    print("rest pixels, max |rgb - input|:", np.abs(rest - colour).max())
    assert np.abs(rest - colour).max() < 1e-3

    receding = _region(image, (16, 32), (4, 12)).mean(axis=0)
    approaching = _region(image, (16, 32), (52, 60)).mean(axis=0)
    rest_ratio = colour[2] / colour[0]
    print("b/r rest", rest_ratio, "receding", receding[2] / receding[0], "approaching", approaching[2] / approaching[0])
    assert receding[2] / receding[0] < 0.8 * rest_ratio  # redder
    assert approaching[2] / approaching[0] > 1.25 * rest_ratio  # bluer
    assert receding.sum() < sum(colour) < approaching.sum()


def test_searchlight_ratio_is_d4_and_chang_is_d1(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera = _setup(bpy, relativity_addon, use_doppler=False)
    # One grey emitter filling the view, moving sideways: D varies across the image.
    beta = (0.6, 0.0, 0.0)
    dh.add_emitter_plane(bpy, scene, "Grey", (-3.0, 3.0), (-2.5, 2.5), GREY, beta)
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "searchlight.exr")
    d = dh.source_doppler_factor(dh.pixel_photon_directions(bpy, scene, camera), beta)
    # Moving toward +X: photons reaching the left of the image propagate more along beta.
    bright, dim = (slice(20, 28), slice(2, 6)), (slice(20, 28), slice(58, 62))
    measured = image[bright][..., 1].mean() / image[dim][..., 1].mean()
    expected = (d[bright] ** 4).mean() / (d[dim] ** 4).mean()
    print(f"D {d[bright].mean():.4f} vs {d[dim].mean():.4f}: ratio {measured:.4f}, D^4 ratio {expected:.4f}")
    assert expected > 1.5
    assert measured == pytest.approx(expected, rel=0.02)
    # The emitter's colour is unchanged (no Doppler colour): grey stays grey.
    assert np.abs(image[20:28, 2:62].std(axis=-1)).max() < 1e-4 * image[20:28, 2:62].max()

    # Chang et al.'s single power of D, as a labelled comparison option.
    scene.relativity.use_chang_searchlight = True
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "chang.exr")
    measured = image[bright][..., 1].mean() / image[dim][..., 1].mean()
    expected = d[bright].mean() / d[dim].mean()
    print(f"Chang: ratio {measured:.4f}, D^1 {expected:.4f}")
    assert measured == pytest.approx(expected, rel=0.02)


@pytest.mark.parametrize("d_target", [0.5773502691896258, 1.7320508075688772])
def test_blackbody_seen_at_dt(relativity_addon, factory_blender, tmp_path, d_target):
    """The Sun (5762 K) receding / approaching at 0.5c: colour of the blackbody at D T."""
    bpy = factory_blender
    scene, camera = _setup(bpy, relativity_addon)
    temperature = 5762.0
    beta = dh.beta_for_doppler(d_target)
    dh.add_emitter_plane(bpy, scene, "Sun", (-0.6, 0.6), (-0.6, 0.6), beta=beta, temperature=temperature)
    dh.add_emitter_plane(
        bpy, scene, "SunAtRest", (1.0, 1.8), (-0.6, 0.6), beta=(0.0, 0.0, 0.0), temperature=temperature
    )
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "sun.exr")
    d = dh.source_doppler_factor(dh.pixel_photon_directions(bpy, scene, camera), beta)
    window = (slice(22, 26), slice(30, 34))
    rendered = image[window].reshape(-1, 3).mean(axis=0)
    d_mean = d[window].mean()
    expected_xyz = dh.blackbody_xyz_colour_science(d_mean * temperature)
    delta_e = dh.delta_e_2000_normalised(dh.linear_rec709_to_xyz(rendered), expected_xyz)
    # Luminance: Y(DT)/Y(T) relative to the identical emitter at rest.
    rest = image[22:26, 54:58].reshape(-1, 3).mean(axis=0)
    measured_ratio = dh.linear_rec709_to_xyz(rendered)[1] / dh.linear_rec709_to_xyz(rest)[1]
    expected_ratio = (
        dh.blackbody_xyz_colour_science(d_mean * temperature)[1] / dh.blackbody_xyz_colour_science(temperature)[1]
    )
    print(
        f"D = {d_mean:.4f}: Delta E 2000 = {delta_e:.3f}; Y ratio {measured_ratio:.4f} vs {expected_ratio:.4f} "
        f"(D^4 = {d_mean**4:.4f})"
    )
    assert delta_e < 1.0
    assert measured_ratio == pytest.approx(expected_ratio, rel=0.02)


def test_deep_shift_sweep_is_finite(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera = _setup(bpy, relativity_addon)
    scene.cycles.samples = 2
    factors = np.geomspace(0.01, 100.0, 9)
    for i, d in enumerate(factors):
        x0 = -1.75 + i * 0.39
        for j, colour in enumerate(((1.0, 1.0, 1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), None)):
            y0 = -1.25 + j * 0.63
            # Velocity along the line of sight to the quad's centre: D there is the target.
            toward_camera = -np.array([x0 + 0.185, y0 + 0.3, -dh.PLANE_DEPTH])
            toward_camera /= np.linalg.norm(toward_camera)
            dh.add_emitter_plane(
                bpy,
                scene,
                f"E{i}{j}",
                (x0, x0 + 0.37),
                (y0, y0 + 0.6),
                colour or (1.0, 1.0, 1.0),
                dh.beta_for_doppler(d, toward_camera),
                temperature=None if colour else 5762.0,
            )
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "sweep.exr")
    print("sweep: min", image.min(), "max", image.max())
    assert np.all(np.isfinite(image))
    assert image.min() >= 0.0
    assert image.max() > 1000.0  # white at D = 100 is ~1400 times brighter, not clipped to black


def test_reflected_radiance_scales_with_d4(relativity_addon, factory_blender, tmp_path):
    """A diffuse grey wall lit by a sun lamp at rest relative to it, moving sideways."""
    bpy = factory_blender
    scene, camera = _setup(bpy, relativity_addon, use_doppler=False)
    beta = (0.6, 0.0, 0.0)
    wall = dh.add_emitter_plane(bpy, scene, "Wall", (-3.0, 3.0), (-2.5, 2.5), GREY, beta)
    material = wall.data.materials[0]
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Emission"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*GREY, 1.0)
    tree.links.new(diffuse.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    _apply(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "diffuse.exr")
    d = dh.source_doppler_factor(dh.pixel_photon_directions(bpy, scene, camera), beta)
    bright, dim = (slice(20, 28), slice(2, 6)), (slice(20, 28), slice(58, 62))
    measured = image[bright][..., 1].mean() / image[dim][..., 1].mean()
    expected = (d[bright] ** 4).mean() / (d[dim] ** 4).mean()
    print(f"diffuse: ratio {measured:.4f}, D^4 ratio {expected:.4f}")
    assert image[dim].min() > 0.0
    assert measured == pytest.approx(expected, rel=0.02)
