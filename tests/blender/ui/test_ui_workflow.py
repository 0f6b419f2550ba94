"""A new user's path through the UI: panel, presets, set up at 0.9 c, render, remove everything.

Operators run through ``bpy.ops`` on the real scene; the add-on is installed from the built zip
(shipped presets included). Background Blender has no window, so the panels draw into a small
recording stand-in for ``UILayout`` that checks every property and operator they reference.
"""

import math
import os

import numpy as np
import pytest

import pipeline_helpers as wh
from relativity_addon.blender.common import compat
from relativity_addon.physics.shutter import lens_time


class RecordingLayout:
    """Records what a panel draws; checks names against the real RNA and registered classes."""

    def __init__(self, bpy, log=None):
        self.bpy, self.log = bpy, log if log is not None else []
        self.use_property_split = self.use_property_decorate = self.enabled = True

    def _child(self, *args, **kwargs):
        return RecordingLayout(self.bpy, self.log)

    row = column = box = split = _child

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{type(data).__name__} has no property {name!r}"
        self.log.append(("prop", name))

    def label(self, text="", icon="NONE", **kwargs):
        self.log.append(("label", text, icon))

    def menu(self, idname, text="", **kwargs):
        assert hasattr(self.bpy.types, idname), f"menu {idname} is not registered"
        self.log.append(("menu", idname))

    def operator(self, idname, text="", icon="NONE", **kwargs):
        module, name = idname.split(".")
        assert hasattr(getattr(self.bpy.ops, module), name), f"operator {idname} is not registered"
        self.log.append(("operator", idname))

        class Properties:
            pass

        return Properties()


class FakeContext:
    def __init__(self, scene, obj):
        self.scene, self.object = scene, obj


def draw_panel(bpy, idname, scene, obj=None):
    panel_class = getattr(bpy.types, idname)
    context = FakeContext(scene, obj)
    assert panel_class.poll(context)
    layout = RecordingLayout(bpy)
    # A Panel instance cannot be made outside a UI region; draw() only uses self.layout.
    panel_class.draw(type("PanelShim", (), {"layout": layout})(), context)
    return layout.log


def fingerprint(bpy):
    """Everything the add-on may touch, as one string (compared before apply and after remove)."""

    def idprops(owner):
        return repr(sorted((key, repr(owner[key])) for key in compat.custom_property_keys(owner)))

    cameras = []
    for data in bpy.data.cameras:
        cameras.append(
            (
                data.name,
                data.type,
                data.custom_mode,
                data.lens,
                repr(data.custom_shader),
                data.custom_filepath,
                data.custom_bytecode,
                idprops(data),
                idprops(data.cycles_custom),
            )
        )
    objects = []
    for obj in bpy.data.objects:
        objects.append(
            (
                obj.name,
                obj.type,
                tuple(map(tuple, obj.matrix_world)),
                repr(obj.data),
                tuple((m.name, m.type) for m in obj.modifiers),
                idprops(obj),
            )
        )
    meshes = [(m.name, len(m.vertices), m.vertices[0].co[:] if len(m.vertices) else ()) for m in bpy.data.meshes]
    names = {
        kind: sorted(item.name for item in getattr(bpy.data, kind))
        for kind in ("texts", "node_groups", "materials", "worlds", "scenes")
    }
    # Rendering adds the "Render Result" image: that is Blender's, not the add-on's.
    names["images"] = sorted(image.name for image in bpy.data.images if image.type == "IMAGE")
    scene = bpy.context.scene
    render = (scene.render.engine, repr(getattr(scene, "compositing_node_group", None)))
    return repr((cameras, objects, meshes, names, render))


def test_new_user_sets_up_09c_renders_and_removes_everything(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy, resolution=(64, 48), samples=2, with_camera=False)
    settings = scene.relativity

    # Without a camera the button is disabled and says why (poll_message_set).
    assert not bpy.ops.relativity.setup_scene.poll()
    assert not bpy.ops.relativity.remove_all.poll()
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert any(e[0] == "label" and e[2] == "ERROR" and "has no active camera" in e[1] for e in log)

    data = bpy.data.cameras.new("Camera")
    camera = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.rotation_euler = (0.3, -0.2, 0.5)  # a turned camera: the preset follows its view
    bpy.context.view_layer.update()
    assert bpy.ops.relativity.setup_scene.poll()

    # The 0.9c speed preset from the shipped presets, through Blender's preset operator.
    preset = os.path.join(bpy.utils.preset_paths("relativity/speed")[0], "0.9c.py")
    assert bpy.ops.script.execute_preset(filepath=preset, menu_idname="RELATIVITY_MT_speed_presets") == {"FINISHED"}
    view = np.array(camera.matrix_world.to_quaternion().to_matrix()) @ np.array([0.0, 0.0, -1.0])
    np.testing.assert_allclose(tuple(settings.beta), 0.9 * view, atol=1e-6)

    log = draw_panel(bpy, "RELATIVITY_PT_observer", scene)
    assert ("label", "Speed: 0.9 c", "NONE") in log
    assert ("label", f"Gamma: {1 / math.sqrt(1 - 0.81):.6g}", "NONE") in log
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert not [entry for entry in log if entry[0] == "label" and entry[2] == "ERROR"]
    for op in ("relativity.setup_scene", "relativity.remove_all"):
        assert ("operator", op) in log

    before = fingerprint(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert data.type == "CUSTOM" and bpy.ops.relativity.remove_all.poll()
    assert fingerprint(bpy) != before
    scene.render.filepath = str(tmp_path / "ui.png")
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    image = wh.read_image(bpy, tmp_path / "ui.png")
    assert np.isfinite(image).all()

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert fingerprint(bpy) == before
    assert data.type == "PERSP"
    assert not bpy.ops.relativity.remove_all.poll()


def test_operator_reports_errors_and_changes_nothing(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    scene.relativity.beta = (0.0, 0.0, -1.2)
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert any(e[0] == "label" and e[2] == "ERROR" and "must be below 1" in e[1] for e in log)
    log = draw_panel(bpy, "RELATIVITY_PT_observer", scene)
    assert any(e == ("label", "Gamma: undefined (speed >= c)", "NONE") for e in log)
    before = fingerprint(bpy)
    with pytest.raises(RuntimeError, match="must be below 1"):
        bpy.ops.relativity.setup_scene()
    assert fingerprint(bpy) == before

    scene.relativity.beta = (0.0, 0.0, -0.5)
    scene.render.engine = "BLENDER_WORKBENCH"
    bpy.context.view_layer.update()  # what the UI does after any change: the handlers sync
    assert not bpy.ops.relativity.setup_scene.poll()
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert any(e[0] == "label" and e[1].startswith("Render Engine is Workbench: ") and "Cycles" in e[1] for e in log)


def test_geometry_method_through_the_operators_and_object_panel(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.beta = (0.0, 0.0, -0.8)
    sphere.relativity.enabled = True
    log = draw_panel(bpy, "RELATIVITY_PT_object", scene, sphere)
    assert ("prop", "enabled") in log
    before = fingerprint(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert fingerprint(bpy) != before
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert fingerprint(bpy) == before


def test_coarse_mesh_warning_for_the_geometry_method(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy)
    import bmesh

    mesh = bpy.data.meshes.new("Wall")
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=2.0)  # one 4 x 4 quad
    bm.to_mesh(mesh)
    bm.free()
    wall = bpy.data.objects.new("Wall", mesh)
    wall.location = (0.0, 0.0, -4.0)
    scene.collection.objects.link(wall)
    bpy.context.view_layer.update()
    scene.relativity.method = "GEOMETRY"
    # Without Adaptive, the coarse-edge measure (adaptive tessellation measures edges in pixels at
    # each update: tests/blender/geometry/test_adaptive_tessellation.py)
    wall.relativity.use_adaptive_tessellation = False
    wall.relativity.tessellation = 1
    log = draw_panel(bpy, "RELATIVITY_PT_object", scene, wall)
    # The quad's four sides are 4 long; their midpoints are sqrt(2^2 + 4^2) from the camera:
    # 4 / sqrt(20) = 0.894, halved by one tessellation level: 0.447 > 0.25.
    warnings = [e[1] for e in log if e[0] == "label" and e[2] == "ERROR"]
    assert len(warnings) == 1 and "0.45x" in warnings[0], warnings
    wall.relativity.tessellation = 2  # 0.224: fine enough
    log = draw_panel(bpy, "RELATIVITY_PT_object", scene, wall)
    assert not [e for e in log if e[0] == "label" and e[2] == "ERROR"]
    wall.relativity.tessellation = 1
    scene.relativity.method = "CAMERA"  # the exact camera needs no tessellation
    log = draw_panel(bpy, "RELATIVITY_PT_object", scene, wall)
    assert not [e for e in log if e[0] == "label" and e[2] == "ERROR"]


def test_time_of_flight_says_what_it_leaves_out(relativity_addon, factory_blender):
    """Time of Flight Only: one line in the Effects panel on what it leaves out, one on where it applies,
    and with Apparent Geometry the one-line refusal in the main panel."""
    bpy = factory_blender
    scene, _, _ = wh.new_scene(bpy)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    log = draw_panel(bpy, "RELATIVITY_PT_effects", scene)
    assert ("prop", "use_time_of_flight") in log and not any("Light delay" in e[1] for e in log if e[0] == "label")
    scene.relativity.use_time_of_flight = True
    log = draw_panel(bpy, "RELATIVITY_PT_effects", scene)
    assert any(e[0] == "label" and "no contraction, searchlight or Doppler" in e[1] for e in log)
    scene.relativity.use_time_of_flight = False
    scene.relativity.method = "GEOMETRY"
    log = draw_panel(bpy, "RELATIVITY_PT_effects", scene)
    assert any(e[0] == "label" and "exact camera only" in e[1] for e in log)
    scene.relativity.use_time_of_flight = True
    bpy.context.view_layer.update()
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert any(
        e[0] == "label" and e[2] == "ERROR" and "Time of Flight Only is for the exact camera" in e[1] for e in log
    )


def test_every_shipped_preset_loads_and_gray_velocity_is_converted(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    camera.rotation_euler = (1.2, 0.1, -0.7)
    bpy.context.view_layer.update()
    settings = scene.relativity
    menus = {
        "speed": "RELATIVITY_MT_speed_presets",
        "speed_of_light": "RELATIVITY_MT_speed_of_light_presets",
        "shutter": "RELATIVITY_MT_shutter_presets",
        "paper_setups": "RELATIVITY_MT_paper_setups_presets",
    }
    found = {}
    for kind, menu in menus.items():
        directories = bpy.utils.preset_paths(f"relativity/{kind}")
        assert directories, kind
        files = sorted(f for d in directories for f in os.listdir(d) if f.endswith(".py"))
        found[kind] = files
        for name in files:
            path = next(os.path.join(d, name) for d in directories if os.path.isfile(os.path.join(d, name)))
            assert bpy.ops.script.execute_preset(filepath=path, menu_idname=menu) == {"FINISHED"}, name
    assert found["speed"] == ["0.5c.py", "0.8c.py", "0.999c.py", "0.99c.py", "0.9c.py"]
    assert len(found["shutter"]) == 6 and len(found["speed_of_light"]) == 3 and len(found["paper_setups"]) == 9

    rotation = np.array(camera.matrix_world.to_quaternion().to_matrix())

    def load(kind, name):
        directory = bpy.utils.preset_paths(f"relativity/{kind}")[0]
        bpy.ops.script.execute_preset(filepath=os.path.join(directory, name), menu_idname=menus[kind])

    # Gray et al.: (0.1, 0, 0.99) in Dr TIM (x right, y up, z into the page = viewing direction).
    # In the camera's own axes that is 0.1 * right + 0.99 * view, with view = local -Z.
    load("paper_setups", "Gray_2020_beta_0.1_0_0.99_camera.py")
    right, view = rotation[:, 0], -rotation[:, 2]
    np.testing.assert_allclose(tuple(settings.beta), 0.1 * right + 0.99 * view, atol=1e-6)
    # Fig. 1(c): the same velocity, time of flight only; the next paper set-up switches it off again
    load("paper_setups", "Gray_2020_Fig_1c_time_of_flight.py")
    np.testing.assert_allclose(tuple(settings.beta), 0.1 * right + 0.99 * view, atol=1e-6)
    assert settings.use_time_of_flight and settings.shutter_model == "PINHOLE"
    # Fig. 9: the shutter plane is the plane of spatial fixed points for t_S (docs/physics.md eq. 6:
    # -beta.x = ((gamma + 1) / gamma) c t_S), written in camera-local axes (beta.x is invariant).
    load("paper_setups", "Gray_2020_Fig_9_Lorentz_window.py")
    beta_local = rotation.T @ np.array(settings.beta)
    gamma = 1.0 / math.sqrt(1.0 - beta_local @ beta_local)
    point = np.array(settings.shutter_plane_point)
    expected = (gamma + 1) / gamma * settings.speed_of_light * settings.shutter_time
    assert -beta_local @ point == pytest.approx(expected, abs=2e-3)
    normal = np.array(settings.shutter_plane_normal)
    np.testing.assert_allclose(normal / np.linalg.norm(normal), beta_local / np.linalg.norm(beta_local), atol=1e-6)
    assert settings.use_lorentz_window and settings.shutter_model == "ARBITRARY_PLANE"
    assert settings.lorentz_window_shutter == "WINDOW_PLANE"
    # Fig. 10: the window stays in that plane (the plane of fixed points for t_W = -1), the
    # detector-plane shutter times the rays; its shutter time gives the axial chief ray Fig. 9's
    # lens time (Gray's caption), checked with the physics core's lens times.
    fig9_lens_time = lens_time(
        "ARBITRARY_PLANE",
        np.zeros(3),
        np.array([0.0, 0.0, -1e3]),
        c=1.0,
        shutter_time=settings.shutter_time,
        plane_point=point,
        plane_normal=normal,
    )
    load("paper_setups", "Gray_2020_Fig_10_Lorentz_window_detector_plane.py")
    assert settings.use_lorentz_window and settings.lorentz_window_shutter == "SHUTTER_MODEL"
    assert settings.lorentz_window_time == -1.0 and settings.shutter_model == "DETECTOR_PLANE"
    assert settings.imaging_element == "IDEAL_LENS"
    data = camera.data
    focus = data.dof.focus_distance if data.dof.use_dof else math.inf
    image_distance = 1.0 / (1.0 / (data.lens * 1e-3) - 1.0 / focus)
    fig10_lens_time = lens_time(
        "DETECTOR_PLANE",
        np.zeros(3),
        np.array([0.0, 0.0, -1e3]),
        c=1.0,
        shutter_time=settings.shutter_time,
        detector_point=np.array([0.0, 0.0, image_distance]),
    )
    assert fig10_lens_time == pytest.approx(fig9_lens_time, abs=1e-6)
    # The shutter panel shows the lens for the detector plane and the window's settings.
    shown = [entry[1] for entry in draw_panel(bpy, "RELATIVITY_PT_shutter", scene) if entry[0] == "prop"]
    assert shown == [
        "shutter_model",
        "shutter_time",
        "imaging_element",
        "use_lorentz_window",
        "lorentz_window_shutter",
        "lorentz_window_time",
    ]
    assert not settings.use_time_of_flight
    # Fig. 11: the same with Blender's stereo pair, eyes 0.4 apart converging at 5, as an anaglyph.
    load("paper_setups", "Gray_2020_Fig_11_stereo_Lorentz_window.py")
    np.testing.assert_allclose(beta_local, rotation.T @ np.array(settings.beta), atol=1e-6)
    stereo = camera.data.stereo
    assert (stereo.convergence_mode, stereo.interocular_distance, stereo.convergence_distance) == (
        "OFFAXIS",
        pytest.approx(0.4),
        pytest.approx(5.0),
    )
    assert scene.render.use_multiview and scene.render.views_format == "STEREO_3D"
    assert scene.render.image_settings.stereo_3d_format.display_mode == "ANAGLYPH"

    load("paper_setups", "Weiskopf_1999_Fig_8_Sun_0.5c_Doppler.py")
    np.testing.assert_allclose(tuple(settings.beta), 0.5 * right, atol=1e-6)
    assert settings.use_doppler and not settings.use_searchlight
    load("paper_setups", "Weiskopf_1999_Fig_7_street_0.8c_searchlight.py")
    np.testing.assert_allclose(tuple(settings.beta), 0.8 * view, atol=1e-6)
    assert settings.use_searchlight and not settings.use_doppler

    scene.unit_settings.scale_length = 0.01  # centimetres: c in scene units per second
    load("speed_of_light", "Real_299792458_m_per_s.py")
    assert settings.speed_of_light == pytest.approx(29979245800.0)
    # Speed presets keep the direction of the current velocity.
    load("speed", "0.99c.py")
    np.testing.assert_allclose(tuple(settings.beta), 0.99 * view, atol=1e-6)


def test_user_preset_saved_and_loaded(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, _, _ = wh.new_scene(bpy)
    settings = scene.relativity
    settings.shutter_model = "FOCUS_SURFACE"
    settings.shutter_time = -0.25
    assert bpy.ops.relativity.shutter_preset_add(name="My Shutter") == {"FINISHED"}
    settings.shutter_model = "PINHOLE"
    settings.shutter_time = 0.0
    user_folder = bpy.utils.user_resource("SCRIPTS", path="presets/relativity/shutter")
    assert user_folder.startswith(os.environ["BLENDER_USER_RESOURCES"])
    saved = [name for name in os.listdir(user_folder) if name.lower().startswith("my")]
    assert len(saved) == 1, os.listdir(user_folder)
    path = os.path.join(user_folder, saved[0])
    bpy.ops.script.execute_preset(filepath=path, menu_idname="RELATIVITY_MT_shutter_presets")
    assert settings.shutter_model == "FOCUS_SURFACE" and settings.shutter_time == -0.25
    os.remove(path)


def test_clamping_follows_the_searchlight(relativity_addon, factory_blender):
    """Cycles clamps samples after the camera's D^4: while applied, each clamp is the user's times
    the brightest D^4, (gamma (1 + beta))^4 = 3^4 at 0.8c; a value typed meanwhile is the user's;
    removing the effect gives the user's values back."""
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy)
    scene.relativity.beta = (0.0, 0.0, -0.8)
    scene.cycles.sample_clamp_indirect = 10.0
    scene.cycles.sample_clamp_direct = 0.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert scene.cycles.sample_clamp_indirect == pytest.approx(810.0, rel=1e-5)
    assert scene.cycles.sample_clamp_direct == 0.0
    scene.cycles.sample_clamp_direct = 2.0  # typed in the panel while applied
    scene.frame_set(scene.frame_current)  # the depsgraph update the UI would send
    assert scene.cycles.sample_clamp_direct == pytest.approx(162.0, rel=1e-5)
    scene.relativity.beta = (0.0, 0.0, 0.0)
    assert scene.cycles.sample_clamp_indirect == pytest.approx(10.0, rel=1e-5)
    scene.relativity.beta = (0.0, 0.0, -0.8)
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert (scene.cycles.sample_clamp_direct, scene.cycles.sample_clamp_indirect) == (2.0, 10.0)


def test_clamping_follows_moving_objects(relativity_addon, factory_blender):
    """Apparent Geometry, camera at rest, a mesh keyframed at 0.5c (linear keys): each clamp is the
    user's times ``(gamma (1 + beta))^6`` = 27 (eq. 18's D^2 on a lamp's light, then the object's
    D^4); at Constant Velocity 0.6c, 64; nothing moving: the user's."""
    bpy = factory_blender
    scene, camera, sphere = wh.new_scene(bpy)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.cycles.sample_clamp_indirect = 10.0
    scene.frame_start, scene.frame_end = 1, 24
    fps = scene.render.fps / scene.render.fps_base
    speed = 0.5 * scene.relativity.speed_of_light  # units per second
    for frame in (1, 24):
        sphere.location = (speed * (frame - 1) / fps, 0.0, -5.0)
        sphere.keyframe_insert("location", index=0, frame=frame)
    for fcurve in compat.action_fcurves(sphere.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    sphere.relativity.enabled = True
    sphere.relativity.motion = "ANIMATION"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert scene.cycles.sample_clamp_indirect == pytest.approx(270.0, rel=1e-3)
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = (0.6, 0.0, 0.0)
    scene.frame_set(scene.frame_current)
    assert scene.cycles.sample_clamp_indirect == pytest.approx(640.0, rel=1e-3)
    sphere.relativity.motion = "STATIC"
    scene.frame_set(scene.frame_current)
    assert scene.cycles.sample_clamp_indirect == pytest.approx(10.0, rel=1e-5)
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert scene.cycles.sample_clamp_indirect == 10.0
