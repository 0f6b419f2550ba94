"""A MOVING light lighting a MOVING mesh (Weiskopf et al. eqs. 18 and 19 with the relative Doppler
factor, then eq. 14), real Cycles renders: Apparent Geometry seen by a moving observer, whose final
render is the exact camera, so the moving light is drawn by its stand-in lamps
(docs/moving-lights.md, "A moving light on a moving object").

A white Lambert sphere of rest radius 1 moves along +X at 0.5c; a point light moves at 0.5c along
+X (parallel), along -X (antiparallel) or stays at rest (the control, lit by the lamps-at-rest
stage), placed so that its light reaches the sphere from about 3 radii away, across the motion.
The per-pixel model is written here from docs/physics.md alone:

- each pixel's direction in the observer's frame is aberrated into the scene frame (the photon's
  direction transformed from the camera's frame, Gray et al. eq. 2); the scene-frame ray meets the
  sphere where it was when the light left it (a quadratic in the ray length);
- the light's emission event on its straight path for that receiving event (``|x - x_L(t_e)| =
  c (t_x - t_e)``, a quadratic in ``t_e``);
- the null emission-absorption separation ``(r, r n)`` boosted into the sphere's frame: its time
  part is the sphere-frame distance ``r'``, its space part the direction ``-k'`` the sphere sees the
  light from; the photon's frequency ratio between the light's and the sphere's frames is
  ``D = D_L D_R`` (``D_L = 1 / (gamma_L (1 - beta_L . n))``, ``D_R = gamma_R (1 - beta_R . n)``);
- eq. 18 in the sphere's frame: ``E' = D^4 cos(alpha') I / r'^2`` on the rest normal, ``I = P / 4 pi``;
- Lambert there, then to the observer with ``(D_o D_s)^4`` (eq. 14: ``D_s = 1 / (gamma_R (1 -
  beta_R . k))`` the sphere-to-scene factor of the photon toward the camera, ``D_o = gamma_o (1 -
  beta_o . k)`` the observer's).
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
SAMPLES = 256
# the noise bound per pixel at SAMPLES: twice the point stand-ins' 1.57 % (antiparallel; Blender 4.5 and 5.2).
# With the pair lamps as points (radius 0) beside the stand-ins' strips Cycles' light tree sampled them
# badly: antiparallel 10.6 % (5.2: 10.3 %), with a lamp at rest too 25.8 % (27.8 %); docs/moving-lights.md
NOISE = 0.03
C = 10.0
BETA = 0.5  # the sphere's speed along +X
OBSERVER = np.array([0.0, 0.2, 0.0])  # the camera moves toward the scene: the final render is the exact camera
CAMERA = np.array([0.0, -6.0, 0.0])
LENS, SENSOR = 50.0, 36.0
ALBEDO = 0.8
POWER = 2000.0
SEEN = np.array([0.0, -2.1213, 2.1213])  # where the light's light comes from, about: 3 radii across the motion
EMISSION = -9.0  # c t of that emission, about (the camera sees the sphere 6 m away, 3 m from the light)
VELOCITY = np.array([BETA, 0.0, 0.0])


def _module(name):
    return importlib.import_module(f"{ADDON_MODULE}.blender.{name}")


def _gamma(beta):
    return 1.0 / math.sqrt(1.0 - float(np.dot(beta, beta)))


def _light_position(light_beta):
    """Where Blender draws the light at the camera's time t = 0."""
    return SEEN - EMISSION * np.asarray(light_beta, float)


def _scene(bpy, light_beta, observer=OBSERVER, rest_power=0.0):
    """The sphere and the light; ``rest_power`` > 0: a point lamp at rest of that power at SEEN too."""
    scene, _camera = ch.new_scene(
        bpy, resolution=RESOLUTION, samples=SAMPLES, location=tuple(CAMERA), rotation_euler=(math.pi / 2.0, 0.0, 0.0)
    )
    scene.camera.data.lens = LENS
    scene.camera.data.sensor_width = SENSOR
    scene.camera.data.sensor_fit = "HORIZONTAL"
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.max_bounces = 0
    material = ch.diffuse_material(bpy, "White", (ALBEDO, ALBEDO, ALBEDO))
    # seen about the origin: the light the camera gets at t = 0 left the sphere at t = -0.6 s
    sphere = ch.add_sphere(
        bpy, scene, tuple(BETA * -CAMERA[1] * np.array([1.0, 0.0, 0.0])), 1.0, material, "Sphere", 96, 48
    )
    sphere.relativity.enabled = True
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = tuple(VELOCITY)
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = POWER
    light.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = tuple(_light_position(light_beta))
    scene.collection.objects.link(lamp)
    if np.any(light_beta):
        lamp.relativity.enabled = True
        lamp.relativity.motion = "CONSTANT"
        lamp.relativity.beta = tuple(light_beta)
    if rest_power > 0.0:
        resting = bpy.data.lights.new("Lamp at Rest", "POINT")
        resting.energy = rest_power
        resting.shadow_soft_size = 0.0
        still = bpy.data.objects.new("Lamp at Rest", resting)
        still.location = tuple(SEEN)
        scene.collection.objects.link(still)
    scene.relativity.speed_of_light = C
    scene.relativity.beta = tuple(observer)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.use_doppler = False  # total energy (luminance): colour is tested elsewhere
    scene.relativity.use_searchlight = True
    bpy.context.view_layer.update()
    return scene


def _scene_rays(observer=OBSERVER):
    """Per pixel: the scene-frame direction from the camera along which its photon came, and the
    observer's ``D_o`` for it."""
    view = ch.pixel_rays(RESOLUTION, SENSOR, LENS)  # directions in the camera's frame
    photon = -view
    if not np.any(observer):
        return view, np.ones(view.shape[:-1])
    gamma = _gamma(observer)
    along = photon @ observer
    speed2 = float(observer @ observer)
    # the photon direction in the scene frame, from the frame moving with OBSERVER
    k = (photon + ((gamma - 1.0) * along / speed2)[..., None] * observer + gamma * observer) / (gamma * (1.0 + along))[
        ..., None
    ]
    k /= np.linalg.norm(k, axis=-1, keepdims=True)
    return -k, gamma * (1.0 - k @ observer)


def _seen_sphere(rays):
    """The scene point each ray meets on the sphere when the light it sends left it, the unit rest
    position there (the rest normal) and the light-travel distance (NaN where it misses)."""
    gamma = _gamma(VELOCITY)
    start = CAMERA - np.array([BETA * -CAMERA[1], 0.0, 0.0])  # camera relative to the centre at t = 0
    stretch = np.array([gamma, 1.0, 1.0])
    a_vec = (rays + VELOCITY) * stretch  # at path length s the centre was v s / c further back
    b_vec = start * stretch
    a = np.sum(a_vec * a_vec, axis=-1)
    b = 2.0 * np.sum(a_vec * b_vec, axis=-1)
    cc = b_vec @ b_vec - 1.0
    disc = b * b - 4.0 * a * cc
    s = np.where(disc >= 0.0, (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a), np.nan)
    return CAMERA + s[..., None] * rays, b_vec + s[..., None] * a_vec, s


def _emission(points, path_length, light_beta):
    """The light's emission event for each receiving event (``x``, ``c t_x = -path_length``): its
    position and the scene distance ``r``."""
    beta = np.asarray(light_beta, float)
    delta = points - _light_position(beta)
    a = -path_length
    delta_beta = delta @ beta
    one_minus = 1.0 - float(beta @ beta)
    # (1 - beta^2) tau^2 - 2 (a - delta.beta) tau - (delta.delta - a^2) = 0, the root before a
    half = a - delta_beta
    tau = (half - np.sqrt(half * half + one_minus * (np.sum(delta * delta, axis=-1) - a * a))) / one_minus
    source = _light_position(beta) + tau[..., None] * beta
    r = a - tau
    lit = np.isfinite(r)
    assert np.allclose(np.linalg.norm(points - source, axis=-1)[lit], r[lit], rtol=1e-9)
    return source, r


def _model(light_beta, observer=OBSERVER, power=POWER):
    rays, observer_doppler = _scene_rays(observer)
    points, rest, path_length = _seen_sphere(rays)
    source, r = _emission(points, path_length, light_beta)
    n = (points - source) / r[..., None]
    light_doppler = 1.0 / (_gamma(light_beta) * (1.0 - n @ np.asarray(light_beta, float)))
    gamma = _gamma(VELOCITY)
    # the separation (r, r n) in the sphere's frame (boost along +X)
    r_object = gamma * (r - BETA * r * n[..., 0])
    space = np.stack([gamma * (r * n[..., 0] - BETA * r), r * n[..., 1], r * n[..., 2]], axis=-1)
    k_object = space / r_object[..., None]
    doppler = light_doppler * r_object / r  # nu_sphere / nu_light: the separation scales with the frequency
    cosine = np.maximum(-np.sum(rest * k_object, axis=-1), 0.0)
    irradiance = doppler**4 * cosine * power / (4.0 * math.pi) / r_object**2
    to_camera = -rays
    sphere_to_scene = 1.0 / (gamma * (1.0 - to_camera @ VELOCITY))
    return ALBEDO / math.pi * irradiance * (observer_doppler * sphere_to_scene) ** 4


def _inner(model):
    """On the sphere at least two pixels from its outline, lit above 5 % of the model's peak."""
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
    """render | model | |difference| x 4 on one scale, a PNG to look at."""
    peak = float(np.nanmax(model))
    panels = np.hstack([image, np.nan_to_num(model), 4.0 * np.abs(image - np.nan_to_num(model))]) / peak
    picture = bpy.data.images.new("comparison", panels.shape[1], panels.shape[0])
    rgba = np.repeat(np.clip(panels[::-1], 0.0, 1.0)[..., None], 4, axis=-1)
    rgba[..., 3] = 1.0
    picture.pixels.foreach_set(rgba.astype(np.float32).ravel())
    picture.filepath_raw = str(path)
    picture.file_format = "PNG"
    picture.save()


def _compare(bpy, light_beta, tmp_path, label, observer=OBSERVER, rest_power=0.0):
    scene = _scene(bpy, light_beta, observer, rest_power)
    _module("pipeline.effect").apply(scene)
    lamps = []

    def seen(render_scene, *_args):  # the lamps the render has (the final render's stand-ins)
        lamps[:] = [
            f"{obj.name} ({obj.data.energy:.3g} W)"
            for obj in render_scene.objects
            if obj.type == "LIGHT" and not obj.hide_render
        ]

    bpy.app.handlers.render_post.append(seen)
    try:
        image = ch.luminance(ch.render_exr(bpy, scene, tmp_path / f"{label}.exr"))
    finally:
        bpy.app.handlers.render_post.remove(seen)
    model = _model(light_beta, observer)
    if rest_power > 0.0:  # light adds up: the lamp at rest through the same model
        model = model + _model(np.zeros(3), observer, rest_power)
    inner = _inner(model)
    _save_side_by_side(bpy, tmp_path / f"{label}_render_model_difference.png", image, model)
    rendered, expected = image[inner], model[inner]
    pattern = float(np.sum(np.abs(rendered - expected)) / np.sum(expected))
    total = float(rendered.sum() / expected.sum())
    shift = float(np.linalg.norm(_centroid(np.where(inner, image, 0.0)) - _centroid(np.where(inner, model, 0.0))))
    print(
        f"{label}: {inner.sum()} lit pixels, per-pixel error {pattern:.1%}, total {total:.4f}, "
        f"centroid {shift:.2f} px off; {len(lamps)} lamps render: " + ", ".join(lamps)
    )
    return pattern, total, shift


@pytest.mark.parametrize(("label", "light_beta"), [("parallel", (BETA, 0.0, 0.0)), ("antiparallel", (-BETA, 0.0, 0.0))])
def test_moving_light_on_moving_sphere(relativity_addon, factory_blender, tmp_path, label, light_beta):
    """The lit part within NOISE per pixel (noise included), 5 % in total and 1 px of the model."""
    pattern, total, shift = _compare(factory_blender, np.array(light_beta), tmp_path, label)
    assert pattern < NOISE
    assert total == pytest.approx(1.0, abs=0.05)
    assert shift < 1.0


def test_lamp_at_rest_on_moving_sphere_control(relativity_addon, factory_blender, tmp_path):
    """The control: the light at rest, lit by the lamps-at-rest stage through the same model."""
    pattern, total, shift = _compare(factory_blender, np.zeros(3), tmp_path, "rest")
    assert pattern < NOISE
    assert total == pytest.approx(1.0, abs=0.05)
    assert shift < 1.0


def test_moving_light_and_lamp_at_rest_on_moving_sphere(relativity_addon, factory_blender, tmp_path):
    """The antiparallel light and a lamp at rest as bright from where the sphere sees the light: the
    sphere's light tree holds both kinds of lamps (pair lamps, the lamps-at-rest stage's copies), and
    the light is their two models' sum, within NOISE per pixel."""
    light_beta = np.array((-BETA, 0.0, 0.0))
    pattern, total, shift = _compare(factory_blender, light_beta, tmp_path, "with_rest", rest_power=POWER)
    assert pattern < NOISE
    assert total == pytest.approx(1.0, abs=0.05)
    assert shift < 1.0


@pytest.mark.parametrize(("label", "light_beta"), [("parallel", (BETA, 0.0, 0.0)), ("antiparallel", (-BETA, 0.0, 0.0))])
def test_observer_at_rest_warns(relativity_addon, factory_blender, label, light_beta):
    """With the observer at rest Apparent Geometry renders the preview, whose material shader lights
    a moving object from a moving light as if the object were at rest: measured against the model
    above (the observer at rest, 64 samples) 1.77x (parallel) and 2.70x (antiparallel) of the light,
    79 % and 172 % per pixel (the light at rest there: 0.999, 0.7 %). Not fixed: the panel says so."""
    bpy = factory_blender
    scene = _scene(bpy, np.array(light_beta), observer=np.zeros(3))
    effect = _module("pipeline.effect")
    effect.apply(scene)
    found = [line for line in effect.scene_warnings(scene) if "Moving lights on moving objects" in line]
    print(found)
    assert len(found) == 1 and "\n" not in found[0]
    scene.relativity.beta = tuple(OBSERVER)  # the exact camera's final render: no warning
    assert not [line for line in effect.scene_warnings(scene) if "Moving lights on moving objects" in line]


def test_remove_restores_the_scene(relativity_addon, factory_blender):
    """The pair's lamps, their collections and the stand-ins' light linking are the add-on's while
    the final render's exact camera is set up; after the render and on Remove the file is as before."""
    bpy = factory_blender
    scene = _scene(bpy, np.array([BETA, 0.0, 0.0]))

    def state():
        return {
            "objects": sorted(obj.name for obj in bpy.data.objects),
            "lights": sorted(light.name for light in bpy.data.lights),
            "collections": sorted(collection.name for collection in bpy.data.collections),
            "linking": sorted(
                (obj.name, str(obj.light_linking.receiver_collection))
                for obj in bpy.data.objects
                if obj.type == "LIGHT"
            ),
            "scene_keys": sorted(scene.keys()),
        }

    before = state()
    effect = _module("pipeline.effect")
    effect.apply(scene)
    assert effect.begin_final_render(scene)
    pairs = [obj for obj in scene.objects if obj.name.startswith("Relativity Pair") and not obj.hide_render]
    stand_ins = [obj for obj in scene.objects if obj.name.startswith("Relativity Lamp ")]
    assert 2 <= len(pairs) <= 6 and stand_ins
    assert all(obj.light_linking.receiver_collection is not None for obj in pairs + stand_ins)
    effect.end_final_render(scene)
    effect.sync(scene)
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Relativity Pair")]
    assert effect.begin_final_render(scene)
    effect.remove(scene)
    assert state() == before


def test_exact_camera_method_refuses_the_moving_mesh(relativity_addon, factory_blender):
    """With the exact camera's method a moving mesh is refused (README), moving light or not: the
    case only arises on the Apparent Geometry path."""
    scene = _scene(factory_blender, np.array([BETA, 0.0, 0.0]))
    scene.relativity.method = "CAMERA"
    errors = importlib.import_module(f"{ADDON_MODULE}.errors")
    with pytest.raises(errors.RelativityError) as raised:
        _module("pipeline.effect").apply(scene)
    print(raised.value)
    assert "'Sphere'" in str(raised.value) and "\n" not in str(raised.value)
