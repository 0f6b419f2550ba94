"""A mesh at rest sharing a material with a moving mesh renders as it would without the effect.

Reported by another helper: in ``test_interreflection_limits.py``'s scene (a panel at rest and a
moving sphere, Apparent Geometry, camera at rest) the panel sharing the sphere's material measured
0.0246 before Set Up and 0.0 after on main. Here the panel at rest shares "White" with the moving
sphere; it is rendered before Set Up and after, lit by a point lamp, a sun, and by an emitter
(measured pixels of the panel, real Cycles renders).
"""

import numpy as np
import pytest
import test_interreflection as case

import camera_helpers as ch


def _render(bpy, scene, path):
    return ch.luminance(ch.render_exr(bpy, scene, path))


def _light(bpy, scene, kind):
    lamp = scene.objects["Lamp"]
    if kind == "point":
        lamp.location = (-1.0, -2.0, 0.5)  # in front of the panel
    elif kind == "sun":
        lamp.data.type = "SUN"
        lamp.data.energy = 3.0
        lamp.rotation_euler = (0.9, 0.0, 0.4)
    elif kind == "emitter":
        lamp.data.energy = 0.0
        glow = ch.diffuse_material(bpy, "Glow", (1.0, 1.0, 1.0))
        from relativity_addon.blender.common import compat

        tree = compat.material_node_tree(glow)
        for node in list(tree.nodes):
            tree.nodes.remove(node)
        emission = tree.nodes.new("ShaderNodeEmission")
        emission.inputs["Strength"].default_value = 5.0
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        tree.links.new(emission.outputs[0], output.inputs["Surface"])
        mesh = bpy.data.meshes.new("Emitter")
        import bmesh

        bm = bmesh.new()
        bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.5)
        bm.to_mesh(mesh)
        bm.free()
        mesh.materials.append(glow)
        emitter = bpy.data.objects.new("Emitter", mesh)
        emitter.location = tuple(case.CAMERA + np.array([0.0, 1.0, 3.0]))
        emitter.rotation_euler = (np.pi, 0.0, 0.0)
        scene.collection.objects.link(emitter)
    bpy.context.view_layer.update()


@pytest.mark.parametrize(
    ("kind", "doppler", "keyframed"),
    [
        ("point", False, False),
        ("sun", False, False),
        ("emitter", False, False),
        ("point", True, False),
        ("emitter", True, False),
        ("point", False, True),
    ],
)
def test_rest_mesh_sharing_a_moving_mesh_material(
    relativity_addon, factory_blender, tmp_path, kind, doppler, keyframed
):
    """The panel at rest shares "White" with the moving sphere: after Set Up it renders as before
    (within 5 %; on main 0.0 in every case: the rest-normal group's transform of the absent
    attribute's (0, 0, 0) gave NaN normals)."""
    bpy = factory_blender
    beta = np.array([case.EACH, 0.0, 0.0])
    scene, rotation = case._scene(bpy, beta, np.zeros(3))
    scene.relativity.use_doppler = doppler
    if keyframed:
        sphere = scene.objects["Sphere"]
        sphere.relativity.motion = "ANIMATION"
    # the sphere far behind the camera (no shadow or bounce on the panel), direct light only
    scene.objects["Sphere"].location = (0.0, -40.0, 0.0)
    scene.cycles.max_bounces = 0
    if keyframed:
        for frame, x in ((1, 0.0), (20, 3.0)):
            sphere.location.x = x
            sphere.keyframe_insert("location", frame=frame)
        scene.frame_set(1)
    _light(bpy, scene, kind)
    assert scene.objects["Panel"].data.materials[0] == scene.objects["Sphere"].data.materials[0]
    seen = case._inner(case._seen_panel(rotation, beta, np.zeros(3))[0])
    before = _render(bpy, scene, tmp_path / "before.exr")
    effect = case._module("pipeline.effect")
    effect.apply(scene)
    after = _render(bpy, scene, tmp_path / "after.exr")
    effect.remove(scene)
    b, a = float(before[seen].mean()), float(after[seen].mean())
    label = f"{kind}, doppler {doppler}, keyframed {keyframed}"
    print(f"{label}: panel at rest {seen.sum()} px, before Set Up {b:.5f}, after {a:.5f}, ratio {a / b:.4f}")
    assert a == pytest.approx(b, rel=0.05)
