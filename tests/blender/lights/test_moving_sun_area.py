"""Moving sun and area lights behind the exact camera (blender/lights/stand_in_lamps.py), on the floor of
test_moving_point_light.py, against relations written out here in numpy (docs/physics.md):

- A sun is a plane wave: moving with beta, its photon direction in the scene frame is its own
  frame's direction aberrated (k = aberrate(k', -beta)) and the irradiance on a surface facing it
  is D^2 times its strength (radiance D^4 times the disc's solid angle 1 / D^2),
  D = 1 / (gamma (1 - beta . k)). Shadows fall along k.
- An area light is drawn as its centre: a point source with intensity (P / pi) cos(theta') in its
  own frame (a Lambertian emitter of power P), theta' the angle between its axis and the photon
  direction aberrated into its frame, with eq. 19 from retarded positions. At rest it is compared
  with Blender's own area light (the error of the centre-point approximation).
"""

import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_moving_point_light as floor  # noqa: E402

ch = floor.ch
SUN_STRENGTH = 3.0  # W/m^2
SUN_BETA = np.array([0.5, 0.0, 0.0])


def test_moving_sun_is_aberrated_and_d_squared_brighter(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, sun = floor._floor_scene(bpy, beta=SUN_BETA, occluder=True, kind="SUN")
    sun.data.energy = SUN_STRENGTH
    sun.data.angle = 0.0  # hard shadows
    floor._effect().apply(scene)  # the sun points down its local -Z: straight down
    assert sun.hide_render
    rendered = floor._render(bpy, scene, tmp_path / "sun.exr")
    image = ch.luminance(rendered)  # the colour shifts (eq. 18), the brightness follows D^2
    points = floor._floor_points(bpy, scene, camera)
    k = ch.aberrate(np.array([0.0, 0.0, -1.0]), -SUN_BETA)  # photon direction, scene frame
    d = 1.0 / (ch.gamma_of(SUN_BETA) * (1.0 - SUN_BETA @ k))
    lit = floor.ALBEDO / math.pi * d * d * SUN_STRENGTH * (-k[2])
    shadow = floor._blocked(points - 10.0 * k, points)
    at_rest_shadow = floor._blocked(points + 10.0 * np.array([0.0, 0.0, 1.0]), points)
    seen = floor._blocked(np.broadcast_to(floor.CAMERA, points.shape), points)
    edge = np.zeros_like(shadow)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            edge |= np.roll(np.roll(shadow, dy, 0), dx, 1) != shadow
    judged = ~seen & ~edge
    brightness = image[judged & ~shadow].mean() / lit
    wrong = ((image < 0.5 * lit) != shadow) & judged
    print(
        f"sun at 0.5c: k = {np.round(k, 4)}, D = {d:.4f}; floor {brightness:.4f} of D^2 E cos / pi "
        f"(at rest: {1.0 / (d * d * -k[2]):.4f}); shadow {shadow.sum()} px, {wrong.sum()} judged px wrong; "
        f"an unaberrated shadow shares {(shadow & at_rest_shadow).sum()} px"
    )
    assert brightness == pytest.approx(1.0, abs=0.01)
    assert wrong.sum() <= 0.02 * shadow.sum()
    # Its colour: the white's spectrum shifted by D (the physics core's colour-science model).
    from relativity_addon.physics.spectral import doppler_shift_rgb, linear_rec709_to_XYZ

    lit_rgb = rendered[..., :3][judged & ~shadow].mean(axis=0)
    colour_error = np.abs(lit_rgb / lit_rgb.sum() - (shifted := doppler_shift_rgb((1.0, 1.0, 1.0), d)) / shifted.sum())
    print(
        f"floor colour {np.round(lit_rgb / lit_rgb.sum(), 4)}, white shifted {np.round(shifted / shifted.sum(), 4)}"
        f" (XYZ {np.round(linear_rec709_to_XYZ(shifted), 3)})"
    )
    assert colour_error.max() < 0.01
    assert (shadow & at_rest_shadow).sum() < 0.7 * shadow.sum()


def _area_scene(bpy, beta, size, samples=floor.SAMPLES_LAMPS):
    scene, camera, lamp = floor._floor_scene(bpy, beta=beta, kind="AREA", samples=samples)
    lamp.data.size = size
    return scene, camera, lamp


@pytest.mark.parametrize("size", [0.2, 1.0])
def test_area_light_at_rest_against_blenders_own(relativity_addon, factory_blender, tmp_path, size):
    """beta = 0: the centre-point approximation against Blender's area light (pointing down)."""
    bpy = factory_blender
    scene, _camera, lamp = _area_scene(bpy, (0.0, 0.0, 0.0), size, samples=16)  # one stand-in lamp
    floor._effect().apply(scene)
    assert lamp.hide_render
    ours = floor._render(bpy, scene, tmp_path / "ours.exr")[..., 1]
    floor._effect().remove(scene)
    lamp.relativity.motion = "STATIC"
    blender = floor._render(bpy, scene, tmp_path / "blender.exr")[..., 1]
    lit = blender > 0.1 * blender.max()
    ratio = ours[lit].mean() / blender[lit].mean()
    largest = np.abs(ours - blender)[lit].max() / blender.max()
    print(
        f"area light {size} m at 1 m: centre point / Blender's area light over {lit.sum()} px: mean {ratio:.4f}, "
        f"largest difference {largest:.4f} of the peak"
    )
    assert ratio == pytest.approx(1.0, abs=0.02 if size < 0.5 else 0.06)
    assert largest < (0.05 if size < 0.5 else 0.4)  # a 1 m panel 1 m above the floor is no point


def test_moving_area_light_follows_eq_19_with_its_cosine(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, _lamp = _area_scene(bpy, floor.BETA, 0.2)
    floor._effect().apply(scene)
    image = floor._render(bpy, scene, tmp_path / "area.exr")[..., 1]
    points = floor._floor_points(bpy, scene, camera)
    radiance, source, _ = floor._expected_radiance(points, floor.BETA)  # isotropic P / (4 pi)
    n = (points - source) / np.linalg.norm(points - source, axis=-1, keepdims=True)
    cos_own = np.array([ch.aberrate(v, floor.BETA)[2] * -1.0 for v in n.reshape(-1, 3)]).reshape(n.shape[:-1])
    expected = radiance * 4.0 * np.maximum(cos_own, 0.0)  # (P / pi) cos(theta') instead of P / (4 pi)
    isotropic_cosine = radiance * 4.0 * np.maximum(-n[..., 2], 0.0)  # the cosine not aberrated
    measured, profile = image[floor.ROWS].mean(0), expected[floor.ROWS].mean(0)
    error = np.abs(measured - profile).max() / profile.max()
    unaberrated = np.abs(isotropic_cosine[floor.ROWS].mean(0) - profile).max() / profile.max()
    print(f"area light at 0.5c: max error {error:.4f} of the peak (its cosine unaberrated: {unaberrated:.3f})")
    assert error < 0.05
    assert unaberrated > 3.0 * error


def test_moving_blackbody_sun_in_spectral_mode_is_the_blackbody_at_d_t(relativity_addon, factory_blender, tmp_path):
    """Spectral mode: a 5000 K sun moving at 0.5c lights the floor with its spectrum shifted by its
    one D (eq. 18: irradiance ``D^3 S(lambda D) = D^-2 B(lambda, D T)`` per unit of ``B / Y(T)``),
    so the floor is the blackbody at ``D T`` (colour-science) with luminance
    ``a / pi E cos D^-2 Y(D T) / Y(T)``, in the fast mode too. Without the shift it kept its
    5000 K colour at ``D^2``."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "colour"))
    import colour_helpers as dh

    bpy = factory_blender
    temperature = 5000.0
    scene, _camera, sun = floor._floor_scene(bpy, beta=SUN_BETA, kind="SUN", samples=8)
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    sun.data.energy = SUN_STRENGTH
    sun.data.use_temperature = True
    sun.data.temperature = temperature
    floor._effect().apply(scene)
    k = ch.aberrate(np.array([0.0, 0.0, -1.0]), -SUN_BETA)
    d = 1.0 / (ch.gamma_of(SUN_BETA) * (1.0 - SUN_BETA @ k))
    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, _info = spectral_render.render(scene, 3)
    floor_xyz = dh.linear_rec709_to_xyz(pixels[:, :, :3].reshape(-1, 3).astype(float)).mean(axis=0)
    blackbody = dh.blackbody_xyz_colour_science(d * temperature)
    y_ratio = blackbody[1] / dh.blackbody_xyz_colour_science(temperature)[1]
    expected_y = floor.ALBEDO / math.pi * SUN_STRENGTH * (-k[2]) * y_ratio / (d * d)
    delta_e = dh.delta_e_2000_normalised(floor_xyz, blackbody)
    print(
        f"sun at 0.5c, D = {d:.4f}: floor Delta E {delta_e:.3f} from the blackbody at D T, "
        f"Y / expected {floor_xyz[1] / expected_y:.4f}; at T: Delta E "
        f"{dh.delta_e_2000_normalised(floor_xyz, dh.blackbody_xyz_colour_science(temperature)):.2f}"
    )
    assert delta_e < 1.0
    assert floor_xyz[1] / expected_y == pytest.approx(1.0, abs=0.03)
    assert tuple(sun.data.color) == (1.0, 1.0, 1.0) and sun.data.use_temperature, "the user's sun is restored"
    # The fast mode: the same blackbody at D T and brightness (the stand-in at D T, D^-2 Y(D T)/Y(T)).
    fast = floor._render(bpy, scene, tmp_path / "fast.exr")[..., :3]
    fast_xyz = dh.linear_rec709_to_xyz(fast.reshape(-1, 3).astype(float)).mean(axis=0)
    fast_delta_e = dh.delta_e_2000_normalised(fast_xyz, blackbody)
    print(f"fast mode: Delta E {fast_delta_e:.3f}, Y / expected {fast_xyz[1] / expected_y:.4f}")
    assert fast_delta_e < 1.0
    assert fast_xyz[1] / expected_y == pytest.approx(1.0, abs=0.03)


def test_moving_sun_with_a_blackbody_in_its_tree_is_the_blackbody_at_d_t(relativity_addon, factory_blender, tmp_path):
    """A 4000 K Blackbody node on the moving sun's Emission Color, Strength 2 (its own temperature
    off): the floor is the blackbody at ``D T`` with ``a / pi E cos D^-2 Y(D T) / Y(T)``, ``E`` the
    sun's strength times 2, in the fast mode and in spectral mode. Before, the stand-in sun (which
    has no tree) was white at the sun's own strength: Delta E 24, luminance 0.38 of the physics."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "colour"))
    import colour_helpers as dh

    bpy = factory_blender
    temperature, strength = 4000.0, 2.0
    scene, _camera, sun = floor._floor_scene(bpy, beta=SUN_BETA, kind="SUN", samples=8)
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    sun.data.energy = SUN_STRENGTH / strength
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        sun.data.use_nodes = True  # 4.5: the tree is used only then; 5.x: always on
    tree = sun.data.node_tree
    emission = next(node for node in tree.nodes if node.bl_idname == "ShaderNodeEmission")
    emission.inputs["Strength"].default_value = strength
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = temperature
    tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    floor._effect().apply(scene)
    k = ch.aberrate(np.array([0.0, 0.0, -1.0]), -SUN_BETA)
    d = 1.0 / (ch.gamma_of(SUN_BETA) * (1.0 - SUN_BETA @ k))
    shifted = dh.blackbody_xyz_colour_science(d * temperature)
    y_ratio = shifted[1] / dh.blackbody_xyz_colour_science(temperature)[1]
    expected_y = floor.ALBEDO / math.pi * SUN_STRENGTH * (-k[2]) * y_ratio / (d * d)
    fast = floor._render(bpy, scene, tmp_path / "fast.exr")[..., :3]
    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    spectral, _info = spectral_render.render(scene, 3)
    for mode, pixels in (("fast", fast), ("spectral", spectral[:, :, :3])):
        floor_xyz = dh.linear_rec709_to_xyz(pixels.reshape(-1, 3).astype(float)).mean(axis=0)
        delta_e = dh.delta_e_2000_normalised(floor_xyz, shifted)
        print(
            f"{mode}: D = {d:.4f}, Delta E {delta_e:.3f} from the blackbody at D T, "
            f"Y / expected {floor_xyz[1] / expected_y:.4f}"
        )
        assert delta_e < 1.0
        assert floor_xyz[1] / expected_y == pytest.approx(1.0, abs=0.03)


@pytest.mark.parametrize("kind", ["SUN", "POINT"])
def test_moving_light_tree_left_out_is_said(relativity_addon, factory_blender, kind):
    """A texture on a moving sun's (or point lamp's) Emission Color is not carried to its stand-in:
    one panel line (none before); a Blackbody there is carried (above): no line."""
    bpy = factory_blender
    scene, _camera, sun = floor._floor_scene(bpy, beta=SUN_BETA, kind=kind, samples=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        sun.data.use_nodes = True  # 4.5: the tree is used only then; 5.x: always on
    tree = sun.data.node_tree
    emission = next(node for node in tree.nodes if node.bl_idname == "ShaderNodeEmission")
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    floor._effect().apply(scene)
    assert not [line for line in floor._effect().scene_warnings(scene) if "node tree" in line]
    floor._effect().remove(scene)
    checker = tree.nodes.new("ShaderNodeTexChecker")
    tree.links.new(checker.outputs["Color"], emission.inputs["Color"])
    floor._effect().apply(scene)
    lines = [line for line in floor._effect().scene_warnings(scene) if "node tree" in line]
    assert lines == [
        "Light 'Lamp': its node tree (an Emission Color made by nodes other than one Blackbody) is left out "
        "of the moving light (it carries the Color, Emission Strength and a Blackbody only)"
    ]


def test_keyframed_sun_moves_with_its_keyframes_velocity(relativity_addon, factory_blender):
    """A sun keyframed to move at 0.5c along x gets, at the frame, the stand-in of a sun moving at
    that velocity: the photon direction aberrated and the strength ``D^2`` written out here."""
    bpy = factory_blender
    scene, _camera, sun = floor._floor_scene(bpy, beta=None, kind="SUN")
    sun.data.energy = SUN_STRENGTH
    fps = scene.render.fps
    for frame in (1, 21):
        sun.location = (SUN_BETA[0] * floor.C * (frame - 11) / fps, 0.0, 3.0)
        sun.keyframe_insert("location", frame=frame)
    for curve in ch.compat.action_fcurves(sun.animation_data):
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"
    sun.relativity.motion = "ANIMATION"
    scene.frame_set(11)
    floor._effect().apply(scene)
    assert sun.hide_render
    (stand_in,) = [obj for obj in scene.objects if obj.type == "LIGHT" and obj is not sun and not obj.hide_render]
    k = ch.aberrate(np.array([0.0, 0.0, -1.0]), -SUN_BETA)
    d = 1.0 / (ch.gamma_of(SUN_BETA) * (1.0 - SUN_BETA @ k))
    bpy.context.view_layer.update()
    direction = -np.array(stand_in.matrix_world.to_3x3().col[2])
    print(
        f"keyframed sun: stand-in direction {np.round(direction, 4)} (k {np.round(k, 4)}), "
        f"strength {stand_in.data.energy:.4f} (D^2 E {d * d * SUN_STRENGTH:.4f})"
    )
    assert np.allclose(direction, k, atol=1e-4)
    assert stand_in.data.energy == pytest.approx(d * d * SUN_STRENGTH, rel=1e-4)
