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


def _render(bpy, tmp_path, beta, name, use_osl=True):
    """The panel's (and the sphere's) pixels rendered through Set Up, and the panel's model."""
    scene, rotation = case._scene(bpy, beta, -beta)
    scene.cycles.shading_system = use_osl
    effect = case._module("pipeline.effect")
    effect.apply(scene)
    image = ch.luminance(ch.render_exr(bpy, scene, tmp_path / f"{name}.exr"))
    carrying = [m.name for m in bpy.data.materials if names.BOUNCE_MATERIAL_KEY in m]
    effect.remove(scene)
    return image, rotation, carrying


@pytest.mark.parametrize(("name", "sphere_beta"), [("apart", -case.EACH), ("approaching", case.EACH)])
def test_set_up_corrects_the_bounce(relativity_addon, factory_blender, tmp_path, name, sphere_beta):
    """Through Set Up, on OSL: the panel's bounce light within 5 % of the physics model both ways
    (uncorrected, on main: 1.121 apart, 0.950 approaching); the sphere's own pixels (camera rays,
    direct light) as without the correction (SVM shading, the same scene)."""
    bpy = factory_blender
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    beta = np.array([sphere_beta, 0.0, 0.0])
    corrected, rotation, carrying = _render(bpy, tmp_path, beta, name)
    plain, _, none = _render(bpy, tmp_path, beta, f"{name}_svm", use_osl=False)
    physics = case._model(rotation, beta, -beta)
    sampled = case._inner(case._seen_panel(rotation, beta, -beta)[0]) & np.isfinite(physics)
    case._save(bpy, tmp_path / f"{name}_corrected_render_model.png", corrected, physics)
    ratio = float(corrected[sampled].mean() / physics[sampled].mean())
    uncorrected = float(plain[sampled].mean() / physics[sampled].mean())
    rays = ch.pixel_rays(case.RESOLUTION, case.SENSOR, case.LENS)
    sphere_path, _ = case._sphere_hit(case.CAMERA, 0.0, rays, beta)
    sphere = np.isfinite(sphere_path) & case._inner(np.where(np.isfinite(sphere_path), 1.0, np.nan))
    direct = float(corrected[sphere].mean() / plain[sphere].mean())
    print(
        f"{name}: {sampled.sum()} panel px, rendered over physics: corrected {ratio:.4f}, "
        f"SVM uncorrected {uncorrected:.4f}; sphere {sphere.sum()} px, corrected over SVM {direct:.4f}"
    )
    assert carrying == ["White"] and none == []
    assert ratio == pytest.approx(1.0, abs=0.05)
    assert direct == pytest.approx(1.0, abs=0.01)
