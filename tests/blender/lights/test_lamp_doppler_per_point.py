"""Per receiving point: a lamp at rest close to a sphere moving at 0.5c (Weiskopf et al. eq. 18,
then eq. 14), real Cycles renders on the Apparent Geometry path, camera at rest
(docs/lamp-doppler.md).

A white Lambert sphere of rest radius 1 moves along +X at 0.5c past the camera; a point (or area)
lamp at rest 3 radii from the sphere's seen centre, across the motion. Across the lit part of the
sphere the light's Doppler factor and its aberrated direction vary from point to point (docs:
one D and one direction per lamp and object were 42 % off here). The per-pixel model below is
written from docs/physics.md alone: each pixel's ray meets the sphere where the sphere was when
the light left it (uniform motion, Lorentz-contracted along +X, a quadratic in the ray length);
there the rest-frame normal is the unit rest position; the photon from the lamp (direction ``k``,
scene distance ``r``) is received with ``D = gamma (1 - beta . k)`` from the aberrated direction
``k'`` (the photon's four-momentum boosted), ``E' = D^2 cos(alpha') I / r^2``; the camera gets
``albedo / pi E' D_c^4`` with ``D_c = 1 / (gamma (1 - beta . k_c))`` (eq. 14). The area lamp is
integrated over its panel the same way, element by element (a Lambertian emitter).
"""

import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from blender_support import ADDON_MODULE

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402

RESOLUTION = (96, 72)
BETA = 0.5
C = 10.0
CAMERA_DISTANCE = 6.0
LENS, SENSOR = 50.0, 36.0
ALBEDO = 0.8
LAMP = np.array([0.0, -2.1213, 2.1213])  # 3 radii from the seen centre (the origin), across +X
POWER = 2000.0
AREA_SIZE = 1.0
SUN_STRENGTH = 60.0  # W/m^2
SPOT_SIZE, SPOT_BLEND = math.radians(30.0), 0.3  # the cone's edge crosses the sphere (19.5 deg half-width)
AREA_POWER = 2000.0
GAMMA = 1.0 / math.sqrt(1.0 - BETA**2)
VELOCITY = np.array([BETA, 0.0, 0.0])


def _module(name):
    return importlib.import_module(f"{ADDON_MODULE}.blender.{name}")


def _scene(bpy, kind, samples, lamp_at=LAMP, searchlight=True, beta=BETA):
    scene, _camera = ch.new_scene(
        bpy,
        resolution=RESOLUTION,
        samples=samples,
        location=(0.0, -CAMERA_DISTANCE, 0.0),
        rotation_euler=(math.pi / 2.0, 0.0, 0.0),
    )
    scene.camera.data.lens = LENS
    scene.camera.data.sensor_width = SENSOR
    scene.camera.data.sensor_fit = "HORIZONTAL"
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.max_bounces = 0
    material = ch.diffuse_material(bpy, "White", (ALBEDO, ALBEDO, ALBEDO))
    # seen at the origin: the camera event is t = 0, the light left the sphere at t = -0.6 s
    sphere = ch.add_sphere(bpy, scene, (beta * CAMERA_DISTANCE, 0.0, 0.0), 1.0, material, "Sphere", 96, 48)
    sphere.relativity.enabled = True
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = (beta, 0.0, 0.0)
    light = bpy.data.lights.new("Lamp", kind)
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = tuple(lamp_at)
    if kind == "SUN":
        light.energy = SUN_STRENGTH
        light.angle = 0.0
        lamp.rotation_euler = (math.radians(45.0), 0.0, 0.0)
    elif kind in ("POINT", "SPOT"):
        light.energy = POWER
        light.shadow_soft_size = 0.0
        lamp.rotation_euler = (math.radians(45.0), 0.0, math.radians(10.0))  # -Z near the origin
        if kind == "SPOT":
            light.spot_size, light.spot_blend = SPOT_SIZE, SPOT_BLEND
    else:
        light.energy = AREA_POWER
        light.size = AREA_SIZE
        lamp.rotation_euler = (math.radians(45.0), 0.0, 0.0)  # -Z (its light) toward the origin
    scene.collection.objects.link(lamp)
    scene.relativity.speed_of_light = C
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.use_doppler = False  # total energy: D^2 (colour is tested elsewhere)
    scene.relativity.use_searchlight = searchlight
    bpy.context.view_layer.update()
    return scene, lamp


def _seen_sphere(beta=BETA):
    """Per pixel: the scene point where the ray meets the sphere (moving at ``beta`` along X) at the
    time the light left it, and the rest-frame normal there (NaN where the ray misses)."""
    gamma = 1.0 / math.sqrt(1.0 - beta * beta)
    camera = np.array([0.0, -CAMERA_DISTANCE, 0.0])
    rays = ch.pixel_rays(RESOLUTION, SENSOR, LENS)
    start = camera - np.array([beta * CAMERA_DISTANCE, 0.0, 0.0])  # camera relative to the centre at t = 0
    # at path length s the light left at t = -s / c, when the centre was at c0 - v s / c:
    # rest position = stretch (start + s (n + beta)), |rest position| = 1
    stretch = np.array([gamma, 1.0, 1.0])
    a_vec = (rays + np.array([beta, 0.0, 0.0])) * stretch
    b_vec = start * stretch
    a = np.sum(a_vec * a_vec, axis=-1)
    b = 2.0 * np.sum(a_vec * b_vec, axis=-1)
    cc = b_vec @ b_vec - 1.0
    disc = b * b - 4.0 * a * cc
    s = np.where(disc >= 0.0, (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a), np.nan)
    points = camera + s[..., None] * rays
    rest = b_vec + s[..., None] * a_vec
    return points, rest, rays


def _boosted(k, beta=BETA):
    """The photon direction ``k`` (scene frame) in the sphere's frame (moving at ``beta`` along X):
    its four-momentum boosted (docs/physics.md); returns (energy D, direction k')."""
    gamma = 1.0 / math.sqrt(1.0 - beta * beta)
    energy = gamma * (1.0 - beta * k[..., 0])
    along = gamma * (k[..., 0] - beta)
    boosted = np.stack([along, k[..., 1], k[..., 2]], axis=-1)
    return energy, boosted / energy[..., None]


def _received(points, rest, source, intensity, power=2, beta=BETA):
    """Eq. 18 in the scene frame's distance: ``D^2 cos(alpha') I / r^2`` (``intensity`` per point);
    ``power`` 0: the geometry alone, ``cos(alpha') I / r^2`` (the aberrated direction, no ``D``)."""
    offset = points - source
    r = np.linalg.norm(offset, axis=-1)
    doppler, k_object = _boosted(offset / r[..., None], beta)
    cosine = np.maximum(-np.sum(rest * k_object, axis=-1), 0.0)
    return doppler**power * cosine * intensity / r**2


def _model(kind, lamp_matrix, searchlight=True, beta=BETA):
    """Per-pixel radiance by eqs. 18 and 14 (NaN off the sphere); without the searchlight (and
    Doppler colour) no power of ``D``, neither eq. 18's nor eq. 14's: the aberrated direction alone."""
    power = 2 if searchlight else 0
    points, rest, rays = _seen_sphere(beta)
    lamp_at = lamp_matrix[:3, 3]
    if kind == "SUN":  # a plane wave along the sun's -Z: one k, D^2 cos(alpha') E
        doppler, k_object = _boosted(-lamp_matrix[:3, 2], beta)
        irradiance = doppler**2 * np.maximum(-(rest @ k_object), 0.0) * SUN_STRENGTH
    elif kind in ("POINT", "SPOT"):
        irradiance = _received(points, rest, lamp_at, POWER / (4.0 * math.pi), power, beta)
        if kind == "SPOT":  # Cycles' cone: smoothstep over the blend, in the cosine of the angle
            offset = points - lamp_at
            cosine = (offset / np.linalg.norm(offset, axis=-1, keepdims=True)) @ -lamp_matrix[:3, 2]
            cos_half = math.cos(SPOT_SIZE / 2.0)
            t = np.clip((cosine - cos_half) / ((1.0 - cos_half) * SPOT_BLEND), 0.0, 1.0)
            irradiance = irradiance * t * t * (3.0 - 2.0 * t)
    else:  # a Lambertian panel: radiance P / (pi A); an element's intensity L cos_e dA along k
        count = 24
        grid = (np.arange(count) + 0.5) / count - 0.5
        axis = -lamp_matrix[:3, 2]
        radiance = AREA_POWER / (math.pi * AREA_SIZE**2)
        irradiance = np.zeros(points.shape[:-1])
        for u in grid:
            for v in grid:
                element = lamp_matrix[:3, :3] @ np.array([u * AREA_SIZE, v * AREA_SIZE, 0.0]) + lamp_matrix[:3, 3]
                offset = points - element
                k = offset / np.linalg.norm(offset, axis=-1, keepdims=True)
                emitted = np.maximum(k @ axis, 0.0) * radiance * (AREA_SIZE / count) ** 2
                irradiance += _received(points, rest, element, emitted, power, beta)
    to_camera = -rays
    camera_doppler = 1.0 / (1.0 / math.sqrt(1.0 - beta * beta) * (1.0 - to_camera @ np.array([beta, 0.0, 0.0])))
    return ALBEDO / math.pi * irradiance * camera_doppler ** (2 * power)


def _inner(model):
    """Pixels on the sphere at least two pixels from its outline, where the model is lit (> 5 %
    of its peak)."""
    on = np.isfinite(model)
    inner = on.copy()
    for dy in (-2, -1, 0, 1, 2):
        for dx in (-2, -1, 0, 1, 2):
            inner &= np.roll(np.roll(on, dy, axis=0), dx, axis=1)
    return inner & (np.nan_to_num(model) > 0.05 * np.nanmax(model))


def _centroid(weights):
    rows, columns = np.indices(weights.shape)
    return np.array([np.sum(weights * columns), np.sum(weights * rows)]) / np.sum(weights)


def _save_side_by_side(bpy, path, image, model):
    """render | model | |difference| x 4, one brightness scale, as a PNG to look at."""
    peak = float(np.nanmax(model))
    panels = np.hstack([image, np.nan_to_num(model), 4.0 * np.abs(image - np.nan_to_num(model))]) / peak
    picture = bpy.data.images.new("comparison", panels.shape[1], panels.shape[0])
    rgba = np.repeat(np.clip(panels[::-1], 0.0, 1.0)[..., None], 4, axis=-1)
    rgba[..., 3] = 1.0
    picture.pixels.foreach_set(rgba.astype(np.float32).ravel())
    picture.filepath_raw = str(path)
    picture.file_format = "PNG"
    picture.save()


def _compare(bpy, kind, tmp_path, samples, lamp_at=LAMP, searchlight=True, beta=BETA):
    scene, lamp = _scene(bpy, kind, samples, lamp_at, searchlight, beta)
    _module("pipeline.effect").apply(scene)
    image = ch.luminance(ch.render_exr(bpy, scene, tmp_path / f"{kind}.exr"))
    model = _model(kind, np.array(lamp.matrix_world), searchlight, beta)
    inner = _inner(model)
    _save_side_by_side(bpy, tmp_path / f"{kind}_render_model_difference.png", image, model)
    rendered, expected = image[inner], model[inner]
    pattern = float(np.sum(np.abs(rendered - expected)) / np.sum(expected))
    total = float(rendered.sum() / expected.sum())
    shift = float(np.linalg.norm(_centroid(np.where(inner, image, 0.0)) - _centroid(np.where(inner, model, 0.0))))
    stand_ins = sum(_module("lights.lamps_on_moving_objects").is_copy(obj) for obj in scene.objects)
    print(
        f"{kind}: {inner.sum()} lit pixels, per-pixel error {pattern:.1%}, total {total:.4f}, "
        f"centroid {shift:.2f} px off, {stand_ins} copies"
    )
    return pattern, total, shift


@pytest.mark.parametrize("kind", ["POINT", "SPOT", "AREA"])
def test_close_lamp_lights_each_point_with_its_own_doppler_factor(relativity_addon, factory_blender, tmp_path, kind):
    """3 radii: the lit part's per-pixel brightness within 6 % of eqs. 18 and 14 on average (mean
    absolute difference over the mean; sampling noise included), its total within 3 %, its
    centroid within 0.5 px. One D and one direction per lamp and object: 36 % (point), 49 %
    (spot) and 33 % (area), the centroid 1.9-3.3 px off."""
    pattern, total, shift = _compare(factory_blender, kind, tmp_path, samples=64)
    assert pattern < 0.06
    assert total == pytest.approx(1.0, abs=0.03)
    assert shift < 0.5


@pytest.mark.parametrize("beta", [BETA, -BETA])
def test_lamp_half_a_radius_from_the_surface(relativity_addon, factory_blender, tmp_path, beta):
    """1.5 radii (the point lamp 0.5 m from the surface): the per-point light within 8 % per pixel,
    5 % in total (the issue's bar; the stand-ins' cosines clamped at the terminator add light
    there), 0.5 px; one D and direction per lamp and object: 96 %, 7.2 px off. Moving either way
    (issue 27 asks +0.5c and -0.5c: the scene's mirror image, which a sign slip would break)."""
    pattern, total, shift = _compare(factory_blender, "POINT", tmp_path, samples=64, lamp_at=LAMP / 2.0, beta=beta)
    assert pattern < 0.08
    assert total == pytest.approx(1.0, abs=0.05)
    assert shift < 0.5


def test_sun_is_one_plane_wave(relativity_addon, factory_blender, tmp_path):
    """A sun (one photon direction everywhere): one D and one aberrated direction are exact for an
    object that does not turn; within 2 % per pixel, 1 % in total, 0.2 px."""
    pattern, total, shift = _compare(factory_blender, "SUN", tmp_path, samples=16)
    assert pattern < 0.02
    assert total == pytest.approx(1.0, abs=0.01)
    assert shift < 0.2


def test_lamp_direction_stays_aberrated_with_colour_effects_off(relativity_addon, factory_blender, tmp_path):
    """Doppler colour and searchlight both off: no power of D, but the sphere still receives the
    lamp's light from the aberrated direction in its own frame (geometry, not Doppler): the model
    without D within 6 % per pixel, 3 % in total, 0.5 px (measured 1.1 %, 0.998, 0.00 px). Dropping
    the stand-ins and rest normals with the colour effects, as before (Cycles' cosine on the
    apparent sphere toward the lamp itself): 43 %, total 1.31, the lit part's centroid 2.8 px off."""
    pattern, total, shift = _compare(factory_blender, "POINT", tmp_path, samples=64, searchlight=False)
    assert pattern < 0.06
    assert total == pytest.approx(1.0, abs=0.03)
    assert shift < 0.5
