"""Live behaviour: the result depends only on the frame, settings updates apply at once, and
bad input gives a one-line error (API and batch script)."""

import numpy as np
import pytest

import geometry_helpers as gh
from geometry_helpers import ch


def _scene(bpy):
    scene, camera_object = ch.new_scene(bpy, resolution=(64, 48), samples=1)
    scene.relativity.speed_of_light = 4.0
    obj = ch.add_sphere(bpy, scene, (0.0, 0.0, -5.0), 1.0, ch.emission_material(bpy), name="Ball", segments=16, rings=8)
    return scene, camera_object, obj


def test_frames_are_independent_of_history(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    obj.keyframe_insert("location", index=0, frame=1)
    obj.location.x = 3.0
    obj.keyframe_insert("location", index=0, frame=20)
    obj.relativity.motion = "ANIMATION"
    scene.relativity.beta = (0.0, 0.3, 0.0)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    alone, _ = gh.evaluated_points(bpy, obj)
    for frame in (1, 20, 5, 12):
        scene.frame_set(frame)
        if frame == 5:
            at_five, _ = gh.evaluated_points(bpy, obj)
    in_sequence, _ = gh.evaluated_points(bpy, obj)
    assert np.array_equal(alone, in_sequence)
    assert not np.allclose(at_five, alone)


def test_velocity_changes_update_at_once(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    obj.relativity.motion = "CONSTANT"
    gh.apply_geometry(scene)
    at_rest, _ = gh.evaluated_points(bpy, obj)
    obj.relativity.beta = (0.6, 0.0, 0.0)  # update callback
    moving, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
    # Light left the sphere (~5 units away, c = 4) ~1.25 s ago, when it was ~3 units to -x.
    shift = moving.mean(axis=0) - at_rest.mean(axis=0)
    assert shift[0] < -2.0
    assert np.allclose(beta, [0.6, 0.0, 0.0], atol=1e-6)
    scene.relativity.beta = (0.0, 0.0, 0.5)  # observer velocity: picked up by the depsgraph handler
    bpy.context.view_layer.update()
    _, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
    gamma = 1.0 / np.sqrt(1.0 - 0.25)
    # Composition: u' = (u / gamma - v) for u perpendicular to v.
    assert np.allclose(beta, [0.6 / gamma, 0.0, -0.5], atol=1e-6)


def test_superluminal_object_velocity_is_a_one_line_error(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (1.2, 0.0, 0.0)
    with pytest.raises(gh.geometry_module().RelativityError, match="below 1"):
        gh.apply_geometry(scene)
    assert gh.addon_module("geometry.modifier").find_modifier(obj) is None  # nothing changed
    blend = ch.save_blend(bpy, tmp_path / "fast.blend")
    result = ch.run_render_script(blend, tmp_path / "fast.png", "--method=geometry", check=False)
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert "Traceback" not in result.stderr
    assert "below 1" in lines[-1]


@pytest.mark.parametrize("final_render", ["PREVIEW", "EXACT"])
def test_relativity_beta_reaches_the_shader(relativity_addon, factory_blender, tmp_path, final_render):
    """A material reading the point attribute relativity_beta (Attribute node) renders its value:
    on the boosted-mesh preview the velocity relative to the observer, in the observer's frame;
    behind the exact camera (the final render's default) the scene-frame velocity."""
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    material = obj.data.materials[0]
    tree = material.node_tree
    attribute = tree.nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = "GEOMETRY"
    attribute.attribute_name = "relativity_beta"
    tree.links.new(attribute.outputs["Vector"], tree.nodes["Emission"].inputs["Color"])
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.0, 0.0)
    obj.location = (2.5, 0.0, -5.0)  # seen where it was 5 / c ago: straight ahead, 5 units away
    scene.relativity.geometry_final_render = final_render
    blend = ch.save_blend(bpy, tmp_path / "beta.blend")
    # colour and brightness effects off: the material shows the attribute itself
    image = ch.render_image(
        bpy,
        blend,
        tmp_path / "beta.exr",
        "--method=geometry",
        "--beta=0,0.2,0",
        "--resolution=64x48",
        "--no-doppler",
        "--no-searchlight",
    )
    lit = image.sum(-1) > 0.05
    assert lit.sum() > 50
    colour = np.median(image[lit], axis=0)
    # Velocity addition, u perpendicular to v: u' = (u / gamma_v, -v, 0) (linear EXR keeps signs).
    expected = np.array([0.5 * np.sqrt(1.0 - 0.2**2), -0.2, 0.0]) if final_render == "PREVIEW" else (0.5, 0, 0)
    print(f"rendered relativity_beta {colour}, expected {expected}")
    assert np.allclose(colour, expected, atol=2e-3)


def test_bake_operator_reports_errors_in_one_line(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    bpy.context.view_layer.objects.active = obj
    with pytest.raises(gh.geometry_module().RelativityError, match="at least two samples"):
        gh.addon_module("geometry.bakes").bake_deformation(scene, obj, 1, 1)
    scene.camera = None
    with pytest.raises(RuntimeError, match="no active camera"):
        bpy.ops.relativity.bake_deformation()
    scene.camera = camera_object
    scene.frame_start, scene.frame_end = 1, 3
    obj.relativity.samples_per_frame = 2
    assert bpy.ops.relativity.bake_deformation() == {"FINISHED"}
    assert gh.addon_module("geometry.modifier").bake_mesh(obj) is not None
    assert gh.geometry_module().scene_errors(scene) == []


def test_duplicated_object_gets_its_own_cache(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object, obj = _scene(bpy)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.0, 0.0)
    gh.apply_geometry(scene)
    twin = obj.copy()  # what Shift+D does: the modifier (and its cache pointer) is copied
    twin.location = (1.5, 1.0, -6.0)
    scene.collection.objects.link(twin)
    twin.relativity.beta = (0.0, 0.0, 0.0)  # update callback
    modifier = gh.addon_module("geometry.modifier")
    assert modifier.cache_object(twin) != modifier.cache_object(obj)
    first, _ = gh.evaluated_points(bpy, obj)
    second, beta = gh.evaluated_points(bpy, twin, "relativity_beta")
    assert np.allclose(beta, 0.0)
    assert not np.allclose(first, second)
    gh.remove_effect(scene)
    assert not any(o.name.startswith("RelativityCache") for o in bpy.data.objects)
    assert not any(m.name.startswith("RelativityCache") for m in bpy.data.meshes)
