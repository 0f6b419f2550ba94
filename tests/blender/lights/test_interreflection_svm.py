"""The bounce between moving objects corrected on Cycles' default shading, SVM (issue 27, item 6;
``lights/bounce_nodes.py``): ``test_interreflection.py``'s case through the add-on's own Set Up,
0.5c apart and approaching, against that file's physics model (written from docs/physics.md
alone). The same render with the inserted node muted is the uncorrected snapshot (on main, before
the node form: 1.121 apart, 0.950 approaching). Camera rays stay unchanged (the sphere, seen
directly, lit only by the lamp), nothing moving gets no node, and Remove gives the scene back.
"""

import numpy as np
import pytest
import test_interreflection as case

import camera_helpers as ch
from relativity_addon.blender.common import names


def _render(bpy, scene, path, muted=False):
    """Luminance of a render with the bounce node of every material carrying it (un)muted."""
    for material in bpy.data.materials:
        if names.BOUNCE_MATERIAL_KEY in material:
            material.node_tree.nodes[material[names.BOUNCE_MATERIAL_KEY]["node"]].mute = muted
    return ch.luminance(ch.render_exr(bpy, scene, path))


@pytest.mark.parametrize(("name", "sphere_beta"), [("apart", -case.EACH), ("approaching", case.EACH)])
def test_set_up_corrects_the_bounce_on_svm(relativity_addon, factory_blender, tmp_path, name, sphere_beta):
    """Through Set Up on SVM: the panel's bounce light within 5 % of the physics model both ways;
    the sphere's own pixels (camera rays, direct light) as with the node muted (1 %)."""
    bpy = factory_blender
    beta = np.array([sphere_beta, 0.0, 0.0])
    scene, rotation = case._scene(bpy, beta, -beta)
    assert not scene.cycles.shading_system  # Cycles' default: SVM
    effect = case._module("pipeline.effect")
    effect.apply(scene)
    carrying = sorted(m.name for m in bpy.data.materials if names.BOUNCE_MATERIAL_KEY in m)
    corrected = _render(bpy, scene, tmp_path / f"{name}.exr")
    plain = _render(bpy, scene, tmp_path / f"{name}_muted.exr", muted=True)
    effect.remove(scene)
    physics = case._model(rotation, beta, -beta)
    sampled = case._inner(case._seen_panel(rotation, beta, -beta)[0]) & np.isfinite(physics)
    case._save(bpy, tmp_path / f"{name}_svm_render_model.png", corrected, physics)
    ratio = float(corrected[sampled].mean() / physics[sampled].mean())
    uncorrected = float(plain[sampled].mean() / physics[sampled].mean())
    rays = ch.pixel_rays(case.RESOLUTION, case.SENSOR, case.LENS)
    sphere_path, _ = case._sphere_hit(case.CAMERA, 0.0, rays, beta)
    sphere = np.isfinite(sphere_path) & case._inner(np.where(np.isfinite(sphere_path), 1.0, np.nan))
    direct = float(corrected[sphere].mean() / plain[sphere].mean())
    print(
        f"{name}: {sampled.sum()} panel px, rendered over physics: SVM corrected {ratio:.4f}, "
        f"node muted {uncorrected:.4f}; sphere {sphere.sum()} px, corrected over muted {direct:.4f}"
    )
    assert ratio == pytest.approx(1.0, abs=0.05)
    assert direct == pytest.approx(1.0, abs=0.01)
    assert carrying == ["White"]


def test_at_rest_control_on_svm(relativity_addon, factory_blender, tmp_path):
    """Nothing moves: no material gets the node and the SVM render matches the model (3 %)."""
    bpy = factory_blender
    scene, rotation = case._scene(bpy, np.zeros(3), np.zeros(3))
    effect = case._module("pipeline.effect")
    effect.apply(scene)
    assert not any(names.BOUNCE_MATERIAL_KEY in m for m in bpy.data.materials)
    assert not any(g.name.startswith(names.BOUNCE_SCENE_GROUP) for g in bpy.data.node_groups)
    image = _render(bpy, scene, tmp_path / "rest.exr")
    effect.remove(scene)
    physics = case._model(rotation, np.zeros(3), np.zeros(3))
    sampled = case._inner(case._seen_panel(rotation, np.zeros(3), np.zeros(3))[0]) & np.isfinite(physics)
    ratio = float(image[sampled].mean() / physics[sampled].mean())
    print(f"rest: rendered over physics {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.03)


def test_svm_values_follow_the_sync_and_remove_gives_the_scene_back(relativity_addon, factory_blender):
    """The scene's group holds one receiver box per moving object; a changed velocity reaches its
    node inputs at the next sync without rebuilding the group; switching OSL shading on swaps the
    node form for the script; Remove gives the file back (``scene_dump``)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
    import scene_dump

    from relativity_addon.blender.common import osl

    bpy = factory_blender
    effect = case._module("pipeline.effect")
    beta = np.array([case.EACH, 0.0, 0.0])
    scene, _ = case._scene(bpy, beta, -beta)
    before = scene_dump.dump(bpy)
    effect.apply(scene)
    effect.sync(scene)
    group = bpy.data.node_groups[scene[names.BOUNCE_GROUP_KEY]]
    assert bpy.data.materials["White"][names.BOUNCE_MATERIAL_KEY]["group"] == group.name
    receivers = sorted(n.name for n in group.nodes if n.bl_idname == "ShaderNodeGroup" and n.name != "factor")
    assert len(receivers) == 2
    nodes_before = {n.as_pointer() for n in group.nodes}
    betas = sorted(tuple(round(v, 4) for v in group.nodes[r].inputs["Beta"].default_value) for r in receivers)
    assert betas == sorted([(round(case.EACH, 4), 0.0, 0.0), (round(-case.EACH, 4), 0.0, 0.0)])
    assert not any("bounced" in line for line in effect.scene_warnings(scene))
    scene.objects["Sphere"].relativity.beta = (0.0, 0.4, 0.0)
    effect.sync(scene)
    betas = [tuple(round(v, 4) for v in group.nodes[r].inputs["Beta"].default_value) for r in receivers]
    assert (0.0, 0.4, 0.0) in betas
    assert {n.as_pointer() for n in group.nodes} == nodes_before  # values written, nothing rebuilt
    group_name = group.name
    if osl.unavailable_reason() is None:
        scene.cycles.shading_system = True
        effect.sync(scene)
        assert "text" in bpy.data.materials["White"][names.BOUNCE_MATERIAL_KEY]
        assert group_name not in bpy.data.node_groups
        scene.cycles.shading_system = False
        effect.sync(scene)
        assert "group" in bpy.data.materials["White"][names.BOUNCE_MATERIAL_KEY]
    effect.remove(scene)
    scene.objects["Sphere"].relativity.beta = tuple(float(b) for b in beta)
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, "\n".join(lines[:20])
    assert not any(g.name.startswith(names.BOUNCE_SCENE_GROUP) for g in bpy.data.node_groups)
