"""Every label the panels draw fits the sidebar, so Blender never cuts one in the middle.

In Debian's Blender in a real window (tests/gui/) the sidebar opens 292 px wide at UI scale 1, and
labels longer than that were drawn cut in the middle ("The viewport sho...ed-mesh preview",
"Animated lights: e...parent Geometry)"); with the camera's animation as velocity and a refused
sync the Observer panel said "Speed: nan c" and "Gamma: undefined (speed >= c)". Each label is
measured here with Blender's UI font at the UI's text size (11 points), leaving room for the icon
and the panel's margins, as ``test_no_osl_build.test_long_warnings_are_wrapped_whole`` does.
"""

import pytest
from test_no_osl_build import Context, _geometry_scene, _moving_light
from test_ui_workflow import RecordingLayout

import pipeline_helpers as wh

SIDEBAR = 292  # the 3D view sidebar's width when it opens (Debian's Blender 5.2 under Xvfb, UI scale 1)
PANELS = ("RELATIVITY_PT_main", "RELATIVITY_PT_observer", "RELATIVITY_PT_shutter", "RELATIVITY_PT_effects")


def _labels(bpy, scene, obj, width):
    log = []
    context = Context(bpy, scene, obj, width)
    for idname in (*PANELS, "RELATIVITY_PT_object"):
        getattr(bpy.types, idname).draw(type("PanelShim", (), {"layout": RecordingLayout(bpy, log)})(), context)
    return [entry[1] for entry in log if entry[0] == "label"]


def _too_long(bpy, labels, width):
    import blf

    blf.size(0, 11 * (bpy.context.preferences.system.ui_scale or 1.0))
    room = width - 50  # the icon, the panel's margins and a box's
    return [text for text in labels if blf.dimensions(0, text)[0] > room]


def _states(bpy):
    """(name, scene, active object) in the states whose panels draw the longest texts."""
    scene, camera, sphere = _geometry_scene(bpy)
    yield "geometry", scene, sphere
    light = _moving_light(bpy, scene)
    light.data.type = "SUN"
    yield "moving sun, Apparent Geometry", scene, light
    light.relativity.motion = "ANIMATION"
    yield "animated sun", scene, light
    scene.relativity.use_time_of_flight = True
    yield "time of flight", scene, sphere
    scene.relativity.use_time_of_flight = False
    empty = bpy.data.objects.new("Empty", None)
    scene.collection.objects.link(empty)
    yield "empty", scene, empty
    scene.relativity.method = "CAMERA"
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    scene.relativity.shutter_model = "ARBITRARY_PLANE"
    scene.relativity.use_chang_searchlight = True
    bpy.context.view_layer.update()
    yield "exact camera, camera animation", scene, sphere


@pytest.mark.parametrize("width", [SIDEBAR])
def test_every_label_fits_the_sidebar(relativity_addon, factory_blender, width):
    bpy = factory_blender
    cut = {}
    for name, scene, obj in _states(bpy):
        too_long = _too_long(bpy, _labels(bpy, scene, obj, width), width)
        if too_long:
            cut[name] = too_long
    assert not cut, cut


def test_unknown_speed_is_not_called_faster_than_light(relativity_addon, factory_blender):
    """Velocity from the camera's animation while the scene's check is refused: no speed was read,
    and the panel says so instead of 'nan c' and 'speed >= c'."""
    bpy = factory_blender
    scene, _, sphere = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    sphere.relativity.motion = "CONSTANT"  # refused on the exact camera: the check stops there
    sphere.relativity.beta = (0.3, 0.0, 0.0)
    bpy.context.view_layer.update()
    labels = _labels(bpy, scene, sphere, None)
    speed = [text for text in labels if text.startswith(("Speed", "Gamma"))]
    assert speed, labels
    for text in speed:
        assert "nan" not in text and ">= c" not in text, speed
