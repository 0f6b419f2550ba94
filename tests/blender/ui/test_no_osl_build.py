"""A Blender build without OSL (Debian's 5.2, issue 25): what the user is told, and where.

The wheel here has OSL; the tests give Blender the answer of such a build the way Debian's does:
``_cycles.with_osl`` False and no ``oslquery`` module. The panel must say before Set Up that this
build has no OSL and what the final render will be; Set Up refuses the exact camera in one line
that names no module; an Apparent Geometry F12 renders the boosted-mesh preview (the same pixels
as Final Render: Boosted Meshes) and says so; switching the Method after Set Up says why in the
panel and in a popup; moving lights are rendered at rest with a warning saying why. Long warnings
are wrapped to the sidebar's width, not cut.
"""

import importlib
import sys

import numpy as np
import pytest
from test_ui_workflow import RecordingLayout, fingerprint

import pipeline_helpers as wh

INTERNAL = ("oslquery", "_cycles", "with_osl", "OSLUnavailableError")


@pytest.fixture
def no_osl(monkeypatch):
    """Blender as a build without OSL: what ``cycles.engine.with_osl()`` reads, and no oslquery."""
    import _cycles

    monkeypatch.setattr(_cycles, "with_osl", False)
    monkeypatch.setitem(sys.modules, "oslquery", None)  # ``import oslquery`` raises ImportError


def _module(bpy, name):
    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.{name}")


class Region:
    def __init__(self, width):
        self.width = width


class Context:
    def __init__(self, bpy, scene, obj=None, width=None):
        self.scene, self.object = scene, obj
        self.region = Region(width) if width is not None else None
        self.preferences = bpy.context.preferences


def _errors(bpy, scene, idname="RELATIVITY_PT_main", obj=None, width=None):
    """The ERROR messages a panel draws, each a message whole (wrapped lines joined)."""
    log = []
    context = Context(bpy, scene, obj, width)
    getattr(bpy.types, idname).draw(type("PanelShim", (), {"layout": RecordingLayout(bpy, log)})(), context)
    messages = []
    for entry in log:
        if entry[0] == "label" and entry[2] == "ERROR":
            messages.append(entry[1])
        elif entry[0] == "label" and entry[2] == "BLANK1" and messages:
            messages[-1] += " " + entry[1]
    return messages, log


def _drain(notice):
    """The popups queued for the main thread (taken off the queue)."""
    queued = []
    while not notice._pending.empty():
        queued.append(notice._pending.get_nowait())
    return queued


def _assert_user_facing(message):
    assert message[:1].isupper(), message
    for name in INTERNAL:
        assert name not in message, message


def _geometry_scene(bpy, final_render="EXACT"):
    scene, camera, sphere = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.geometry_final_render = final_render
    scene.relativity.beta = (0.0, 0.0, -0.6)
    sphere.relativity.enabled = True
    bpy.context.view_layer.update()
    return scene, camera, sphere


def test_osl_is_decided_in_one_place(relativity_addon, factory_blender, monkeypatch):
    """The wheel has OSL; without ``_cycles.with_osl`` or without oslquery the reason is one line
    for the user, naming neither."""
    osl = _module(factory_blender, "common.osl")
    assert osl.unavailable_reason() is None
    import _cycles

    monkeypatch.setitem(sys.modules, "oslquery", None)
    without_compiler = osl.unavailable_reason()
    monkeypatch.setattr(_cycles, "with_osl", False)
    without_osl = osl.unavailable_reason()
    for reason in (without_compiler, without_osl):
        assert reason is not None and "OSL" in reason
        _assert_user_facing(reason)
    assert "no OSL" in without_osl


def test_exact_camera_refused_in_one_line_and_said_before_set_up(relativity_addon, factory_blender, no_osl):
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    scene.relativity.beta = (0.0, 0.0, -0.6)
    bpy.context.view_layer.update()
    messages, _ = _errors(bpy, scene)
    said = [m for m in messages if "has no OSL" in m]
    assert said and "Apparent Geometry" in said[0], messages
    _assert_user_facing(said[0])
    before = fingerprint(bpy)
    with pytest.raises(RuntimeError) as refused:
        bpy.ops.relativity.setup_scene()
    line = str(refused.value).strip().splitlines()[-1].split(": ", 1)[-1]
    assert "has no OSL" in line and "Exact Camera" in line, line
    _assert_user_facing(line)
    assert fingerprint(bpy) == before
    assert camera.data.type == "PERSP"


def test_no_osl_is_said_first_whatever_else_the_exact_camera_refuses(relativity_addon, factory_blender, no_osl):
    """A moving object refuses the exact camera too; without OSL the first reason given is the
    build (changing the object would not help). Found in Debian's Blender (tests/gui/)."""
    bpy = factory_blender
    scene, _, sphere = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = (0.3, 0.0, 0.0)
    bpy.context.view_layer.update()
    messages, _ = _errors(bpy, scene)
    assert messages and "has no OSL" in messages[0] and "Apparent Geometry" in messages[0], messages
    with pytest.raises(RuntimeError) as refused:
        bpy.ops.relativity.setup_scene()
    assert "has no OSL" in str(refused.value), refused.value


def test_geometry_final_render_is_the_preview_and_says_so(
    relativity_addon, factory_blender, no_osl, capfd, tmp_path, monkeypatch
):
    """Final Render: Exact Camera without OSL: the panel says so before Set Up, Set Up warns, F12
    renders exactly what Final Render: Boosted Meshes renders, and a popup (with a window) says so."""
    bpy = factory_blender
    notice = _module(bpy, "pipeline.render_notice")
    scene, camera, _ = _geometry_scene(bpy)
    messages, _ = _errors(bpy, scene)
    said = [m for m in messages if "has no OSL" in m]
    assert said and "boosted-mesh preview" in said[0], messages
    capfd.readouterr()
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    out, err = capfd.readouterr()
    warned = [line for line in (out + err).splitlines() if "has no OSL" in line]
    assert warned and "boosted-mesh preview" in warned[0], out + err

    monkeypatch.setattr(notice, "_background", lambda: False)
    _drain(notice)
    scene.render.filepath = str(tmp_path / "exact.png")
    scene.render.image_settings.file_format = "PNG"
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    queued = _drain(notice)
    assert camera.data.type == "PERSP"
    titles = [reason for title, reason in queued if "boosted-mesh preview" in title]
    assert titles and "has no OSL" in titles[0], queued
    _assert_user_facing(titles[0])
    messages, _ = _errors(bpy, scene)
    assert any("has no OSL" in m for m in messages), messages

    scene.relativity.geometry_final_render = "PREVIEW"
    scene.render.filepath = str(tmp_path / "preview.png")
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    exact, preview = (wh.read_image(bpy, tmp_path / f"{name}.png") for name in ("exact", "preview"))
    assert np.isfinite(exact).all() and exact.max() > 0.1
    np.testing.assert_array_equal(exact, preview)


def test_switching_method_after_set_up_says_why(relativity_addon, factory_blender, no_osl, monkeypatch):
    bpy = factory_blender
    effect = _module(bpy, "pipeline.effect")
    notice = _module(bpy, "pipeline.render_notice")
    monkeypatch.setattr(notice, "_background", lambda: False)
    scene, _, _ = _geometry_scene(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    _drain(notice)
    scene.relativity.method = "CAMERA"
    bpy.context.view_layer.update()  # the handlers sync after every change
    assert effect.applied_method(scene) == "GEOMETRY"  # not taken away without a word
    popups = _drain(notice)
    assert popups and "has no OSL" in popups[0][1], popups
    _assert_user_facing(popups[0][1])
    messages, _ = _errors(bpy, scene)
    said = [m for m in messages if "Apparent Geometry" in m and "has no OSL" in m]
    assert said, messages
    scene.relativity.method = "GEOMETRY"  # back: the refused switch is no longer news (seen in Debian's Blender)
    bpy.context.view_layer.update()
    messages, _ = _errors(bpy, scene)
    assert not any(m.startswith("Still set up") for m in messages), messages


def _moving_light(bpy, scene):
    data = bpy.data.lights.new("Lamp", "POINT")
    data.energy = 100.0
    light = bpy.data.objects.new("Lamp", data)
    light.location = (0.0, 2.0, -4.0)
    scene.collection.objects.link(light)
    light.relativity.motion = "CONSTANT"
    light.relativity.beta = (0.3, 0.0, 0.0)
    bpy.context.view_layer.update()
    return light


def test_moving_light_without_osl_is_at_rest_and_says_why(relativity_addon, factory_blender, no_osl):
    bpy = factory_blender
    scene, _, _ = _geometry_scene(bpy)
    _moving_light(bpy, scene)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    messages, _ = _errors(bpy, scene)
    at_rest = [m for m in messages if "'Lamp'" in m]
    assert at_rest and "at rest" in at_rest[0] and "has no OSL" in at_rest[0], messages
    assert not any("final render is exact" in m for m in messages), messages
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}


def test_moving_light_warning_promises_no_exact_final_render(relativity_addon, factory_blender):
    """With OSL but Final Render: Boosted Meshes the final render is the preview: the warning
    must not promise an exact one (it does with Final Render: Exact Camera)."""
    bpy = factory_blender
    scene, _, _ = _geometry_scene(bpy, final_render="PREVIEW")
    _moving_light(bpy, scene)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    messages, _ = _errors(bpy, scene)
    lights = [m for m in messages if m.startswith("Moving lights with a moving observer")]
    assert lights and "final render is exact" not in lights[0] and "Boosted Meshes" in lights[0], messages
    scene.relativity.geometry_final_render = "EXACT"
    messages, _ = _errors(bpy, scene)
    assert any("final render is exact" in m for m in messages), messages
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}


@pytest.mark.parametrize("width", [180, 320, 600])
def test_long_warnings_are_wrapped_whole(relativity_addon, factory_blender, width):
    """At any sidebar width every line fits (measured with Blender's UI font at the UI's text
    size, 11 points, leaving room for the icon) and the lines together are the whole warning."""
    import blf

    bpy = factory_blender
    scene, _, _ = _geometry_scene(bpy)
    _moving_light(bpy, scene)
    effect = _module(bpy, "pipeline.effect")
    warnings = effect.scene_warnings(scene)
    blf.size(0, 11 * (bpy.context.preferences.system.ui_scale or 1.0))
    room = width - 40  # the icon and the panel's margins
    longest = max(warnings, key=lambda text: blf.dimensions(0, text)[0])
    assert blf.dimensions(0, longest)[0] > room  # a warning one label would cut
    messages, log = _errors(bpy, scene, width=width)
    assert longest in messages
    lines = [entry[1] for entry in log if entry[0] == "label" and entry[2] in ("ERROR", "BLANK1")]
    assert len(lines) > len(messages)
    for line in lines:
        assert blf.dimensions(0, line)[0] <= room, (width, line)


def test_switching_method_that_removes_the_effect_says_so(relativity_addon, factory_blender, monkeypatch):
    """With OSL: Apparent Geometry set up, then Method Exact Camera with an orthographic camera,
    which the exact camera cannot replace: the effect is gone, and the panel and a popup say so
    (an update callback has no operator report)."""
    bpy = factory_blender
    effect = _module(bpy, "pipeline.effect")
    notice = _module(bpy, "pipeline.render_notice")
    monkeypatch.setattr(notice, "_background", lambda: False)
    scene, camera, _ = _geometry_scene(bpy)
    camera.data.type = "ORTHO"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    _drain(notice)
    scene.relativity.method = "CAMERA"
    bpy.context.view_layer.update()
    assert effect.applied_method(scene) is None
    popups = [reason for _, reason in _drain(notice)]
    assert popups and "removed" in popups[0] and "Orthographic" in popups[0], popups
    _assert_user_facing(popups[0])
    messages, _ = _errors(bpy, scene)
    assert popups[0] in messages, messages
    assert bpy.ops.relativity.setup_scene.poll()
    scene.relativity.method = "GEOMETRY"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    messages, _ = _errors(bpy, scene)
    assert not any("removed" in m for m in messages), messages
