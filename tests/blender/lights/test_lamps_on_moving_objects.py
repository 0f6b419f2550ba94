"""Lamps at rest lighting an object moving at 0.5c (Weiskopf et al. eq. 18, then eq. 14), real
Cycles renders on the Apparent Geometry path with a camera at rest (docs/lamp-doppler.md).

The object is a cube turned 25 degrees about Z, moving along +X; one lamp far ahead (+X), one far
behind (-X). The camera looks from the side (-Y): it sees (Penrose-Terrell rotation included) the
face lit only by the lamp ahead on the right and the face lit only by the lamp behind on the left.
Light from a lamp at rest reaches an object moving with ``beta`` with ``D = gamma (1 - beta . k)``
(docs/physics.md; ``k`` lamp -> object): ``sqrt(3)`` from ahead, ``1/sqrt(3)`` from behind. At a
given scene-frame distance the object-frame irradiance is ``D^2`` times the irradiance at rest
(eq. 18 with ``r' = D r``, eq. 25), and its spectrum is the lamp's shifted by ``D``
(``D^5 I(lambda D)`` per wavelength, eq. 18).

Eq. 14 (the object-to-camera factor, applied by the materials) and the apparent shape are the same
with and without eq. 18's factor, so each face's brightness over its brightness in the same
render with D set to 1 is eq. 18's factor alone. The face centres' absolute radiance and the
sides' ratio are compared with eqs. 18 and 14 written out here (rest-frame cosine, aberrated
photon direction, the point's own D, retarded positions).
"""

import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from blender_support import ADDON_MODULE
from relativity_addon.blender.common import compat
from relativity_addon.physics import spectral

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402

RESOLUTION = (96, 64)
BETA = 0.5
LAMP_DISTANCE = 100.0  # far: one D and direction per lamp and object good to ~1 % here
POWER = 450000.0
ALBEDO = 0.5
C = 10.0
CAMERA_DISTANCE = 12.0
LENS, SENSOR = 60.0, 36.0  # mm: the camera's focal length and (horizontal) sensor width
ROTATION = 25.0  # degrees about Z
D_AHEAD = math.sqrt((1.0 + BETA) / (1.0 - BETA))
D_BEHIND = 1.0 / D_AHEAD


def _module(name):
    return importlib.import_module(f"{ADDON_MODULE}.blender.{name}")


def _scene(bpy, beta=BETA, samples=16, temperature=None):
    scene, camera = ch.new_scene(
        bpy,
        resolution=RESOLUTION,
        samples=samples,
        location=(0.0, -CAMERA_DISTANCE, 0.0),
        rotation_euler=(math.pi / 2.0, 0.0, 0.0),
    )
    camera.data.lens = LENS
    camera.data.sensor_width = SENSOR
    camera.data.sensor_fit = "HORIZONTAL"
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.max_bounces = 0
    material = ch.diffuse_material(bpy, "Grey", (ALBEDO, ALBEDO, ALBEDO))
    mesh = bpy.data.meshes.new("Cube")
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(corners, [], faces)
    mesh.materials.append(material)
    cube = bpy.data.objects.new("Cube", mesh)
    cube.rotation_euler = (0.0, 0.0, math.radians(ROTATION))
    cube.location = (beta * CAMERA_DISTANCE, 0.0, 0.0)  # seen (light-travel time) near the image centre
    scene.collection.objects.link(cube)
    cube.relativity.enabled = True
    cube.relativity.motion = "CONSTANT"
    cube.relativity.beta = (beta, 0.0, 0.0)
    for name, x in (("Ahead", LAMP_DISTANCE), ("Behind", -LAMP_DISTANCE)):
        light = bpy.data.lights.new(name, "POINT")
        light.energy = POWER
        light.shadow_soft_size = 0.0
        if temperature is not None:
            light.use_temperature = True
            light.temperature = temperature
        lamp = bpy.data.objects.new(name, light)
        lamp.location = (x, 0.0, 0.0)
        scene.collection.objects.link(lamp)
    scene.relativity.speed_of_light = C
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.relativity.method = "GEOMETRY"
    bpy.context.view_layer.update()
    return scene, cube


def _render(bpy, scene, path):
    return ch.render_exr(bpy, scene, path)


def _edge(image):
    """The image column of the cube's front edge: the largest brightness step along the middle row."""
    row = ch.luminance(image)[image.shape[0] // 2]
    lit = np.nonzero(row > 0.02 * row.max())[0]
    steps = np.abs(np.diff(row[lit.min() + 2 : lit.max() - 1]))
    edge = lit.min() + 2 + int(np.argmax(steps))
    y = ch.luminance(image)
    rows = np.nonzero(np.minimum(y[:, edge - 3], y[:, edge + 3]) > 0.02 * y.max())[0]
    return edge, lit.min(), lit.max(), slice(rows.min() + 2, rows.max() - 1)


def _faces(image, edges):
    """Mean RGB of the face lit from ahead (right of the front edge: +X) and of the face lit from
    behind (left), two pixels away from every edge, over the rows where both are lit."""
    edge, left, right, band = edges
    return image[band, edge + 2 : right - 1].reshape(-1, 3).mean(axis=0), image[band, left + 2 : edge - 1].reshape(
        -1, 3
    ).mean(axis=0)


def _renders(bpy, scene, monkeypatch, tmp_path):
    """(with eq. 18, without): the same applied scene, eq. 18's factor set to D = 1 for the second
    (the lamp copies, light linking and rest-frame normals kept); each as (face lit from ahead,
    face lit from behind) mean RGB."""
    effect = _module("pipeline.effect")
    effect.apply(scene)
    with_eq18 = _render(bpy, scene, tmp_path / "with.exr")
    stage = _module("lights.lamps_on_moving_objects")
    copy_colour = stage.copy_colour
    monkeypatch.setattr(stage, "copy_colour", lambda lamp, _doppler, snap: copy_colour(lamp, 1.0, snap))
    without = _render(bpy, scene, tmp_path / "without.exr")
    monkeypatch.undo()
    edges = _edge(without)
    return _faces(with_eq18, edges), _faces(without, edges)


def _apparent(points):
    """Where the camera (at rest, at t_o) sees points of the cube that are at ``points`` at t_o:
    x_e = p - u tau with tau from docs/physics.md's closed form for uniform motion."""
    u = np.array([BETA * C, 0.0, 0.0])
    delta = np.array([0.0, -CAMERA_DISTANCE, 0.0]) - points
    du = delta @ u
    tau = (du + np.sqrt(du**2 + (C**2 - u @ u) * np.sum(delta * delta, axis=-1))) / (C**2 - u @ u)
    return points - tau[..., None] * u


def _face_predictions():
    """For the face lit from ahead and the one lit from behind, at the apparent position of the
    face's centre: (image column, radiance by eqs. 18 and 14 exactly, the same with Cycles'
    cosine on the apparent face, as before rest-frame normals).

    Both: albedo / pi * E' * D_oc^4 (eq. 14, D_oc = 1 / (gamma (1 - beta . k)), k toward the
    camera), Blender's point light of power P having intensity P / (4 pi). Exactly: eq. 18's
    cosine between the rest-frame normal and the object-frame photon direction (aberrated), with
    the point's own D; the other: the cosine on the apparent (retarded) face and D of the lamp ->
    cube centre direction."""
    gamma = 1.0 / math.sqrt(1.0 - BETA**2)
    beta = np.array([BETA, 0.0, 0.0])
    theta = math.radians(ROTATION)
    origin = np.array([BETA * CAMERA_DISTANCE, 0.0, 0.0])
    contract = np.diag([1.0 / gamma, 1.0, 1.0])
    camera = np.array([0.0, -CAMERA_DISTANCE, 0.0])
    centre = _apparent(origin[None])[0]
    result = []
    for normal, lamp in (
        ((math.sin(theta), -math.cos(theta), 0.0), (LAMP_DISTANCE, 0.0, 0.0)),
        ((-math.cos(theta), -math.sin(theta), 0.0), (-LAMP_DISTANCE, 0.0, 0.0)),
    ):
        normal, lamp = np.array(normal), np.array(lamp)
        along = np.cross(normal, (0.0, 0.0, 1.0))
        rest = np.array([normal, normal + 0.01 * along, normal + (0.0, 0.0, 0.01)])  # centre and two neighbours
        seen = _apparent(origin + rest @ contract.T)
        apparent_normal = np.cross(seen[1] - seen[0], seen[2] - seen[0])
        apparent_normal *= np.sign(apparent_normal @ normal) / np.linalg.norm(apparent_normal)
        point = seen[0]
        k = (point - lamp) / np.linalg.norm(point - lamp)
        to_camera = (camera - point) / np.linalg.norm(camera - point)
        d_camera = 1.0 / (gamma * (1.0 - beta @ to_camera))
        d_lamp = gamma * (1.0 - beta @ k)
        d_centre = gamma * (1.0 - beta @ ((centre - lamp) / np.linalg.norm(centre - lamp)))
        k_object = (k + (gamma - 1.0) * k[0] * np.array([1.0, 0.0, 0.0]) - gamma * beta) / (gamma * (1.0 - beta @ k))
        scale = ALBEDO / math.pi * POWER / (4.0 * math.pi) / np.sum((point - lamp) ** 2) * d_camera**4
        exact = scale * d_lamp**2 * -(normal @ k_object)
        apparent = scale * d_centre**2 * -(apparent_normal @ k)
        column = RESOLUTION[0] / 2.0 + point[0] / (point[1] + CAMERA_DISTANCE) * LENS / SENSOR * RESOLUTION[0]
        result.append((column, exact, apparent))
    return result


def _at_column(image, column):
    """Luminance at a (fractional) image column, linearly between pixel centres, over the middle rows."""
    rows = ch.luminance(image)[RESOLUTION[1] // 2 - 4 : RESOLUTION[1] // 2 + 4].mean(axis=0)
    return float(np.interp(column, np.arange(RESOLUTION[0]) + 0.5, rows))


def test_lit_sides_follow_eq_18_brightness(relativity_addon, factory_blender, tmp_path, monkeypatch):
    """Searchlight on, Doppler colour off (total energy): each face gains D^2 over eq. 14 alone,
    the lamp ahead 3x, the lamp behind 1/3x, so the two sides' ratio gains 9x."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    scene.relativity.use_doppler = False
    (ahead, behind), (ahead0, behind0) = _renders(bpy, scene, monkeypatch, tmp_path)
    image = ch.read_exr(bpy, tmp_path / "with.exr")
    (column_a, exact_a, apparent_a), (column_b, exact_b, apparent_b) = _face_predictions()
    seen_a, seen_b = _at_column(image, column_a), _at_column(image, column_b)
    print(
        f"face centres: ahead {seen_a:.4f} (eqs. 18 and 14 {exact_a:.4f}; apparent-face cosine {apparent_a:.4f}), "
        f"behind {seen_b:.4f} ({exact_b:.4f}; {apparent_b:.4f}); side ratio {seen_a / seen_b:.4f}, "
        f"eqs. 18 and 14 {exact_a / exact_b:.4f}, apparent-face cosine {apparent_a / apparent_b:.4f}"
    )
    assert seen_a == pytest.approx(exact_a, rel=0.03)
    assert seen_b == pytest.approx(exact_b, rel=0.03)
    assert seen_a / seen_b == pytest.approx(exact_a / exact_b, rel=0.03)
    gain_ahead = ch.luminance(ahead) / ch.luminance(ahead0)
    gain_behind = ch.luminance(behind) / ch.luminance(behind0)
    ratio, ratio0 = ch.luminance(ahead) / ch.luminance(behind), ch.luminance(ahead0) / ch.luminance(behind0)
    print(
        f"gain ahead {gain_ahead:.4f} (D^2 = {D_AHEAD**2:.4f}), behind {gain_behind:.4f} "
        f"(D^2 = {D_BEHIND**2:.4f}); side ratio {ratio:.4f} with eq. 18, {ratio0:.4f} without"
    )
    assert gain_ahead == pytest.approx(D_AHEAD**2, rel=0.03)
    assert gain_behind == pytest.approx(D_BEHIND**2, rel=0.03)
    assert ratio / ratio0 == pytest.approx((D_AHEAD / D_BEHIND) ** 2, rel=0.04)


@pytest.mark.parametrize("temperature", [None, 4000.0])
def test_lit_sides_follow_eq_18_colour(relativity_addon, factory_blender, tmp_path, monkeypatch, temperature):
    """Doppler colour and searchlight on: the light reaching each face is the lamp's spectrum
    shifted by D and scaled by D^-2 (eq. 18 with r' = D r), computed here with colour-science:
    for a white lamp, ``D^-2 M(D) (1, 1, 1)``, M the project's up-sampled-RGB matrix
    (physics/spectral.py); for a 4000 K lamp, a blackbody at ``D T`` with luminance
    ``D^-2 Y(D T)/Y(T)``. The materials multiply every channel by the same eq. 14 factor with and
    without eq. 18, so each channel's gain is the lamp's."""
    bpy = factory_blender
    scene, _ = _scene(bpy, temperature=temperature)
    faces, faces0 = _renders(bpy, scene, monkeypatch, tmp_path)
    for name, doppler, face, face0 in zip(("ahead", "behind"), (D_AHEAD, D_BEHIND), faces, faces0, strict=True):
        if temperature is None:
            expected = spectral.doppler_shift_rgb((1.0, 1.0, 1.0), doppler) / doppler**2
        else:
            rest = spectral.blackbody_linear_rgb(temperature, gamut_map=True)
            shifted = spectral.blackbody_linear_rgb(doppler * temperature, gamut_map=True)
            y_ratio = spectral.blackbody_luminance_ratio(temperature, doppler)
            expected = (
                shifted
                / spectral.luminance_linear_rec709(shifted)
                * y_ratio
                / doppler**2
                / (rest / spectral.luminance_linear_rec709(rest))
            )
        gain = face / face0
        print(
            f"{temperature} {name}: D {doppler:.4f}, channel gains {np.round(gain, 4)}, "
            f"expected {np.round(expected, 4)}"
        )
        np.testing.assert_allclose(gain, expected, rtol=0.03)


def test_object_at_rest_renders_as_without_the_effect(relativity_addon, factory_blender, tmp_path):
    """Velocity 0: no copy, and the render is the plain render's (no stage, no light linking)."""
    bpy = factory_blender
    scene, cube = _scene(bpy, beta=0.0)
    plain = _render(bpy, scene, tmp_path / "plain.exr")
    _module("pipeline.effect").apply(scene)
    assert not any(_module("lights.lamps_on_moving_objects").is_copy(obj) for obj in scene.objects)
    applied = _render(bpy, scene, tmp_path / "applied.exr")
    assert plain.max() > 0.05
    np.testing.assert_allclose(applied, plain, rtol=1e-4, atol=1e-5)


def _state(bpy):
    return {
        "objects": sorted(obj.name for obj in bpy.data.objects),
        "lights": sorted(
            (light.name, tuple(light.color), light.energy, light.use_temperature) for light in bpy.data.lights
        ),
        "collections": sorted(collection.name for collection in bpy.data.collections),
        "linking": sorted(
            (
                obj.name,
                str(obj.light_linking.receiver_collection),
                str(obj.light_linking.blocker_collection),
                tuple(k for k in obj.keys() if k != "relativity"),
            )
            for obj in bpy.data.objects
        ),
        "scene keys": sorted(bpy.context.scene.keys()),
        "meshes": sorted(
            (mesh.name, tuple(attribute.name for attribute in mesh.attributes), mesh.attributes.active_index)
            for mesh in bpy.data.meshes
        ),
        "materials": sorted(
            (
                material.name,
                tuple(sorted(node.name for node in material.node_tree.nodes)),
                len(material.node_tree.links),
                tuple(material.keys()),
            )
            for material in bpy.data.materials
        ),
        "node groups": sorted(group.name for group in bpy.data.node_groups),
    }


def test_remove_restores_lights_collections_and_light_linking(relativity_addon, factory_blender, tmp_path):
    """Apply (copies, collections, light linking, rest-normal attribute and material nodes), change
    a lamp, sync, then remove: the scene's lights, collections, light-linking settings, meshes'
    attributes and materials are exactly as before; a render matches."""
    bpy = factory_blender
    scene, cube = _scene(bpy, temperature=5000.0)
    before = _state(bpy)
    plain = _render(bpy, scene, tmp_path / "plain.exr")
    effect = _module("pipeline.effect")
    effect.apply(scene)
    added = [obj for obj in scene.objects if _module("lights.lamps_on_moving_objects").is_copy(obj)]
    assert {obj[_module("common.names").LAMP_DOPPLER_COPY_KEY][0] for obj in added} == {"Ahead", "Behind"}
    assert scene.objects["Ahead"].light_linking.receiver_collection is not None
    assert cube.data.attributes.get(_module("common.names").REST_NORMAL_ATTRIBUTE) is not None
    scene.objects["Ahead"].data.energy = POWER  # an edit while applied: the copies follow, nothing new
    effect.sync(scene)
    scene.objects["Behind"].name = "Renamed"  # a lamp renamed while applied: its copy is rebuilt
    effect.sync(scene)
    assert sum(_module("lights.lamps_on_moving_objects").is_copy(obj) for obj in scene.objects) == len(added)
    effect.remove(scene)
    scene.objects["Renamed"].name = "Behind"
    assert _state(bpy) == before
    cube.relativity.enabled = False  # the plain render had no apparent geometry either
    np.testing.assert_allclose(_render(bpy, scene, tmp_path / "removed.exr"), plain, rtol=1e-4, atol=1e-5)


def test_stand_ins_of_a_side_lamp_lie_where_the_object_sees_it(relativity_addon, factory_blender):
    """A lamp beside the cube's path: its stand-ins lie on the line through the lamp along the
    motion (+X), and the place where the cube's (seen) centre sees the lamp in its own frame, at
    the object-frame distance D r along the photon direction boosted (docs/physics.md, eq. 25),
    lies on that line between the first and the last; their colour is the centre's D^2
    (searchlight, Doppler colour off), each point's own D is their trees'; moving the lamp and
    syncing moves them."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    scene.relativity.use_doppler = False
    for name in ("Behind",):
        bpy.data.objects.remove(bpy.data.objects[name])
    lamp = scene.objects["Ahead"]
    effect = _module("pipeline.effect")
    centre = _apparent(np.array([[BETA * CAMERA_DISTANCE, 0.0, 0.0]]))[0]
    gamma = 1.0 / math.sqrt(1.0 - BETA**2)
    beta = np.array([BETA, 0.0, 0.0])
    for position in ((0.0, 20.0, 3.0), (-5.0, -15.0, 0.0)):
        lamp.location = position
        bpy.context.view_layer.update()
        if effect.applied_method(scene) is None:
            effect.apply(scene)
        else:
            effect.sync(scene)
        copies = [obj for obj in scene.objects if _module("lights.lamps_on_moving_objects").is_copy(obj)]
        assert len(copies) > 1
        r = np.linalg.norm(centre - np.array(position))
        k = (centre - np.array(position)) / r
        doppler = gamma * (1.0 - beta @ k)
        k_object = (k + (gamma - 1.0) * k[0] * np.array([1.0, 0.0, 0.0]) - gamma * beta) / doppler
        seen_at = centre - doppler * r * k_object
        along = np.array([np.array(copy.matrix_world.translation) for copy in copies])
        np.testing.assert_allclose(along[:, 1:], np.tile(np.array(position)[1:], (len(copies), 1)), atol=1e-5)
        np.testing.assert_allclose(seen_at[1:], np.array(position)[1:], atol=1e-6)
        assert along[:, 0].min() < seen_at[0] < along[:, 0].max()
        for copy in copies:
            np.testing.assert_allclose(tuple(copy.data.color), [doppler**2] * 3, rtol=1e-5)
            assert not copy.visible_camera and copy.light_linking.receiver_collection is not None


def test_keyframed_motion_gives_the_constant_velocity_factor(relativity_addon, factory_blender):
    """The same cube keyframed at 0.5c (linear, extrapolated) instead of CONSTANT: its lamp copies
    carry the same D^2 (the centre's velocity and retarded position come from its keyframes)."""
    bpy = factory_blender
    colours = {}
    for motion in ("CONSTANT", "ANIMATION"):
        scene, cube = _scene(bpy)
        scene.relativity.use_doppler = False
        scene.objects["Behind"].location = (-20.0, 10.0, 0.0)  # off the axis: the copy is turned too
        if motion == "ANIMATION":
            cube.relativity.motion = "ANIMATION"
            fps = scene.render.fps / scene.render.fps_base
            start = cube.location.x
            for frame in (1, 25):
                cube.location.x = start + BETA * C * (frame - scene.frame_current) / fps
                cube.keyframe_insert("location", index=0, frame=frame)
            fcurve = next(f for f in compat.action_fcurves(cube.animation_data) if f.array_index == 0)
            for point in fcurve.keyframe_points:
                point.interpolation = "LINEAR"
            fcurve.extrapolation = "LINEAR"
            scene.frame_set(scene.frame_current)
        _module("pipeline.effect").apply(scene)
        colours[motion] = {
            obj.name: (tuple(obj.data.color), tuple(obj.matrix_world.translation))
            for obj in scene.objects
            if _module("lights.lamps_on_moving_objects").is_copy(obj)
        }
        _module("pipeline.effect").remove(scene)
    assert set(colours["CONSTANT"]) == set(colours["ANIMATION"]) and len(colours["CONSTANT"]) >= 2
    for name, (colour, position) in colours["CONSTANT"].items():
        np.testing.assert_allclose(colours["ANIMATION"][name][0], colour, rtol=1e-4)
        np.testing.assert_allclose(
            colours["ANIMATION"][name][1], position, rtol=1e-4, atol=1e-3
        )  # float32 keys, sampled; stand-ins up to 73 m out


def test_moving_observer_final_render_keeps_eq_18(relativity_addon, factory_blender, tmp_path, monkeypatch):
    """Observer at 0.2c: the Apparent Geometry final render photographs the scene-frame meshes
    through the exact camera, with the lamp copies and light linking as at rest: each face still
    gains eq. 18's D^2 (the scene-frame factor; eq. 14 now carries the observer's motion)."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    scene.relativity.use_doppler = False
    scene.relativity.beta = (0.0, 0.2, 0.0)
    cameras = []

    def probe(render_scene, *_):
        cameras.append(render_scene.camera.data.type)

    bpy.app.handlers.render_pre.append(probe)
    try:
        (ahead, behind), (ahead0, behind0) = _renders(bpy, scene, monkeypatch, tmp_path)
    finally:
        bpy.app.handlers.render_pre.remove(probe)
    assert cameras == ["CUSTOM", "CUSTOM"] and scene.camera.data.type == "PERSP"  # exact camera for the renders
    assert ch.luminance(ahead) / ch.luminance(ahead0) == pytest.approx(D_AHEAD**2, rel=0.03)
    assert ch.luminance(behind) / ch.luminance(behind0) == pytest.approx(D_BEHIND**2, rel=0.03)


@pytest.mark.parametrize("movers", (30, 63, 64))
def test_more_light_linking_collections_than_cycles_renders_is_warned(relativity_addon, factory_blender, capfd, movers):
    """Each lamp and moving object pair gets its own receiver collection; Cycles renders at most 64
    light-linking collections and ignores the rest (its console line: "Maximum number of light
    linking collections (64) exceeded"), so past that some moving objects are lit wrongly. Set Up
    still works; the panel says so, exactly when Cycles drops collections."""
    bpy = factory_blender
    scene, cube = _scene(bpy, samples=1)
    scene.render.resolution_x, scene.render.resolution_y = 16, 12
    bpy.data.objects.remove(bpy.data.objects["Behind"])
    for number in range(movers - 1):
        extra = cube.copy()
        extra.data = cube.data
        extra.location = (cube.location.x + 3.0 * (number + 1), 0.0, 0.0)
        scene.collection.objects.link(extra)
    bpy.context.view_layer.update()
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    stage = _module("lights.lamps_on_moving_objects")
    used = stage.light_linking_collections(scene)
    warned = [line for line in _module("pipeline.effect").scene_warnings(scene) if "light-linking" in line]
    capfd.readouterr()
    ch.render_exr(bpy, scene, Path(bpy.app.tempdir) / f"linking_{movers}.exr")
    captured = capfd.readouterr()
    dropped = "light linking collections" in (captured.err + captured.out).lower()
    print(f"{movers} moving objects: {used} light-linking collections, warned {bool(warned)}, Cycles dropped {dropped}")
    assert used == movers + 1  # one for the lamp's own light, one per object
    assert bool(warned) == (used > 64)
    assert dropped == bool(warned)
