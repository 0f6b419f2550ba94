"""Temperatures that are not numbers (issue 25): a NaN Blackbody Temperature on an object, a NaN
light Temperature or a NaN *Lit By: Blackbody* Temperature is refused in one line naming the
object and the setting, at Set Up and at F12 after Set Up, on both render paths; the F12 image has
no NaN or huge pixel. Infinity (stored as the largest float), negative values (clamped to 0) and 0
(not an emitter) are numbers: they render finite pixels."""

import math

import numpy as np
import pytest

import camera_helpers as ch
import pipeline_helpers as wh

NAN = float("nan")


def _notice(bpy):
    import importlib

    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.pipeline.render_notice")


def _scene(bpy, method):
    scene, _, sphere = wh.new_scene(bpy, resolution=(32, 24), samples=1)
    sphere.location = (0.0, 0.0, -5.0)
    sphere.relativity.temperature = 3000.0
    settings = scene.relativity
    settings.beta = (0.0, 0.0, -0.5)
    settings.method = method
    if method == "GEOMETRY":
        sphere.relativity.enabled = True
    bpy.context.view_layer.update()
    return scene, sphere


def _f12(bpy, scene, path):
    pixels = ch.render_exr(bpy, scene, path)
    assert np.all(np.isfinite(pixels)), "NaN or infinite pixel"
    return pixels


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
def test_nan_object_temperature_refused_at_set_up_and_at_f12(relativity_addon, factory_blender, tmp_path, method):
    bpy = factory_blender
    scene, sphere = _scene(bpy, method)
    sphere.relativity.temperature = NAN
    with pytest.raises(RuntimeError, match=r"Object 'Marker': Blackbody Temperature is nan K"):
        bpy.ops.relativity.setup_scene()

    sphere.relativity.temperature = 3000.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    valid = _f12(bpy, scene, tmp_path / "valid.exr")
    assert valid.max() > 0.05  # the sphere is seen

    sphere.relativity.temperature = NAN  # after Set Up: refused at sync, then F12
    pixels = _f12(bpy, scene, tmp_path / "nan.exr")
    refusal = _notice(bpy).last_refusal(scene)
    assert refusal is not None and "Object 'Marker': Blackbody Temperature is nan K" in refusal, refusal
    # the exact camera renders black; Apparent Geometry its last valid state (3000 K)
    assert pixels.max() <= (1e-6 if method == "CAMERA" else 1.01 * valid.max()), pixels.max()

    sphere.relativity.temperature = 3000.0
    _f12(bpy, scene, tmp_path / "again.exr")
    assert _notice(bpy).last_refusal(scene) is None
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}


def test_nan_lit_by_blackbody_and_light_temperature_refused(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, _ = _scene(bpy, "CAMERA")
    light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    scene.collection.objects.link(light)
    settings = scene.relativity
    settings.fast_illuminant = "BLACKBODY"
    settings.fast_illuminant_temperature = NAN
    with pytest.raises(RuntimeError, match=r"Lit By: Blackbody: Temperature is nan K"):
        bpy.ops.relativity.setup_scene()
    settings.fast_illuminant_temperature = 5000.0
    light.data.use_temperature = True
    light.data.temperature = NAN
    with pytest.raises(RuntimeError, match=r"Light 'Lamp': Temperature is nan K"):
        bpy.ops.relativity.setup_scene()
    light.data.temperature = 4000.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    settings.fast_illuminant_temperature = NAN
    _f12(bpy, scene, tmp_path / "nan.exr")
    assert "Lit By: Blackbody: Temperature is nan K" in _notice(bpy).last_refusal(scene)


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
@pytest.mark.parametrize("value", [math.inf, -50.0, 0.0])
def test_numbers_render_finite_pixels(relativity_addon, factory_blender, tmp_path, method, value):
    bpy = factory_blender
    scene, sphere = _scene(bpy, method)
    sphere.relativity.temperature = value
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    pixels = _f12(bpy, scene, tmp_path / "f.exr")
    assert _notice(bpy).last_refusal(scene) is None
    assert 0.0 < pixels.max() < 1e3, pixels.max()


def test_nan_blackbody_node_refused_naming_the_object(relativity_addon, factory_blender, tmp_path):
    """A material's Blackbody node at NaN makes its lamp's light group on the exact camera: the
    refusal names the object and the setting, not the colour table."""
    bpy = factory_blender
    scene, sphere = _scene(bpy, "CAMERA")
    sphere.relativity.temperature = 0.0
    tree = sphere.active_material.node_tree
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = 3000.0
    tree.links.new(blackbody.outputs[0], tree.nodes["Emission"].inputs["Color"])
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    blackbody.inputs["Temperature"].default_value = NAN
    pixels = _f12(bpy, scene, tmp_path / "nan.exr")
    refusal = _notice(bpy).last_refusal(scene)
    assert refusal is not None and "Object 'Marker': a Blackbody node's Temperature is nan K" in refusal, refusal
    assert pixels.max() <= 1e-6  # black
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    with pytest.raises(RuntimeError, match=r"Object 'Marker': a Blackbody node's Temperature is nan K"):
        bpy.ops.relativity.setup_scene()
