"""The bounce between moving objects corrected by the add-on's own Set Up (issue 27, item 6;
``lights/interreflection.py``): ``test_interreflection.py``'s case, 0.5c apart and approaching,
rendered with the scene on Cycles' Open Shading Language, against that file's physics model
(written from docs/physics.md alone). Camera rays stay unchanged (the sphere, seen directly, lit
only by the lamp), and Remove gives the scene back.
"""

import numpy as np
import pytest
import test_interreflection as case

import camera_helpers as ch
from relativity_addon.blender.common import names, osl

UNCORRECTED = "Light bounced between moving objects is not corrected, up to 12 % off at 0.5c (docs/lamp-doppler.md)"


def _sphere_pixels(beta):
    """The sphere's inner pixels (at least two pixels from its outline)."""
    rays = ch.pixel_rays(case.RESOLUTION, case.SENSOR, case.LENS)
    sphere_path, _ = case._sphere_hit(case.CAMERA, 0.0, rays, beta)
    return np.isfinite(sphere_path) & case._inner(np.where(np.isfinite(sphere_path), 1.0, np.nan))


def _render(bpy, tmp_path, beta, name, use_osl=True):
    """The panel's (and the sphere's) pixels rendered through Set Up, and the panel's model."""
    scene, rotation = case._scene(bpy, beta, -beta)
    scene.cycles.shading_system = use_osl
    effect = case._module("pipeline.effect")
    effect.apply(scene)
    panel = case._inner(case._seen_panel(rotation, beta, -beta)[0])
    case._border(scene, panel | _sphere_pixels(beta))
    image = ch.luminance(ch.render_exr(bpy, scene, tmp_path / f"{name}.exr"))
    carrying = [m.name for m in bpy.data.materials if names.BOUNCE_MATERIAL_KEY in m]
    effect.remove(scene)
    return image, rotation, carrying


@pytest.fixture
def osl_scene(relativity_addon, factory_blender):
    """``test_interreflection.py``'s pair approaching at 0.5c, on Cycles' OSL (skipped without it)."""
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    beta = np.array([case.EACH, 0.0, 0.0])
    scene, _ = case._scene(factory_blender, beta, -beta)
    scene.cycles.shading_system = True
    return scene


@pytest.mark.parametrize(("name", "sphere_beta"), [("apart", -case.EACH), ("approaching", case.EACH)])
def test_set_up_corrects_the_bounce(relativity_addon, factory_blender, tmp_path, name, sphere_beta):
    """Through Set Up, on OSL: the panel's bounce light within 5 % of the physics model both ways
    (uncorrected, on main: 1.121 apart, 0.950 approaching); the sphere's own pixels (camera rays,
    direct light) as on SVM shading (the node form, ``test_interreflection_svm.py``)."""
    bpy = factory_blender
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    beta = np.array([sphere_beta, 0.0, 0.0])
    corrected, rotation, carrying = _render(bpy, tmp_path, beta, name)
    plain, _, svm_carrying = _render(bpy, tmp_path, beta, f"{name}_svm", use_osl=False)
    physics = case._model(rotation, beta, -beta)
    sampled = case._inner(case._seen_panel(rotation, beta, -beta)[0]) & np.isfinite(physics)
    case._save(bpy, tmp_path / f"{name}_corrected_render_model.png", corrected, physics)
    ratio = float(corrected[sampled].mean() / physics[sampled].mean())
    svm = float(plain[sampled].mean() / physics[sampled].mean())
    sphere = _sphere_pixels(beta)
    direct = float(corrected[sphere].mean() / plain[sphere].mean())
    print(
        f"{name}: {sampled.sum()} panel px, rendered over physics: corrected {ratio:.4f}, "
        f"SVM (node form) {svm:.4f}; sphere {sphere.sum()} px, OSL over SVM {direct:.4f}"
    )
    assert ratio == pytest.approx(1.0, abs=0.05)
    assert direct == pytest.approx(1.0, abs=0.01)
    assert carrying == ["White"] and len(svm_carrying) == 1  # (the second scene's material: White.001)


def test_at_rest_control(relativity_addon, factory_blender, tmp_path):
    """Nothing moves: no material gets the factor and the OSL render matches the model (3 %)."""
    bpy = factory_blender
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    image, rotation, carrying = _render(bpy, tmp_path, np.zeros(3), "rest")
    physics = case._model(rotation, np.zeros(3), np.zeros(3))
    sampled = case._inner(case._seen_panel(rotation, np.zeros(3), np.zeros(3))[0]) & np.isfinite(physics)
    ratio = float(image[sampled].mean() / physics[sampled].mean())
    print(f"rest: rendered over physics {ratio:.4f}")
    assert carrying == []
    assert ratio == pytest.approx(1.0, abs=0.03)


def test_remove_gives_the_scene_back_and_the_panel_says_what_is_left(factory_blender, osl_scene):
    """Set Up on OSL adds the node and its text, Remove gives the file back (``scene_dump``); off
    OSL the node form replaces it (no text, no panel line); with a moving observer the final render
    corrects it (test_interreflection_observer.py) and the panel says nothing of it, unless the final
    render is the boosted-mesh preview: then one panel line says the bounce is uncorrected."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
    import scene_dump

    bpy = factory_blender
    effect = case._module("pipeline.effect")
    scene = osl_scene
    before = scene_dump.dump(bpy)
    effect.apply(scene)
    effect.sync(scene)
    assert names.BOUNCE_SHADER_TEXT in bpy.data.texts
    tree = bpy.data.materials["White"].node_tree
    assert tree.nodes[names.BOUNCE_NODE_NAME].outputs["Out"].is_linked
    assert not any("bounced" in line for line in effect.scene_warnings(scene))
    effect.remove(scene)
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, "\n".join(lines[:20])
    scene.cycles.shading_system = False
    effect.apply(scene)
    effect.sync(scene)
    assert not [line for line in effect.scene_warnings(scene) if "bounced" in line]
    assert names.BOUNCE_SHADER_TEXT not in bpy.data.texts
    assert "group" in bpy.data.materials["White"][names.BOUNCE_MATERIAL_KEY]
    effect.remove(scene)
    scene.cycles.shading_system = True
    scene.relativity.beta = (0.0, 0.0, 0.3)
    effect.apply(scene)
    effect.sync(scene)
    assert not [line for line in effect.scene_warnings(scene) if "bounced" in line]
    effect.remove(scene)
    scene.relativity.geometry_final_render = "PREVIEW"
    effect.apply(scene)
    effect.sync(scene)
    assert [line for line in effect.scene_warnings(scene) if "bounced" in line] == [
        f"{UNCORRECTED}: the observer moves"
    ]
    assert not any(names.BOUNCE_MATERIAL_KEY in m for m in bpy.data.materials)
    effect.remove(scene)


def test_the_lookup_follows_the_sync(factory_blender, osl_scene):
    """A changed velocity or position reaches the shader's boxes and velocities at the next sync
    (the text rewritten, the node recompiled with its sockets)."""
    bpy = factory_blender
    effect = case._module("pipeline.effect")
    scene = osl_scene
    effect.apply(scene)
    effect.sync(scene)
    first = bpy.data.texts[names.BOUNCE_SHADER_TEXT].as_string()
    assert f"beta = vector({case.EACH:.7g}, 0, 0)" in first
    scene.objects["Sphere"].relativity.beta = (0.0, 0.4, 0.0)
    effect.sync(scene)
    second = bpy.data.texts[names.BOUNCE_SHADER_TEXT].as_string()
    assert "beta = vector(0, 0.4, 0)" in second and f"beta = vector({case.EACH:.7g}, 0, 0)" not in second
    scene.objects["Sphere"].location.z += 0.5  # (Constant motion: the location is where it is at every frame)
    effect.sync(scene)
    third = bpy.data.texts[names.BOUNCE_SHADER_TEXT].as_string()
    assert third != second  # the sphere's box moved with it
    node = bpy.data.materials["White"].node_tree.nodes[names.BOUNCE_NODE_NAME]
    assert "Out" in node.outputs and node.outputs["Out"].is_linked
    effect.remove(scene)


def test_a_build_without_osl_gets_the_node_form(relativity_addon, factory_blender, monkeypatch):
    """Without OSL (as Debian's 5.2: ``_cycles.with_osl`` False, no oslquery), with the scene's OSL
    switch on, Set Up takes the node form: no text, no panel line."""
    import sys

    import _cycles

    bpy = factory_blender
    effect = case._module("pipeline.effect")
    beta = np.array([case.EACH, 0.0, 0.0])
    scene, _ = case._scene(bpy, beta, -beta)
    scene.cycles.shading_system = True
    monkeypatch.setattr(_cycles, "with_osl", False)
    monkeypatch.setitem(sys.modules, "oslquery", None)
    effect.apply(scene)
    effect.sync(scene)
    assert not [line for line in effect.scene_warnings(scene) if "bounced" in line]
    assert names.BOUNCE_SHADER_TEXT not in bpy.data.texts
    assert "group" in bpy.data.materials["White"][names.BOUNCE_MATERIAL_KEY]
    effect.remove(scene)
    assert not any(names.BOUNCE_MATERIAL_KEY in m for m in bpy.data.materials)


def test_remove_on_one_scene_leaves_another_set_up_scene_corrected(factory_blender, osl_scene):
    """Two set-up scenes, each with its own moving pair and material: each gets its own text (its
    camera and movers), and Remove on one leaves the other's node and text in place."""
    bpy = factory_blender
    effect = case._module("pipeline.effect")
    first = osl_scene
    second = first.copy()  # a linked copy: the same objects...
    second.name = "Second"
    for obj in list(second.collection.objects):
        second.collection.objects.unlink(obj)
    grey = bpy.data.materials["White"].copy()
    grey.name = "Second White"
    for name in ("Sphere", "Panel", "Camera"):  # ...replaced by copies with their own material
        copy = first.objects[name].copy()
        if copy.type == "MESH":
            copy.data = copy.data.copy()
            copy.data.materials[0] = grey
        second.collection.objects.link(copy)
        if name == "Camera":
            second.camera = copy
    for scene in (first, second):
        effect.apply(scene)
        effect.sync(scene)
    texts = {scene.name: scene.get(names.BOUNCE_TEXT_KEY) for scene in (first, second)}
    effect.remove(first)
    node = grey.node_tree.nodes.get(names.BOUNCE_NODE_NAME)
    assert node is not None and node.outputs["Out"].is_linked, "Remove on one scene took the other's correction"
    assert names.BOUNCE_MATERIAL_KEY not in bpy.data.materials["White"]
    assert len(set(texts.values())) == 2, texts
    assert texts[first.name] not in bpy.data.texts and texts[second.name] in bpy.data.texts
    effect.sync(second)
    assert grey.node_tree.nodes.get(names.BOUNCE_NODE_NAME) is not None
    effect.remove(second)
    assert not any(names.BOUNCE_MATERIAL_KEY in m for m in bpy.data.materials)
    assert not any(t.name.startswith(names.BOUNCE_SHADER_TEXT) for t in bpy.data.texts)
