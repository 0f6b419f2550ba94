"""The mesh path in EEVEE (what material preview and EEVEE renders show) against Cycles.

Apparent geometry is the evaluated mesh, the same for every engine; the Doppler and searchlight
shaders are node groups that EEVEE compiles on its own. One scene, rendered by Cycles and by EEVEE
(CPU through Mesa's software OpenGL, no GPU): a sphere at 0.9c and a blackbody plane at 0.5c,
with Doppler colour and searchlight. Both images must show the same outline and the same colours.
"""

import numpy as np

import colour_helpers as dh
from colour_helpers import ch
from relativity_addon.blender.common import compat

C = 5.0


def _scene(bpy, addon):
    scene, camera = dh.emitter_scene(bpy, samples=16)
    scene.relativity.speed_of_light = C
    # Placed where they are at the camera's time, so that light-travel time shows them in view.
    seen = np.array([-0.4, 0.3, -4.0])
    ball = ch.add_sphere(
        bpy,
        scene,
        seen + [0.9 * np.linalg.norm(seen), 0.0, 0.0],
        0.8,
        ch.emission_material(bpy, "Ball"),
        name="Ball",
        segments=48,
        rings=24,
    )
    ball.active_material.node_tree.nodes["Emission"].inputs["Color"].default_value = (0.3, 0.6, 0.2, 1.0)
    ball.relativity.motion = "CONSTANT"
    ball.relativity.beta = (0.9, 0.0, 0.0)
    plane = dh.add_emitter_plane(bpy, scene, "Star", (-2.0, -0.8), (-1.2, -0.2), beta=None, temperature=5762.0)
    plane.relativity.motion = "CONSTANT"
    plane.relativity.beta = (-0.5, 0.0, 0.0)
    scene.relativity.method = "GEOMETRY"
    dh.addon_module(addon, "pipeline.effect").apply(scene)
    return scene


def _erode(mask):
    """Pixels whose four neighbours are all in ``mask`` too (the border counts as outside)."""
    padded = np.pad(mask, 1)
    return mask & padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]


def test_eevee_shows_the_cycles_image(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene = _scene(bpy, relativity_addon)
    cycles = dh.render(bpy, scene, tmp_path / "cycles.exr")
    scene.render.engine = compat.eevee_engine()
    scene.render.filter_size = 0.0  # one sample position per pixel, like Cycles' 1 px box filter
    eevee = dh.render(bpy, scene, tmp_path / "eevee.exr")
    assert np.all(np.isfinite(eevee)) and np.all(eevee >= 0)

    # Same apparent outline, to the pixel: EEVEE covers everything Cycles covers fully and
    # nothing more than one pixel outside it (Cycles' edge pixels are partly covered).
    brightness = cycles.max()
    covered_cycles, covered_eevee = ch.luminance(cycles) > 1e-4 * brightness, ch.luminance(eevee) > 1e-4 * brightness
    inside, around = _erode(covered_cycles), ~_erode(~covered_cycles)
    print(
        f"covered: Cycles {covered_cycles.sum()}, EEVEE {covered_eevee.sum()} pixels; EEVEE misses "
        f"{(inside & ~covered_eevee).sum()} inner pixels, adds {(covered_eevee & ~around).sum()} outer ones"
    )
    assert inside.sum() > 800
    assert np.all(covered_eevee[inside]) and not np.any(covered_eevee & ~around)

    # Same colours inside (away from edges, where the engines anti-alias differently).
    inside &= covered_eevee
    error = np.abs(eevee[inside] - cycles[inside]).sum(-1) / cycles[inside].sum(-1)
    hue_spread = np.ptp(cycles[inside][:, 2] / cycles[inside][:, 0])
    print(
        f"{inside.sum()} inner pixels: colour error mean {error.mean():.4f}, max {error.max():.4f}; "
        f"b/r spread {hue_spread:.2f}"
    )
    assert hue_spread > 0.2  # the Doppler shift varies across the image: the test sees the shaders
    assert error.mean() < 0.02 and np.percentile(error, 95) < 0.05
