"""The per-ray bounce factor (docs/lamp-doppler.md, "A per-ray correction") in a real Cycles
render of ``test_interreflection.py``'s case, against its physics model.

The sphere's material gets an OSL script node (``bounce_factor.osl``, the formulas of
``physics/bounce.py``) between its Doppler-coloured colour and its BSDF: on non-camera rays it
finds the receiving point (``P + I * ray length``), where that point sees the sphere's point, and
scales the colour by ``F``. The receiver's velocity (and, in one variant, its rest normal) is
given to it, as the add-on could not give it (a material shader does not know the surface a ray
came from); in another variant the shader traces back to the receiver for its normal (OSL only):
this measures how far the correction reaches. The add-on's own correction
(``lights/interreflection.py``, which would act on these OSL scenes at the render's sync) is kept
out here; ``test_interreflection_correction.py`` renders it.
"""

from pathlib import Path

import numpy as np
import pytest
import test_interreflection as case

import camera_helpers as ch
from relativity_addon.blender.common import names, osl

SHADER = Path(__file__).with_name("bounce_factor.osl")


def _insert_factor(bpy, scene, beta_receiver, receiver_normal, use_factor, use_normal):
    """The script node in the sphere's own copy of the material (the panel keeps the original)."""
    scene.cycles.shading_system = True
    sphere = scene.objects["Sphere"]
    material = sphere.material_slots[0].material.copy()
    sphere.material_slots[0].material = material
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfDiffuse")
    colour = bsdf.inputs["Color"]
    source = colour.links[0].from_socket  # the Doppler colour group's output
    text = bpy.data.texts.get(SHADER.name) or bpy.data.texts.new(SHADER.name)
    text.from_string(SHADER.read_text())
    script = tree.nodes.new("ShaderNodeScript")
    script.mode = "INTERNAL"
    with osl.compiling():  # Cycles' compile leaves its .oso behind otherwise (common/osl.py)
        script.script = text
    assert "Out" in script.outputs, "the OSL shader did not compile"
    beta = tree.nodes.new("ShaderNodeAttribute")
    beta.attribute_type = "GEOMETRY"
    beta.attribute_name = names.BETA_ATTRIBUTE
    rest = next(
        (n for n in tree.nodes if n.bl_idname == "ShaderNodeGroup" and n.node_tree.name == names.REST_NORMAL_GROUP),
        None,
    )
    if rest is None:  # nothing moves: no rest normals, the geometry's own
        rest = tree.nodes.new("ShaderNodeNewGeometry")
    tree.links.new(source, script.inputs["In"])
    tree.links.new(beta.outputs["Vector"], script.inputs["BetaS"])
    tree.links.new(rest.outputs["Normal"], script.inputs["RestNormal"])
    script.inputs["Camera"].default_value = tuple(case.CAMERA)
    script.inputs["BetaP"].default_value = tuple(beta_receiver)
    script.inputs["ReceiverNormal"].default_value = tuple(receiver_normal)
    script.inputs["UseFactor"].default_value = use_factor
    script.inputs["UseNormal"].default_value = use_normal
    tree.links.new(script.outputs["Out"], colour)


@pytest.mark.parametrize(("name", "sphere_beta"), [("apart", -case.EACH), ("approaching", case.EACH), ("rest", 0.0)])
def test_per_ray_factor_in_a_render(relativity_addon, factory_blender, tmp_path, monkeypatch, name, sphere_beta):
    """Rendered over the physics model (the test's 487 / 222 pixels): OSL shading with the factor
    off is the suite's 1.12 / 0.95; with the factor and the receiver's rest normal within 5 % both
    ways (measured 0.982 / 1.006), and the same with the normal the shader traces back to the
    receiver (its apparent mesh's, turned back to the rest normal with the receiver's velocity);
    without the normal better than without the factor both ways, but not within 5 % apart
    (1.086 / 0.962). At rest the factor changes nothing."""
    bpy = factory_blender
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    beta = np.array([sphere_beta, 0.0, 0.0])
    monkeypatch.setattr(case._module("lights.interreflection"), "_reason", lambda *args: "the test's own shader")
    effect = case._module("pipeline.effect")
    images, sampled = {}, None
    variants = (("off", 0.0, 0.0), ("normal", 1.0, 1.0), ("traced normal", 1.0, 2.0), ("no normal", 1.0, 0.0))
    for key, use_factor, use_normal in variants:
        scene, rotation = case._scene(bpy, beta, -beta)
        effect.apply(scene)
        _insert_factor(bpy, scene, -beta, rotation[:, 2], use_factor, use_normal)
        if sampled is None:  # the panel's inner pixels (where the sphere is not in front)
            sampled = case._inner(case._seen_panel(rotation, beta, -beta)[0])
        case._border(scene, sampled)
        images[key] = ch.luminance(ch.render_exr(bpy, scene, tmp_path / f"{name}_{key}.exr"))
        effect.remove(scene)
    physics = case._model(rotation, beta, -beta)
    sampled &= np.isfinite(physics)
    case._save(bpy, tmp_path / f"{name}_factor_render_model.png", images["normal"], physics)
    ratios = {key: round(float(image[sampled].mean() / physics[sampled].mean()), 4) for key, image in images.items()}
    print(f"{name}, {sampled.sum()} px: rendered over physics {ratios}")
    if name == "rest":  # the control: the factor is 1 when nothing moves
        assert ratios["off"] == pytest.approx(1.0, abs=0.03)
        assert ratios["normal"] == pytest.approx(ratios["off"], abs=0.002)
        assert ratios["no normal"] == pytest.approx(ratios["off"], abs=0.002)
        assert ratios["traced normal"] == pytest.approx(ratios["off"], abs=0.002)
        return
    assert ratios["off"] == pytest.approx({"apart": 1.12, "approaching": 0.95}[name], abs=0.04)
    assert ratios["normal"] == pytest.approx(1.0, abs=0.05)
    assert ratios["traced normal"] == pytest.approx(ratios["normal"], abs=0.005)
    assert abs(ratios["no normal"] - 1.0) < abs(ratios["off"] - 1.0)
    if name == "apart":
        assert ratios["no normal"] > 1.05
