"""Clear errors instead of wrong physics; apply/remove restores the camera exactly."""

import math

import pytest

import camera_helpers as ch


@pytest.fixture
def addon(factory_blender):
    """The add-on registered from this source tree (in-process, for glue-level tests)."""
    import relativity_addon
    from relativity_addon.blender.pipeline import effect

    relativity_addon.register()
    yield effect
    relativity_addon.unregister()


def _scene(bpy):
    scene, camera_object = ch.new_scene(bpy, resolution=(64, 48), samples=1)
    ch.add_sphere(bpy, scene, (0.0, 0.0, -5.0), 0.5, ch.emission_material(bpy))
    return scene, camera_object


def test_apply_then_remove_restores_camera(addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    data = camera_object.data
    scene.relativity.beta = (0.3, 0.0, -0.4)
    addon.apply(scene)
    assert data.type == "CUSTOM" and data.custom_mode == "INTERNAL"
    assert data.custom_shader.name == addon.exact_camera.names.SHADER_TEXT
    assert data.custom_bytecode
    assert set(addon.exact_camera.REQUIRED_PARAMETERS) <= set(data.cycles_custom.keys())
    # World beta (0.3, 0, -0.4) with an unrotated camera: shader axes are (x, y, -z).
    assert tuple(data.cycles_custom["beta"]) == pytest.approx((0.3, 0.0, 0.4))

    # Settings changes re-sync the camera through the property update callbacks.
    scene.relativity.beta = (0.0, 0.5, 0.0)
    assert tuple(data.cycles_custom["beta"]) == pytest.approx((0.0, 0.5, 0.0))
    scene.relativity.shutter_model = "DETECTOR_PLANE"
    assert data.cycles_custom["shutter_model"] == 2
    # An invalid setting makes the shader refuse to render (black), never render wrong physics.
    scene.relativity.beta = (0.0, 1.2, 0.0)
    assert not data.cycles_custom["settings_valid"]
    scene.relativity.beta = (0.0, 0.5, 0.0)
    assert data.cycles_custom["settings_valid"]

    assert addon.remove(scene)
    assert data.type == "PERSP"
    assert data.custom_shader is None
    assert addon.exact_camera.names.CAMERA_SAVED_STATE_KEY not in data
    assert len(data.cycles_custom.keys()) == 0
    assert addon.exact_camera.names.SHADER_TEXT not in bpy.data.texts


@pytest.mark.parametrize(
    "beta, message",
    [((0.6, 0.8, 0.0), "below 1"), ((0.0, 0.0, -1.5), "below 1"), ((math.nan, 0.0, 0.0), "finite")],
)
def test_bad_velocity_is_refused(addon, factory_blender, beta, message):
    scene, camera_object = _scene(factory_blender)
    scene.relativity.beta = beta
    with pytest.raises(addon.RelativityError, match=message):
        addon.apply(scene)
    assert camera_object.data.type == "PERSP"


def test_wrong_engine_camera_type_and_method_are_refused(addon, factory_blender):
    scene, camera_object = _scene(factory_blender)
    scene.render.engine = "BLENDER_WORKBENCH"
    with pytest.raises(addon.RelativityError, match="Cycles"):
        addon.apply(scene)
    scene.render.engine = "CYCLES"
    camera_object.data.type = "ORTHO"
    with pytest.raises(addon.RelativityError, match="perspective"):
        addon.apply(scene)
    camera_object.data.type = "PERSP"


@pytest.mark.parametrize(
    "source",
    [
        "shader relativistic_camera(output point position = 0) { this is not OSL }",
        # Compiles, but is not our shader: no parameters would reach it.
        "shader relativistic_camera(output point position = 0, output vector direction = 0,"
        " output color throughput = 1) { direction = vector(0, 0, 1); }",
    ],
    ids=["syntax-error", "empty-shader"],
)
def test_compile_failure_or_empty_shader_is_detected(addon, factory_blender, monkeypatch, source):
    scene, camera_object = _scene(factory_blender)
    monkeypatch.setattr(addon.exact_camera, "shader_source", lambda: source)
    with pytest.raises(addon.RelativityError, match="compile|empty shader"):
        addon.apply(scene)
    # The failed attempt leaves the camera as it was.
    assert camera_object.data.type == "PERSP"
    assert addon.exact_camera.names.CAMERA_SAVED_STATE_KEY not in camera_object.data


def test_render_script_fails_with_one_line_reasons(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    blend = ch.save_blend(bpy, tmp_path / "scene.blend")
    out = tmp_path / "out.png"
    cases = {
        "--beta=0,0,-1.0": "below 1",
        "--beta=nan,0,0": "finite",
        "--beta=0,0": "X,Y,Z",
        "--samples=zero": "integer",
        "--method=sideways": "invalid choice",  # (geometry is a method now: tests/blender/geometry)
        "--resolution=0x10": "positive",
        "--shutter=sideways": "invalid choice",
    }
    for option, reason in cases.items():
        result = ch.run_render_script(blend, out, option, check=False)
        assert result.returncode != 0, option
        lines = [line for line in result.stderr.splitlines() if line.startswith("render.py:")]
        assert len(lines) == 1 and reason in lines[0], (option, result.stderr)
        assert "Traceback" not in result.stderr + result.stdout, option
    assert not out.exists()

    bpy.data.objects.remove(camera_object)
    no_camera = ch.save_blend(bpy, tmp_path / "no_camera.blend")
    result = ch.run_render_script(no_camera, out, "--beta=0,0,0.5", check=False)
    assert result.returncode != 0 and "no active camera" in result.stderr
    result = ch.run_render_script(tmp_path / "missing.blend", out, check=False)
    assert result.returncode != 0 and "no such .blend file" in result.stderr


def test_png_output_and_beta_written_to_file(factory_blender, tmp_path):
    bpy = factory_blender
    _scene(bpy)
    blend = ch.save_blend(bpy, tmp_path / "scene.blend")
    out = tmp_path / "frame.png"
    result = ch.run_render_script(blend, out, "--beta=-0.5,0,0", "--samples=1", "--resolution=32x24", "--frame=3")
    assert result.returncode == 0 and out.exists()
    image = bpy.data.images.load(str(out))
    assert tuple(image.size) == (32, 24)
