"""Acceptance: a setting changed in the panel after Set Up reaches the next F12 render, on both paths.

Only the user-facing surface is used: the scene is set up with the N-panel's button
(``bpy.ops.relativity.setup_scene``), a setting is changed by assigning the property as the panel
does (``scene.relativity.use_doppler = False``, ``obj.relativity.beta = ...``), and the frame is
rendered with F12's operator (``bpy.ops.render.render``), read back from ``Render Result``.

For each setting the render after the change is compared with a fresh set-up made with that
setting from the start (Remove Relativistic Effect, the scene built anew with the setting, Set Up,
F12): the two must agree to within render noise (the same set-up renders identically: fixed seed
and sample count, measured in ``test_identical_set_ups_render_identically``). And the fresh
render must differ from the render before the change by far more than that, so that a setting
which did nothing visible cannot pass.

The scene (F12 of the plain scene: red, green and blue spheres above a white one, a grey floor): a
camera moving at 0.5 c (sideways and forward), red and green emitting spheres, a blackbody emitter
(``Object.relativity.temperature``), a blue sphere moving on its own at 0.5 c (apparent-geometry
path), a diffuse floor lit by a point light (one quad: its tessellation shows in its curved edges).
Its keyframed camera moves at (0.2, 0, -0.4) c for the speed of light of 10 units/s used
throughout, different from the manual velocity, so the velocity source shows too. Emitters are
not sampled as lights and paths do not bounce, so a set-up renders exactly the same pixels every
time (measured: 0 difference, also after rebuilding the scene); with light sampling, rebuilding
the same scene changed the noise pattern by about 2% of the mean pixel value.

Not a case: switching the velocity source back from Camera Animation to Manual. The animation
overwrites the Velocity setting (by design, see props.py), so Manual then keeps the last animated
velocity and there is no "fresh set-up with that setting" to compare with.
"""

import numpy as np
import pytest

import pipeline_helpers as wh

ch = wh.ch

RESOLUTION = (48, 36)
SAMPLES = 4
# Mean absolute difference (linear RGB; mean pixel value about 0.5) allowed between two renders of
# the same set-up (measured: exactly 0), and the least a setting must change the image by to count
# as visible (the smallest change below measured 0.04, the object velocity).
SAME = 1e-4
VISIBLE = 1e-2

C = 10.0  # scene units per second
FPS = 24
FRAME = 5  # the camera passes the origin at this frame
CAMERA_KEYS = ((0, (-5 / 12, 0.0, 5 / 6)), (10, (5 / 12, 0.0, -5 / 6)))  # (0.2, 0, -0.4) c for C and FPS
MANUAL_BETA = (-0.2, 0.1, -0.45)

BASE_SCENE = {
    "speed_of_light": C,
    "beta": MANUAL_BETA,
    "shutter_model": "PINHOLE",
    "shutter_time": 0.0,
    "use_lorentz_window": False,
    "lorentz_window_shutter": "WINDOW_PLANE",
    "lorentz_window_time": 0.0,
    "use_geometry": True,
    "use_time_of_flight": False,
    "use_doppler": True,
    "use_searchlight": True,
    "use_chang_searchlight": False,
    "velocity_source": "MANUAL",
    "fast_illuminant": "AUTO",  # a white lamp and a blackbody emitter: white
    "fast_illuminant_temperature": 5762.0,
}
BASE_OBJECTS = {
    "Mover": {"enabled": True, "motion": "CONSTANT", "beta": (0.5, 0.0, 0.0)},
    "Blackbody": {"temperature": 4500.0},
    "Floor": {"tessellation": 1},
}
CAMERA_MOVER = {"motion": "STATIC"}
ARBITRARY_PLANE = {
    "shutter_model": "ARBITRARY_PLANE",
    "shutter_plane_point": (0.0, 0.0, -1.0),
    "shutter_plane_normal": (0.0, 0.0, -1.0),
}
FROM_ANIMATION = {"velocity_source": "CAMERA_ANIMATION"}


def case(method, target, name, value, base=None, objects=None, label=None):
    """One setting change: ``target`` is "scene" (scene.relativity) or an object's name."""
    label = label or f"{name}={value}"
    return pytest.param(
        method, dict(base or {}), dict(objects or {}), target, name, value, id=f"{method}-{target}-{label}"
    )


CASES = [
    # Exact camera: every scene setting.
    case("CAMERA", "scene", "speed_of_light", 15.0, base=FROM_ANIMATION),
    case("CAMERA", "scene", "beta", (0.4, -0.1, -0.5)),
    case("CAMERA", "scene", "shutter_model", "FOCUS_SURFACE"),
    case("CAMERA", "scene", "shutter_time", 0.2),
    case("CAMERA", "scene", "shutter_model", "ARBITRARY_PLANE", base={"shutter_plane_point": (0.0, 0.0, -4.0)}),
    case("CAMERA", "scene", "shutter_plane_point", (0.0, 0.0, -4.0), base=ARBITRARY_PLANE),
    case(
        "CAMERA",
        "scene",
        "shutter_plane_normal",
        (0.6, 0.0, -0.8),
        base={**ARBITRARY_PLANE, "shutter_plane_point": (0.0, 0.0, -4.0)},
    ),
    case("CAMERA", "scene", "use_lorentz_window", True),
    case(
        "CAMERA",
        "scene",
        "lorentz_window_shutter",
        "SHUTTER_MODEL",
        base={"use_lorentz_window": True, "shutter_time": 0.2},
    ),
    case(
        "CAMERA",
        "scene",
        "lorentz_window_time",
        -0.2,
        base={"use_lorentz_window": True, "lorentz_window_shutter": "SHUTTER_MODEL"},
    ),
    case("CAMERA", "scene", "use_geometry", False),
    case("CAMERA", "scene", "use_time_of_flight", True),
    case("CAMERA", "scene", "use_doppler", False),
    case("CAMERA", "scene", "use_searchlight", False),
    case("CAMERA", "scene", "use_chang_searchlight", True),
    case("CAMERA", "scene", "doppler_only_brightness", "SPECTRUM", base={"use_searchlight": False}),
    case("CAMERA", "scene", "velocity_source", "CAMERA_ANIMATION"),
    case("CAMERA", "Blackbody", "temperature", 9000.0),
    case("CAMERA", "scene", "fast_illuminant", "BLACKBODY", base={"fast_illuminant_temperature": 2500.0}),
    case("CAMERA", "scene", "fast_illuminant_temperature", 2500.0, base={"fast_illuminant": "BLACKBODY"}),
    case(
        "CAMERA",
        "scene",
        "method",
        "GEOMETRY",
        base={"geometry_final_render": "PREVIEW"},
        objects={"Mover": CAMERA_MOVER},
    ),  # switching the method after Set Up
    # Apparent geometry: the scene settings that apply there, and every object setting.
    case("GEOMETRY", "scene", "speed_of_light", 15.0, base=FROM_ANIMATION),
    case("GEOMETRY", "scene", "beta", (0.4, -0.1, -0.5)),
    case("GEOMETRY", "scene", "use_doppler", False),
    case("GEOMETRY", "scene", "use_searchlight", False),
    case("GEOMETRY", "scene", "use_chang_searchlight", True),
    case(
        "GEOMETRY",
        "scene",
        "doppler_only_brightness",
        "SPECTRUM",
        base={"use_searchlight": False, "geometry_final_render": "PREVIEW"},
    ),
    case("GEOMETRY", "scene", "velocity_source", "CAMERA_ANIMATION"),
    case(
        "GEOMETRY",
        "scene",
        "method",
        "CAMERA",
        base={"geometry_final_render": "PREVIEW"},
        objects={"Mover": CAMERA_MOVER},
    ),
    case("GEOMETRY", "Mover", "enabled", False),
    case("GEOMETRY", "Mover", "enabled", True, objects={"Mover": {"enabled": False}}),
    case("GEOMETRY", "Mover", "motion", "STATIC"),
    case("GEOMETRY", "Mover", "beta", (-0.3, 0.3, 0.5)),
    # the moving emitter lights the floor as a moving light (the preview's material shader)
    case("GEOMETRY", "Mover", "lights_scene", True, base={"geometry_final_render": "PREVIEW"}),
    case("GEOMETRY", "Blackbody", "temperature", 9000.0),
    case("GEOMETRY", "scene", "geometry_final_render", "PREVIEW"),
    # Tessellation shapes the boosted-mesh preview; the exact final render of a mesh at rest
    # does not depend on it (measured: identical renders).
    case("GEOMETRY", "Floor", "tessellation", 4, base={"geometry_final_render": "PREVIEW"}),
]


# --- the scene --------------------------------------------------------------------------------


def _emitter(bpy, name, colour, strength=1.0):
    material = ch.emission_material(bpy, name, strength=strength)
    material.node_tree.nodes["Emission"].inputs["Color"].default_value = (*colour, 1.0)
    material.cycles.emission_sampling = "NONE"
    return material


def _wipe(bpy):
    """Everything the scene builder made, so a rebuild starts from nothing."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.context.scene.world = None
    for kind in ("meshes", "materials", "lights", "cameras", "worlds", "actions"):
        collection = getattr(bpy.data, kind)
        for item in list(collection):
            if item.users == 0:
                collection.remove(item)


def build_scene(bpy, method, scene_settings, object_settings):
    """The test scene with ``scene.relativity`` and each object's ``relativity`` set (not set up)."""
    _wipe(bpy)
    scene = ch.reset_cycles_scene(bpy, RESOLUTION, SAMPLES)
    scene.cycles.seed = 0
    scene.cycles.use_animated_seed = False
    # Direct light from the lamp only: emitters are not sampled as lights and no path bounces, so
    # the render is a deterministic function of the scene (no sampling noise to hide a change in).
    scene.cycles.max_bounces = 0
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    scene.frame_start, scene.frame_end = 1, 9

    data = bpy.data.cameras.new("Camera")
    data.lens = 30.0
    data.clip_start, data.clip_end = 0.001, 1000.0
    data.dof.use_dof = True  # the focus-surface shutter needs a focus distance; f/1000 stays sharp
    data.dof.focus_distance = 5.0
    data.dof.aperture_fstop = 1000.0
    camera = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    wh.keyframe_camera_path(camera, CAMERA_KEYS)

    wh.add_sphere(bpy, scene, (-1.3, 0.5, -5.0), 0.45, _emitter(bpy, "Red", (1.0, 0.1, 0.05), 2.0), name="Red")
    wh.add_sphere(bpy, scene, (1.3, 0.5, -5.0), 0.45, _emitter(bpy, "Green", (0.1, 1.0, 0.2), 2.0), name="Green")
    wh.add_sphere(
        bpy, scene, (0.0, -0.3, -6.0), 0.5, _emitter(bpy, "Blackbody", (1.0, 1.0, 1.0), 1.0), name="Blackbody"
    )
    wh.add_sphere(bpy, scene, (0.0, 1.0, -4.5), 0.35, _emitter(bpy, "Mover", (0.2, 0.3, 1.0), 2.0), name="Mover")

    mesh = bpy.data.meshes.new("Floor")
    mesh.from_pydata(
        [(-4.0, -1.2, -1.5), (4.0, -1.2, -1.5), (4.0, -1.2, -11.0), (-4.0, -1.2, -11.0)], [], [(0, 1, 2, 3)]
    )
    mesh.materials.append(ch.diffuse_material(bpy, "Floor", (0.8, 0.8, 0.8)))
    floor = bpy.data.objects.new("Floor", mesh)
    scene.collection.objects.link(floor)

    light_data = bpy.data.lights.new("Lamp", "POINT")
    light_data.energy = 150.0
    light_data.shadow_soft_size = 0.0
    light = bpy.data.objects.new("Lamp", light_data)
    light.location = (0.0, 2.0, -4.0)
    scene.collection.objects.link(light)

    scene.frame_set(FRAME)
    settings = scene.relativity
    settings.method = method
    for name, value in {**BASE_SCENE, **scene_settings}.items():
        if name != "velocity_source":
            setattr(settings, name, value)
    settings.velocity_source = {**BASE_SCENE, **scene_settings}["velocity_source"]
    # the exact camera photographs a static scene (an object's own velocity is refused there)
    base_objects = (
        {**BASE_OBJECTS, "Mover": {**BASE_OBJECTS["Mover"], **CAMERA_MOVER}} if method == "CAMERA" else BASE_OBJECTS
    )
    for obj_name in set(base_objects) | set(object_settings):
        values = {**base_objects.get(obj_name, {}), **object_settings.get(obj_name, {})}
        for name, value in values.items():
            setattr(bpy.data.objects[obj_name].relativity, name, value)
    bpy.context.view_layer.update()
    return scene


def set_up(bpy):
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}


def render(bpy, scene, path):
    """F12, then the Render Result image saved and read back (linear float EXR)."""
    assert bpy.ops.render.render() == {"FINISHED"}
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    bpy.data.images["Render Result"].save_render(filepath=str(path), scene=scene)
    image = ch.read_exr(bpy, path)
    assert np.isfinite(image).all()
    return image


def difference(a, b):
    return float(np.abs(a - b).mean())


def set_value(bpy, scene, target, name, value):
    """What the panel does: assign the property."""
    owner = scene.relativity if target == "scene" else bpy.data.objects[target].relativity
    setattr(owner, name, value)


# --- tests ------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
def test_identical_set_ups_render_identically(relativity_addon, factory_blender, tmp_path, method):
    """The noise floor the comparisons rely on: the same set-up, built twice, renders the same."""
    bpy = factory_blender
    scene = build_scene(bpy, method, {}, {})
    set_up(bpy)
    first = render(bpy, scene, tmp_path / "first.exr")
    again = render(bpy, scene, tmp_path / "again.exr")
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    scene = build_scene(bpy, method, {}, {})
    set_up(bpy)
    rebuilt = render(bpy, scene, tmp_path / "rebuilt.exr")
    print(
        f"{method}: mean {first.mean():.4f}, max {first.max():.3f}; same set-up rendered again "
        f"{difference(first, again):.2e}, rebuilt {difference(first, rebuilt):.2e}"
    )
    assert first.mean() > 0.02 and first.max() > 0.5  # the scene is in view
    assert difference(first, again) <= SAME
    assert difference(first, rebuilt) <= SAME


@pytest.mark.parametrize("method, base, objects, target, name, value", CASES)
def test_changed_setting_reaches_next_render(
    relativity_addon, factory_blender, tmp_path, method, base, objects, target, name, value
):
    bpy = factory_blender
    scene = build_scene(bpy, method, base, objects)
    set_up(bpy)
    before = render(bpy, scene, tmp_path / "before.exr")
    set_value(bpy, scene, target, name, value)
    after = render(bpy, scene, tmp_path / "after.exr")

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    fresh_scene, fresh_objects = dict(base), {key: dict(values) for key, values in objects.items()}
    if target == "scene":
        fresh_scene[name] = value
    else:
        fresh_objects.setdefault(target, {})[name] = value
    method_fresh = fresh_scene.pop("method", method)
    scene = build_scene(bpy, method_fresh, fresh_scene, fresh_objects)
    set_up(bpy)
    fresh = render(bpy, scene, tmp_path / "fresh.exr")

    changed, stale = difference(fresh, before), difference(after, fresh)
    print(f"{name} -> {value!r}: fresh set-up vs before {changed:.2e}; after the change vs fresh set-up {stale:.2e}")
    assert changed >= VISIBLE, "the setting makes no visible difference in this scene: the test would be vacuous"
    assert stale <= SAME, (
        f"after changing {name} to {value!r} in the panel, F12 renders {stale:.3g} (mean |difference|) away from "
        f"a fresh set-up with that setting (the change itself is {changed:.3g}; "
        f"after vs before {difference(after, before):.3g}; mean pixel before {before.mean():.3g}, after "
        f"{after.mean():.3g}, fresh {fresh.mean():.3g})"
    )
