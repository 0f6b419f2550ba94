"""Boosted meshes at 0.999999 c reach far beyond the camera's Clip End (issue 25).

An observer moving towards a point at distance d ahead sees it, in its own frame, at
gamma (1 + beta) d = sqrt((1 + beta) / (1 - beta)) d (docs/physics.md: the Lorentz transformation of
the emission event (-d/c, d)): 1405 d at 0.999999 c (as a float32 setting). The camera sits inside an emissive sphere of
radius 10 m and moves along its view axis: the sphere's front pole is seen 14049 m away, far
beyond a Clip End of 100 m, which cuts a hole in the middle of the boosted-mesh render. The panel
warns, naming Clip End, the farthest distance and the Clip End needed; with that Clip End the
middle of the render is bright again.
"""

import math
import re

from test_ui_workflow import draw_panel

import camera_helpers as ch

BETA = 0.999999
RADIUS = 10.0


def _scene(bpy):
    scene, camera = ch.new_scene(bpy, resolution=(32, 24), samples=1)
    camera.data.lens = 500.0  # a 4 degree view: the far cap covers its middle
    camera.data.clip_end = 100.0
    sphere = ch.add_sphere(bpy, scene, (0.0, 0.0, 0.0), RADIUS, ch.emission_material(bpy), segments=64, rings=32)
    sphere.relativity.enabled = True
    settings = scene.relativity
    settings.method = "GEOMETRY"
    settings.geometry_final_render = "PREVIEW"
    settings.use_doppler = False
    settings.use_searchlight = False
    settings.beta = (0.0, 0.0, -BETA)
    return scene, camera


def _clip_warnings(bpy, scene):
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    return [e[1] for e in log if e[0] == "label" and "Clip End" in e[1]]


def test_clip_end_warning_names_the_distance_needed(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera = _scene(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    bpy.context.view_layer.update()
    cut = ch.render_exr(bpy, scene, tmp_path / "cut.exr")
    height, width = cut.shape[:2]
    middle = ch.luminance(cut[height // 2 - 2 : height // 2 + 2, width // 2 - 2 : width // 2 + 2])
    assert middle.max() < 1e-3, middle  # the far cap is cut off by Clip End
    assert ch.luminance(cut).max() > 0.5  # the rest of the sphere is seen

    warnings = _clip_warnings(bpy, scene)
    assert len(warnings) == 1, warnings
    match = re.fullmatch(
        r"Camera 'Camera': Clip End 100 m cuts off mesh 'Marker', seen ([\d.e+]+) m away at this speed: "
        r"set Clip End to ([\d.e+]+) m",
        warnings[0],
    )
    assert match, warnings[0]
    seen, needed = float(match.group(1)), float(match.group(2))
    beta = -scene.relativity.beta[2]  # as Blender stores it (float32: 0.99999899)
    front_pole = RADIUS * math.sqrt((1.0 + beta) / (1.0 - beta))
    assert abs(seen - front_pole) < 1e-3 * front_pole, (seen, front_pole)
    assert front_pole < needed < 1.2 * front_pole

    camera.data.clip_end = needed
    bpy.context.view_layer.update()
    assert _clip_warnings(bpy, scene) == []
    whole = ch.render_exr(bpy, scene, tmp_path / "whole.exr")
    middle = ch.luminance(whole[height // 2 - 2 : height // 2 + 2, width // 2 - 2 : width // 2 + 2])
    assert middle.min() > 0.5, middle
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert camera.data.clip_end == needed  # the user's (the add-on changes no Clip End)
