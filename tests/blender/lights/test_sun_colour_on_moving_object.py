"""A blackbody sun at rest lighting a moving plate (eq. 18's copy of the sun, docs/lamp-doppler.md):
the plate's colour against the blackbody at ``D T`` (colour-science), a real Cycles render.

Two horizontal white plates (normal +Z) under a 4000 K sun shining straight down (``k = -Z``): one
at rest, the reference, and one moving at 0.5c, tilted 45 degrees from straight up (toward the
sun, ``D = 1.56``) or 135 degrees (away, ``D = 0.75``). Eq. 18 (docs/physics.md, the object-frame
spectral irradiance ``D^3 E(lambda D) cos(alpha')`` at a given scene-frame distance, ``D = gamma
(1 - beta . k)``, ``alpha'`` from the aberrated ``k'``) gives a Planck spectrum ``B(lambda, T)``
received as ``D^3 B(lambda D, T) = D^-2 B(lambda, D T)``: the blackbody at ``D T`` with ``D^-2
Y(D T) / Y(T) cos(alpha')`` times the luminance the plate at rest receives. The camera at rest
looks at the moving plate from the direction in which its light reaches the camera with eq. 14's
``D = 1 / (gamma (1 - beta . k_camera)) = 1`` (``beta . k_camera = 1 - 1 / gamma``), on the side
where the plate's own frame shows its lit top, so the materials leave that light as it is; each
pixel's own ``D^4`` (1.02-1.03 on average over the plate) is taken into the expected luminance,
its colour shift (under 1 % of ``D T``) is not. Diffuse, no bounce: a plate's radiance is its
irradiance times albedo / pi.
"""

import importlib
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from blender_support import ADDON_MODULE

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "colour"))
import colour_helpers as dh  # noqa: E402

ch = dh.ch
RESOLUTION = (48, 32)
SAMPLES = 16
C = 10.0
TEMPERATURE = 4000.0
SUN_STRENGTH = 3.0  # W/m^2
ALBEDO = 0.5
SPEED = 0.5
GAMMA = 1.0 / math.sqrt(1.0 - SPEED**2)
SUN = np.array([0.0, 0.0, -1.0])  # the photon direction k: straight down
# The moving plate's velocity, tilted from straight up (toward the sun) or down (away), and the
# camera's height over the plate (the z of k_camera): its direction is then solved for
# ``beta . k_camera = 1 - 1 / gamma`` on the side where the plate's object frame shows its top.
CASES = {"toward": (math.radians(45.0), 0.8), "away": (math.radians(135.0), 0.4)}
DISTANCE = 80.0  # camera to the plates' seen centres
HALF, GAP = 1.5, 2.0  # m: the plates' half size; their seen centres either side of the origin


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _beta(case):
    tilt, _height = CASES[case]
    return SPEED * np.array([math.sin(tilt), 0.0, math.cos(tilt)])


def _camera_direction(case):
    """Unit ``k_camera`` (plate -> camera) with ``beta . k_camera = 1 - 1 / gamma`` and the given z."""
    beta = _beta(case)
    z = CASES[case][1]
    x = (1.0 - 1.0 / GAMMA - beta[2] * z) / beta[0]
    return np.array([x, math.sqrt(1.0 - x * x - z * z), z])


def _plate(bpy, scene, name, centre, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-HALF, -HALF, 0), (HALF, -HALF, 0), (HALF, HALF, 0), (-HALF, HALF, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = tuple(centre)
    scene.collection.objects.link(obj)
    return obj


def _scene(bpy, case, blackbody_node=False):
    import mathutils  # with bpy

    toward_camera = _camera_direction(case)
    camera_at = DISTANCE * toward_camera
    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=SAMPLES, location=tuple(camera_at))
    camera.rotation_euler = mathutils.Vector(tuple(-camera_at)).to_track_quat("-Z", "Y").to_euler()
    camera.data.sensor_fit = "HORIZONTAL"
    camera.data.sensor_width = 36.0
    camera.data.lens = 36.0 * DISTANCE / 9.0  # 9 m wide at the plates
    scene.cycles.max_bounces = 0
    scene.cycles.pixel_filter_type = "BOX"
    right = np.cross(-toward_camera, (0.0, 0.0, 1.0))
    right = GAP * right / np.linalg.norm(right)  # the image's right
    rest = _plate(bpy, scene, "Rest", -right, ch.diffuse_material(bpy, "White rest", (ALBEDO,) * 3))
    mover = _plate(bpy, scene, "Mover", right, ch.diffuse_material(bpy, "White", (ALBEDO,) * 3))
    beta = _beta(case)
    mover.location = tuple(right + beta * DISTANCE)  # seen there, DISTANCE / c ago
    mover.relativity.enabled = True
    mover.relativity.motion = "CONSTANT"
    mover.relativity.beta = tuple(beta)
    light = bpy.data.lights.new("Sun", "SUN")
    light.energy = SUN_STRENGTH
    light.angle = 0.0
    if blackbody_node:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            light.use_nodes = True  # 4.5: the tree is used only then; 5.x: always on
        tree = light.node_tree
        emission = next(node for node in tree.nodes if node.bl_idname == "ShaderNodeEmission")
        blackbody = tree.nodes.new("ShaderNodeBlackbody")
        blackbody.inputs["Temperature"].default_value = TEMPERATURE
        tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    else:
        light.use_temperature = True
        light.temperature = TEMPERATURE
    sun = bpy.data.objects.new("Sun", light)  # unrotated: shines along -Z
    scene.collection.objects.link(sun)
    scene.relativity.speed_of_light = C
    scene.relativity.method = "GEOMETRY"
    scene.relativity.use_doppler = True
    scene.relativity.use_searchlight = True
    bpy.context.view_layer.update()
    return scene, camera, rest


def _received_xyz(doppler):
    """XYZ (CIE 1931, colour-science) of eq. 18's object-frame spectral irradiance from a Planck
    spectrum at ``TEMPERATURE``, ``D^3 B(lambda D, T)``, over the luminance of ``B(lambda, T)``."""
    wavelengths, cmfs = dh.cmfs_1nm()
    rest = dh.planck(wavelengths, TEMPERATURE) @ cmfs
    return doppler**3 * dh.planck(wavelengths * doppler, TEMPERATURE) @ cmfs / rest[1]


def _inner(mask):
    """``mask`` without its outline: pixels whose four neighbours are in it."""
    inner = mask.copy()
    inner[1:, :] &= mask[:-1, :]
    inner[:-1, :] &= mask[1:, :]
    inner[:, 1:] &= mask[:, :-1]
    inner[:, :-1] &= mask[:, 1:]
    return inner


def _camera_doppler(bpy, scene, camera, beta):
    """Eq. 14's ``D = 1 / (gamma (1 - beta . k))`` of every pixel, ``k`` toward the camera."""
    toward_camera = dh.pixel_photon_directions(bpy, scene, camera)
    return 1.0 / (GAMMA * (1.0 - toward_camera @ beta))


def _measure(bpy, scene, camera, case, path):
    image = ch.render_exr(bpy, scene, path)
    luminance = ch.luminance(image)
    left = np.broadcast_to(np.arange(RESOLUTION[0]) < RESOLUTION[0] // 2, luminance.shape)
    rest_side, mover_side = (_inner(side & (luminance > 0.2 * luminance[side].max())) for side in (left, ~left))
    rest_xyz = dh.linear_rec709_to_xyz(image[rest_side]).mean(axis=0)
    mover_xyz = dh.linear_rec709_to_xyz(image[mover_side]).mean(axis=0)
    beta = _beta(case)
    doppler = float(ch.doppler_factor(SUN, beta))
    cosine = float(-ch.aberrate(SUN, beta)[2])  # on the plate's rest normal +Z, in its frame
    camera_gain = float((_camera_doppler(bpy, scene, camera, beta)[mover_side] ** 4).mean())
    expected = rest_xyz[1] * cosine * camera_gain * _received_xyz(doppler)
    delta_e = dh.delta_e_2000_normalised(mover_xyz, expected)
    ratio = mover_xyz[1] / expected[1]
    rest_delta_e = dh.delta_e_2000_normalised(rest_xyz, dh.blackbody_xyz_colour_science(TEMPERATURE))
    print(
        f"{case}: D {doppler:.4f} (D T = {doppler * TEMPERATURE:.0f} K), cos(alpha') {cosine:.4f}, "
        f"pixels {int(rest_side.sum())} at rest, {int(mover_side.sum())} moving; camera D^4 {camera_gain:.4f}; "
        f"against the blackbody at D T: Delta E 2000 {delta_e:.3f}, luminance {ratio:.4f}; "
        f"at rest against {TEMPERATURE:.0f} K: Delta E {rest_delta_e:.3f}"
    )
    return delta_e, ratio


@pytest.mark.parametrize(("source", "case"), [("temperature", "toward"), ("blackbody node", "away")])
def test_sun_on_a_moving_plate_is_the_blackbody_at_d_t(relativity_addon, factory_blender, tmp_path, source, case):
    """Delta E 2000 under 1 from the blackbody at ``D T`` and the luminance within 3 % (measured
    on 5.2: toward, 6252 K, 0.58 and 0.999; away, 2986 K, 0.14 and 0.998); the sun's own 4000 K
    would be Delta E 19.3 and 9.2 off (colour-science: the plate left at the lamp's colour)."""
    bpy = factory_blender
    scene, camera, _rest = _scene(bpy, case, blackbody_node=source == "blackbody node")
    _effect().apply(scene)
    delta_e, ratio = _measure(bpy, scene, camera, case, tmp_path / f"{case}.exr")
    assert delta_e < 1.0
    assert ratio == pytest.approx(1.0, abs=0.03)
