"""The exact camera's colour stage costs a render only what changes its image (issue 26, the exact
camera on its floor).

- The compositor stage (``colour/compositing.py``) is muted while the observer is at rest in every
  frame: ``D = 1`` at every pixel, where the stage gives back the rendered values to its tables'
  rounding. The muted render equals the stage's own output; a speed, or a velocity that is keyed
  (it may change from frame to frame), keeps the stage on. A compositor tree the add-on created
  (the scene had none) is switched off with it: it would only copy the render.
- The denoising data passes, which Cycles writes at every camera sample's first hit, are switched
  on only where the light groups' Denoise nodes use them (the denoiser on, a blackbody lamp in a
  light group); otherwise the view layer keeps the user's setting, which Remove gives back.
"""

import numpy as np

import colour_helpers as dh


def _scene(bpy):
    """A grey plane 4 m in front of the camera under a 2700 K blackbody point lamp (a light group)."""
    scene, _camera = dh.emitter_scene(bpy, samples=4, resolution=(24, 16))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, -4.0))
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 500.0
    lamp.data.use_nodes = True
    tree = lamp.data.node_tree
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = 2700.0
    tree.links.new(blackbody.outputs["Color"], tree.nodes["Emission"].inputs["Color"])
    lamp.location = (0.5, 0.5, -2.0)
    scene.collection.objects.link(lamp)
    return scene


def _stage_nodes(addon, scene):
    tree = dh.addon_module(addon, "common.compat").compositor_tree(scene)
    return [node for node in tree.nodes if node.bl_idname == "CompositorNodeGroup"]


def test_stage_is_muted_only_while_the_observer_is_at_rest_throughout(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene = _scene(bpy)
    scene.relativity.beta = (0.0, 0.0, 0.0)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    nodes = _stage_nodes(relativity_addon, scene)
    assert nodes and all(node.mute for node in nodes)
    assert not scene.render.use_compositing, "the add-on's own compositor tree would only copy the render"
    muted = dh.render(bpy, scene, tmp_path / "muted.exr")
    effect.sync(scene)
    assert all(node.mute for node in nodes)
    scene.relativity.beta = (0.0, 0.0, -0.3)
    effect.sync(scene)
    assert not any(node.mute for node in nodes) and scene.render.use_compositing
    # A keyed velocity may change from frame to frame: the stage stays on, here at rest, which
    # gives its own output at D = 1 to compare the muted render with.
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.keyframe_insert("relativity.beta", frame=1)
    effect.sync(scene)
    assert not any(node.mute for node in nodes)
    unmuted = dh.render(bpy, scene, tmp_path / "unmuted.exr")
    assert not any(node.mute for node in nodes)
    assert muted.mean() > 0.01
    error = np.abs(muted - unmuted).max() / muted.max()
    print(f"at rest, muted stage against its output: max difference {error:.2e} of the brightest pixel")
    assert error < 2e-4
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.animation_data_clear()
    effect.sync(scene)
    assert all(node.mute for node in nodes) and not scene.render.use_compositing
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert scene.render.use_compositing  # as before Set Up (Blender's default)


def test_denoising_passes_only_for_denoised_light_groups(relativity_addon):
    bpy = __import__("bpy")
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene = _scene(bpy)
    layer = scene.view_layers[0]
    layer.cycles.denoising_store_passes = False
    scene.cycles.use_denoising = False
    scene.relativity.beta = (0.0, 0.0, -0.3)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert [group.name for group in layer.lightgroups], "the blackbody lamp has a light group"
    assert not layer.cycles.denoising_store_passes, "written at every sample for muted denoisers"
    scene.cycles.use_denoising = True
    effect.sync(scene)
    assert layer.cycles.denoising_store_passes
    denoisers = [
        node
        for node in dh.addon_module(relativity_addon, "common.compat").compositor_tree(scene).nodes
        if node.bl_idname == "CompositorNodeDenoise" and not node.mute
    ]
    assert denoisers and all(node.inputs["Normal"].is_linked for node in denoisers), "guides linked"
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert not layer.cycles.denoising_store_passes  # the user's setting
