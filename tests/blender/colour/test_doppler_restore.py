"""Applying the exact camera sets up the Doppler colour stage; removing it restores the file.

Also: a .blend saved with the effect renders the same final colours without the add-on and
without colour-science (LUTs and node groups are packed in the file).
"""

import subprocess
import sys

import numpy as np

import colour_helpers as dh
from colour_helpers import ch
from relativity_addon.blender.common import compat

# End of a worker script: bpy 4.5 can hang in exit() (see compat.run_main), so leave with os._exit.
EXIT_WORKER = "import os\nsys.stdout.flush()\nsys.stderr.flush()\nos._exit(0)\n"


def _signature(bpy, scene):
    """Everything the stage touches, as comparable plain data."""

    def tree_signature(tree):
        if tree is None:
            return None
        nodes = sorted((node.name, node.bl_idname) for node in tree.nodes)
        links = sorted(
            (link.from_node.name, link.from_socket.identifier, link.to_node.name, link.to_socket.identifier)
            for link in tree.links
        )
        drivers = [] if tree.animation_data is None else sorted(f.data_path for f in tree.animation_data.drivers)
        return nodes, links, drivers, tree.animation_data is not None

    return {
        "materials": {
            m.name: (tree_signature(m.node_tree), sorted(compat.custom_property_keys(m))) for m in bpy.data.materials
        },
        "worlds": {
            w.name: (tree_signature(w.node_tree), sorted(compat.custom_property_keys(w))) for w in bpy.data.worlds
        },
        "compositor": (
            compat.compositor_tree(scene).name if compat.compositor_tree(scene) else None,
            tree_signature(compat.compositor_tree(scene)),
            scene.render.use_compositing,
        ),
        "aovs": {v.name: sorted(a.name for a in v.aovs) for v in scene.view_layers},
        "node_groups": sorted(g.name for g in bpy.data.node_groups),
        "images": sorted(i.name for i in bpy.data.images),
        "scene_keys": sorted(compat.custom_property_keys(scene)),
    }


def _scene_with_user_compositor(bpy):
    scene, camera = dh.emitter_scene(bpy)
    dh.add_emitter_plane(bpy, scene, "Wall", (-400.0, 400.0), (-400.0, 400.0), (0.3, 0.6, 0.2), beta=None)
    dh.add_emitter_plane(bpy, scene, "Sun", (-0.5, 0.5), (-0.5, 0.5), beta=None, temperature=5762.0, depth=4.0)
    # The user's own compositor: Render Layers -> Exposure -> output.
    if compat.has_compositor_node_groups():
        tree = bpy.data.node_groups.new("User Compositing", "CompositorNodeTree")
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        output = tree.nodes.new("NodeGroupOutput")
        scene.compositing_node_group = tree
    else:  # Blender 4.5: the scene's own tree, ending in a Composite node
        scene.use_nodes = True
        tree = scene.node_tree
        tree.nodes.clear()
        output = tree.nodes.new("CompositorNodeComposite")
        bpy.data.images.remove(bpy.data.images["Viewer Node"])  # made for the default tree's Viewer
    layers = tree.nodes.new("CompositorNodeRLayers")
    exposure = tree.nodes.new("CompositorNodeExposure")
    tree.links.new(layers.outputs["Image"], exposure.inputs["Image"])
    tree.links.new(exposure.outputs["Image"], output.inputs[0])
    scene.render.use_compositing = False
    return scene, camera


def test_apply_then_remove_restores_everything(relativity_addon, factory_blender):
    bpy = factory_blender
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene, _camera = _scene_with_user_compositor(bpy)
    before = _signature(bpy, scene)

    scene.relativity.beta = (0.0, 0.0, -0.5)
    effect.apply(scene)
    applied = _signature(bpy, scene)
    assert applied != before
    user_tree = compat.compositor_tree(scene)
    assert user_tree is not None and user_tree.name == before["compositor"][0]  # the user's tree, kept
    assert any(n.bl_idname == "CompositorNodeGroup" for n in user_tree.nodes)
    assert scene.render.use_compositing
    # Applying twice changes nothing more.
    effect.apply(scene)
    assert _signature(bpy, scene) == applied

    effect.remove(scene)
    after = _signature(bpy, scene)
    assert after == before


def test_saved_file_renders_without_addon_or_colour_science(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene, camera = dh.emitter_scene(bpy, samples=4)
    dh.add_emitter_plane(bpy, scene, "Wall", (-400.0, 400.0), (-400.0, 400.0), (0.3, 0.6, 0.2), beta=None)
    dh.add_emitter_plane(bpy, scene, "Sun", (-0.5, 0.5), (-0.5, 0.5), beta=None, temperature=5762.0, depth=4.0)
    scene.relativity.beta = (0.2, 0.0, -0.5)
    effect.apply(scene)
    reference = dh.render(bpy, scene, tmp_path / "with_addon.exr")
    blend = ch.save_blend(bpy, tmp_path / "packed.blend")

    plain = dh.render_without_addon(bpy, blend, tmp_path / "plain.exr")
    difference = np.abs(plain - reference).max() / reference.max()
    print(f"max |plain - with add-on| / max = {difference:.2e}; reference max {reference.max():.3f}")
    assert np.isfinite(plain).all()
    assert difference < 1e-5
    # And the stage really acted: the wall is not its rest colour.
    assert np.abs(reference[5, 5] - (0.3, 0.6, 0.2)).max() > 0.05


def test_colour_stage_failure_is_one_line_and_leaves_scene_untouched(factory_blender, tmp_path):
    """Applying needs no colour-science (a real Blender has none: the tables ship with the
    add-on); when the shipped tables cannot be read: one clear error line, nothing changed."""
    bpy = factory_blender
    scene, _camera = _scene_with_user_compositor(bpy)
    blend = ch.save_blend(bpy, tmp_path / "no_colour.blend")
    worker = (
        "import sys\n"
        "sys.modules['colour'] = None  # colour-science missing, as in a real Blender\n"
        f"sys.path.insert(0, {str(ch.REPO_ROOT)!r})\n"
        "import bpy\n"
        f"bpy.ops.wm.open_mainfile(filepath={str(blend)!r})\n"
        "from relativity_addon import batch\n"
        "batch.enable_addon()\n"
        "from relativity_addon.physics import shipped_luts as lut_data\n"
        "from relativity_addon.blender.pipeline import effect\n"
        "scene = bpy.context.scene\n"
        "scene.relativity.beta = (0.0, 0.0, -0.5)\n"
        "effect.apply(scene)  # works without colour-science\n"
        "print('APPLIED:' + scene.camera.data.type)\n"
        "effect.remove(scene)\n"
        "lut_data.LUT_PATH = '/nonexistent/spectral_luts.npz'\n"
        "lut_data._tables.cache_clear()\n"
        "for image in [i for i in bpy.data.images if i.name.startswith('Relativity')]:\n"
        "    bpy.data.images.remove(image)\n"
        "try:\n"
        "    effect.apply(scene)\n"
        "except effect.RelativityError as error:\n"
        "    print('ERROR:' + str(error))\n"
        f"bpy.ops.wm.save_as_mainfile(filepath={str(tmp_path / 'after.blend')!r})\n" + EXIT_WORKER
    )
    result = subprocess.run([sys.executable, "-c", worker], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    errors = [line for line in result.stdout.splitlines() if line.startswith("ERROR:")]
    print(errors)
    assert "APPLIED:CUSTOM" in result.stdout.splitlines()
    assert len(errors) == 1 and "Doppler colour" in errors[0] and "lookup tables" in errors[0]
    before = _signature(bpy, scene)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "after.blend"))
    after = _signature(bpy, bpy.context.scene)
    after["scene_keys"] = [key for key in after["scene_keys"] if key != "relativity"]  # the settings themselves
    assert after == before
    assert bpy.context.scene.camera.data.type == "PERSP"


def test_material_added_after_apply_is_shifted_at_render(relativity_addon, factory_blender, tmp_path):
    from relativity_addon.physics import spectral

    bpy = factory_blender
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene, camera = dh.emitter_scene(bpy, samples=4)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    effect.apply(scene)
    colour = (0.3, 0.6, 0.2)
    dh.add_emitter_plane(bpy, scene, "Late", (-400.0, 400.0), (-400.0, 400.0), colour, beta=None)
    image = dh.render(bpy, scene, tmp_path / "late.exr")
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    d = 1.0 / (1.0 / np.sqrt(1.0 - 0.25) * (1.0 - view @ np.array([0.0, 0.0, -0.5])))
    expected = spectral.doppler_shift_rgb(colour, d[24, 32])
    print("late material:", image[24, 32], "expected", expected)
    np.testing.assert_allclose(image[24, 32], expected, rtol=0.01)


def test_constant_world_gets_a_uniform_light_map_while_applied(relativity_addon, factory_blender):
    """The Doppler groups make a constant world look varying to Cycles, which then builds its
    1024 x 512 importance map before every render (1.9 s of a 192 x 96 panorama at 1 sample); a
    constant world gets a uniform 16 map while the exact camera is applied and its own settings back
    afterwards; a world with a texture keeps its own."""
    bpy = factory_blender
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    scene, _camera = dh.emitter_scene(bpy)
    world = bpy.data.worlds.new("Constant")
    tree = compat.world_node_tree(world)
    scene.world = world
    world.cycles.sampling_method, world.cycles.sample_map_resolution = "AUTOMATIC", 512
    scene.relativity.beta = (0.0, 0.0, -0.5)
    effect.apply(scene)
    assert (world.cycles.sampling_method, world.cycles.sample_map_resolution) == ("MANUAL", 16)
    effect.remove(scene)
    assert (world.cycles.sampling_method, world.cycles.sample_map_resolution) == ("AUTOMATIC", 512)
    assert not compat.custom_property_keys(world)

    sky = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(sky.outputs[0], tree.nodes["Background"].inputs["Color"])
    effect.apply(scene)
    assert (world.cycles.sampling_method, world.cycles.sample_map_resolution) == ("AUTOMATIC", 512)
    effect.remove(scene)
