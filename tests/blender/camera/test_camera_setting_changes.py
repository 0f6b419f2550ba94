"""Camera and engine settings changed after Set Up on the exact camera (issue 25).

The exact camera is a Custom (OSL) camera rendered by Cycles. Switching the camera's Type (to
Orthographic, say) or the Render Engine (to EEVEE) after Set Up renders without it: an ordinary
picture with the materials' Doppler colour, not a relativistic one. Both are refused in one line
naming the setting, in the panel at once (sync) and for F12 (the last render's refusal, and a popup
titled as what the picture is); Remove gives back what the add-on changed and keeps the user's Type.
"""

import importlib

import pytest
from test_ui_workflow import draw_panel

import pipeline_helpers as wh
from relativity_addon.blender.common import compat


def _module(bpy, name):
    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.{name}")


def _set_up(bpy):
    scene, camera, _ = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert camera.data.type == "CUSTOM"
    return scene, camera


def _panel_errors(bpy, scene):
    return [e[1] for e in draw_panel(bpy, "RELATIVITY_PT_main", scene) if e[0] == "label" and e[2] == "ERROR"]


def _f12_refusal(bpy, scene, monkeypatch):
    """F12 as with a window: the recorded refusal and the popups' titles."""
    notice = _module(bpy, "pipeline.render_notice")
    shown = []
    monkeypatch.setattr(notice, "_background", lambda: False)
    monkeypatch.setattr(notice, "_popup", lambda title, reason: shown.append(title))
    assert bpy.ops.render.render() == {"FINISHED"}
    notice.show_pending()
    return notice.last_refusal(scene), shown


def test_orthographic_after_set_up_is_refused_and_kept_by_remove(relativity_addon, factory_blender, monkeypatch):
    bpy = factory_blender
    scene, camera = _set_up(bpy)
    camera.data.type = "ORTHO"
    bpy.context.view_layer.update()  # the UI's depsgraph update: the handlers sync
    expected = "Camera 'Camera': Type was changed to Orthographic after Set Up"
    assert any(line.startswith(expected) for line in _panel_errors(bpy, scene)), _panel_errors(bpy, scene)

    refusal, titles = _f12_refusal(bpy, scene, monkeypatch)
    assert refusal is not None and refusal.startswith(expected), refusal
    assert titles == ["Relativity: this render is not relativistic"]  # not black: Cycles' own camera
    assert any(line.startswith(f"Last render refused: {expected}") for line in _panel_errors(bpy, scene))

    effect = _module(bpy, "pipeline.effect")
    with pytest.raises(effect.RelativityError, match=expected):  # Set Up again keeps the user's Type too
        effect.apply(scene)
    assert camera.data.type == "ORTHO"

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    data = camera.data
    assert data.type == "ORTHO"  # the user's change after Set Up stays
    assert data.custom_shader is None and not data.custom_bytecode
    assert len(data.cycles_custom.keys()) == 0
    assert _module(bpy, "common.names").CAMERA_SAVED_STATE_KEY not in data


def test_custom_again_renders_again(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera = _set_up(bpy)
    camera.data.type = "PERSP"
    bpy.context.view_layer.update()
    assert any("Type was changed to Perspective" in line for line in _panel_errors(bpy, scene))
    camera.data.type = "CUSTOM"
    bpy.context.view_layer.update()
    assert not _panel_errors(bpy, scene)
    assert camera.data.cycles_custom["settings_valid"]
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert camera.data.type == "PERSP"


def test_eevee_after_set_up_is_refused_at_f12(relativity_addon, factory_blender, monkeypatch):
    bpy = factory_blender
    scene, camera = _set_up(bpy)
    scene.render.engine = compat.eevee_engine()
    expected = "Render Engine is EEVEE: the exact camera renders with Cycles only"
    refusal, titles = _f12_refusal(bpy, scene, monkeypatch)
    assert refusal is not None and refusal.startswith(expected), refusal
    assert titles == ["Relativity: this render is not relativistic"]
    assert any(line.startswith(f"Last render refused: {expected}") for line in _panel_errors(bpy, scene))

    scene.render.engine = "CYCLES"
    assert bpy.ops.render.render() == {"FINISHED"}
    assert _module(bpy, "pipeline.render_notice").last_refusal(scene) is None
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert camera.data.type == "PERSP"
