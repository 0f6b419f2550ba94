"""Doppler colour stage of the exact (OSL) camera, in the compositor.

The camera shader multiplies every camera ray's throughput by ``D^4`` (searchlight). The colour
change needs the spectrum, which a camera shader cannot touch, so this stage applies the
spectral Doppler matrix per pixel after the render, with no second render:

- ``ln D`` per pixel comes from the ``relativity_log_doppler`` AOV, written by every material
  at the first camera hit (``materials.doppler_aov_group``), and for the other samples (the
  world, volume scattering) from the pixel centre's direction (``world_doppler``):
  ``D = gamma (1 - beta . k)`` with ``k`` the scene-frame photon direction (the Incoming vector)
  and ``beta`` the observer velocity (docs/physics.md). Computed by Cycles per sample, so it holds
  for every shutter model, depth of field and the Lorentz window, and it follows the velocity
  frame by frame in animation renders. The ``relativity_coverage`` AOV (1 from every writer)
  is the share of samples that wrote it: ``ln D = AOV + (1 - coverage) ln D_pixel``, or, where
  the world writes its own AOV (``world_doppler.problem``), ``AOV / coverage``.
- ``rgb = C exp(-p_cam ln D)`` undoes the shader's ``D^4`` (``p_cam`` = 4 with the searchlight),
  and the output is ``exp(E) gamut_map(N(D) rgb)`` exactly as in the materials
  (``materials.doppler_colour_group``): ``M(D) = exp(a(D)) N(D)`` read from the packed table
  with Map UV (linear between the two nearest texels, clamped at the ends), ``E = a(D)`` with
  searchlight and Doppler, ``4 ln D`` without Doppler (``1 ln D`` for Chang et al.'s
  comparison). All exponents are added before one ``exp`` so that nothing overflows float32.
- Pixels whose material already did the exact blackbody shift (``relativity_colour_done`` AOV,
  written by ``materials``) keep their rendered colour.
- The light of blackbody lamps (Cycles light groups per temperature, ``light_groups.py``) goes
  through the table of its blackbody (``physics/illuminants.py``): a surface it lit sends a
  reflectance times that spectrum. The rest of the pixel goes through the emitters' table.
  Where Cycles' denoiser is on, a Denoise node per group denoises its pass like the Image.
- The light of moving blackbody lights' stand-in lamps (the observed light group,
  ``light_groups.OBSERVED``) is already the illuminant the observer sees: their shader gave each
  surface point the blackbody at ``D_o D_L T`` (``shaders/relativistic_moving_lamp.osl``), which no
  table of one temperature can. What is left is the reflectance's own shift, ``R(lambda D_o)``:
  the pass is scaled per channel by ``r / rho``, ``rho`` the Diffuse Color pass and ``r`` its
  colour relative to white after the emitters' table at ``D`` (``gamut_map(N(D) rho) /
  gamut_map(N(D) 1)``, von Kries: exact for grey, 1 where there is no diffuse colour).
- With the observer at rest in every frame the stage is the identity (``D = 1``) and is muted,
  so that it costs the render nothing (``at_rest_throughout``).

The group is inserted after every Render Layers node of the scene's compositor (a tree is
created if the scene has none); :func:`remove_colour_stage` restores the compositor exactly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import bpy

from ..common import compat, names
from ..common.nodes import Group, Menu, Node, ensure_group, fmath, group_node, vmath
from . import light_groups, lut_images, materials

if TYPE_CHECKING:
    from bpy.types import Image, NodeTree, Scene

    from ..scene.snapshot import Snapshot

COMPOSITOR_GROUP = names.COMPOSITOR_GROUP
COMPOSITOR_GAMUT_MAP = names.COMPOSITOR_GAMUT_MAP_GROUP
SCENE_TREE_NAME = names.COMPOSITOR_SCENE_TREE
SAVED_KEY = names.COMPOSITOR_SAVED_KEY
VALUE_NAMES = ("Use Doppler", "Spectral Searchlight", "Power of D", "Camera Power")
GROUP_INPUTS = ("Lit 1", "Lit 2", "Observed")  # the inputs of light_groups.GROUPS' passes
REFLECTANCE_EPSILON = 1e-4  # below it a Diffuse Color channel counts as none (the factor tends to 1)


def _matrix_nodes(key, image_name, colour):
    """Nodes for ``gamut_map(N(D) colour)`` (``{key}_mapped``) and ``a(D)`` (``{key}_alpha``) read
    from a packed matrix table (``luts``) at the texel position the shared nodes computed."""
    nodes = {f"{key}_lut": Node("CompositorNodeImage", props={"image": image_name})}
    map_inputs, map_props = compat.map_uv_nearest()
    for row in range(3):
        for side in "01":
            texel = f"{key}_row{row}_{side}"
            # z: UV alpha
            nodes[f"{texel}_uv"] = Node("ShaderNodeCombineXYZ", {0: f"u{side}", 1: (row + 0.5) / 3.0, 2: 1.0})
            nodes[texel] = Node(
                "CompositorNodeMapUV",
                {
                    "Image": f"{key}_lut.Image",
                    "UV": f"{texel}_uv",
                    **{name: Menu(value) for name, value in map_inputs.items()},
                },
                map_props,
            )
            nodes[f"{texel}_dot"] = vmath("DOT_PRODUCT", texel, colour)
        nodes[f"{key}_step{row}"] = fmath("SUBTRACT", f"{key}_row{row}_1_dot.Value", f"{key}_row{row}_0_dot.Value")
        nodes[f"{key}_dot{row}"] = fmath("MULTIPLY_ADD", "frac", f"{key}_step{row}", f"{key}_row{row}_0_dot.Value")
    nodes.update(
        {
            f"{key}_split0": Node("CompositorNodeSeparateColor", {0: f"{key}_row0_0"}),
            f"{key}_split1": Node("CompositorNodeSeparateColor", {0: f"{key}_row0_1"}),
            f"{key}_alpha_step": fmath("SUBTRACT", f"{key}_split1.Alpha", f"{key}_split0.Alpha"),
            f"{key}_alpha": fmath("MULTIPLY_ADD", "frac", f"{key}_alpha_step", f"{key}_split0.Alpha"),
            f"{key}_product": Node("ShaderNodeCombineXYZ", {0: f"{key}_dot0", 1: f"{key}_dot1", 2: f"{key}_dot2"}),
            f"{key}_mapped": group_node(COMPOSITOR_GAMUT_MAP, {0: f"{key}_product"}, kind="CompositorNodeGroup"),
            # exp(E) with E = a(D) with the searchlight and Doppler, + (p - p_cam) ln D
            f"{key}_base": Node(
                "ShaderNodeMix", {"Factor": "group.Use Doppler", 4: colour, 5: f"{key}_mapped"}, {"data_type": "VECTOR"}
            ),
            f"{key}_log_gain": fmath("MULTIPLY_ADD", f"{key}_alpha", "group.Spectral Searchlight", "power_term"),
            f"{key}_safe_log_gain": fmath("MINIMUM", f"{key}_log_gain", materials.EXP_LIMIT),
            f"{key}_gain": fmath("EXPONENT", f"{key}_safe_log_gain"),
            f"{key}_shifted": vmath("SCALE", f"{key}_base.Result", scale=f"{key}_gain"),
        }
    )
    return nodes


def _reflectance_shift_nodes():
    """``observed_seen``: the observed light group's pass times the reflectance shift factor
    ``(gamut_map(N(D) rho) + e) / (gamut_map(N(D) 1) rho + e)`` per channel, ``rho`` the Diffuse
    Color pass, ``N`` the emitters' table read at the texels of the ``emit`` nodes (mixed by Use
    Doppler: the pass as rendered without the colour shift and in the spectral passes)."""
    nodes = {}
    for key, colour in (("refl", "group.Diffuse Color"), ("white", (1.0, 1.0, 1.0))):
        for row in range(3):
            for side in "01":
                nodes[f"{key}_row{row}_{side}_dot"] = vmath("DOT_PRODUCT", f"emit_row{row}_{side}", colour)
            low, high = f"{key}_row{row}_0_dot.Value", f"{key}_row{row}_1_dot.Value"
            nodes[f"{key}_step{row}"] = fmath("SUBTRACT", high, low)
            nodes[f"{key}_dot{row}"] = fmath("MULTIPLY_ADD", "frac", f"{key}_step{row}", low)
        nodes[f"{key}_product"] = Node("ShaderNodeCombineXYZ", {i: f"{key}_dot{i}" for i in range(3)})
        nodes[f"{key}_mapped"] = group_node(COMPOSITOR_GAMUT_MAP, {0: f"{key}_product"}, kind="CompositorNodeGroup")
    eps = (REFLECTANCE_EPSILON,) * 3
    nodes.update(
        {
            "refl_top": vmath("ADD", "refl_mapped", eps),
            "white_albedo": vmath("MULTIPLY", "white_mapped", "group.Diffuse Color"),
            "refl_bottom": vmath("ADD", "white_albedo", eps),
            "refl_factor": vmath("DIVIDE", "refl_top", "refl_bottom"),
            "observed_shifted": vmath("MULTIPLY", "group.Observed", "refl_factor"),
            "observed_seen": Node(
                "ShaderNodeMix",
                {"Factor": "group.Use Doppler", 4: "group.Observed", 5: "observed_shifted"},
                {"data_type": "VECTOR"},
            ),
        }
    )
    return nodes


def compositor_group() -> Group:
    scale, offset = lut_images.texture_u_scale_offset(lut_images.DOPPLER_LOG10_RANGE)
    nodes = {
        # ln D per pixel from the materials' AOV (materials.doppler_aov_group), over the share
        # ``coverage`` of samples that wrote it. With World Directions = 1 the other samples (the
        # world, a camera ray scattered in a volume) take the pixel centre's ln D from the image
        # world_doppler writes: ln D = AOV + (1 - coverage) ln D_pixel. With 0 (the world writes the
        # AOV itself), the mean over the writing samples: AOV / coverage.
        "world_image": Node("CompositorNodeImage", props={"image": names.WORLD_DOPPLER_IMAGE}),
        "world_split": Node("CompositorNodeSeparateColor", {0: "world_image.Image"}),
        "uncovered": fmath("SUBTRACT", 1.0, "group.Coverage"),
        "world_share": fmath("MULTIPLY", "uncovered", "group.World Directions"),
        "world_term": fmath("MULTIPLY", "world_share", "world_split.Red"),
        "sum": fmath("ADD", "group.Log Doppler", "world_term"),
        "weight": fmath("ADD", "group.Coverage", "world_share"),
        "coverage": fmath("MAXIMUM", "weight", 1e-3),
        "ln_d": fmath("DIVIDE", "sum", "coverage"),
        # Linear interpolation between the two nearest texels, done here with two nearest-texel
        # reads (Blender 4.5's Map UV has no bilinear mode nor an Extend border): x is the texel
        # coordinate, clamped to the table (= Extend), i0 the left texel, at most size - 2.
        "x_raw": fmath(
            "MULTIPLY_ADD", "ln_d", scale * lut_images.LUT_SIZE / materials.LN10, offset * lut_images.LUT_SIZE - 0.5
        ),
        "x_low": fmath("MAXIMUM", "x_raw", 0.0),
        "x": fmath("MINIMUM", "x_low", lut_images.LUT_SIZE - 1.0),
        "i_floor": fmath("FLOOR", "x"),
        "i0": fmath("MINIMUM", "i_floor", lut_images.LUT_SIZE - 2.0),
        "frac": fmath("SUBTRACT", "x", "i0"),
        "u0": fmath("MULTIPLY_ADD", "i0", 1.0 / lut_images.LUT_SIZE, 0.5 / lut_images.LUT_SIZE),
        "u1": fmath("ADD", "u0", 1.0 / lut_images.LUT_SIZE),
        "power": fmath("SUBTRACT", "group.Power of D", "group.Camera Power"),
        "power_term": fmath("MULTIPLY", "power", "ln_d"),
        # The light of blackbody lamps (light_groups.py: one light group per temperature) is read
        # through its temperature's table, the rest of the pixel through the emitters' table.
        # (the light groups' passes denoised like the Image where Cycles' denoiser is on: _add_denoisers)
        "lit_slots": vmath("ADD", "group.Lit 1", "group.Lit 2"),
        "lit": vmath("ADD", "lit_slots", "group.Observed"),
        "rest": vmath("SUBTRACT", "group.Image", "lit"),
        "other": vmath("MAXIMUM", "rest", (0.0, 0.0, 0.0)),  # the passes' noise may push it below 0
    }
    nodes.update(_matrix_nodes("emit", lut_images.DOPPLER_LUT_NAME, "other"))
    nodes.update(_reflectance_shift_nodes())
    for slot, image_name in enumerate(lut_images.ILLUMINANT_LUT_NAMES, start=1):
        nodes.update(_matrix_nodes(f"lit{slot}", image_name, f"group.Lit {slot}"))
    nodes.update(
        {
            "lit_shifted": vmath("ADD", "lit1_shifted", "lit2_shifted"),
            "lit_seen": vmath("ADD", "lit_shifted", "observed_seen.Result"),
            "shifted": vmath("ADD", "emit_shifted", "lit_seen"),
            "kept": Node(
                "ShaderNodeMix",
                {"Factor": "group.Done", 4: "shifted", 5: "group.Image"},
                {"data_type": "VECTOR", "clamp_factor": True},
            ),
            "source_split": Node("CompositorNodeSeparateColor", {0: "group.Image"}),
            "out_split": Node("ShaderNodeSeparateXYZ", {0: "kept.Result"}),
            "out": Node(
                "CompositorNodeCombineColor",
                {0: "out_split.X", 1: "out_split.Y", 2: "out_split.Z", 3: "source_split.Alpha"},
            ),
        }
    )
    return Group(
        COMPOSITOR_GROUP,
        "CompositorNodeTree",
        (
            ("Image", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0)),
            ("Log Doppler", "NodeSocketFloat", 0.0),
            ("Done", "NodeSocketFloat", 0.0),
            ("Coverage", "NodeSocketFloat", 1.0),  # unlinked: every sample wrote ln D
            ("Lit 1", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0)),  # the light groups' passes
            ("Lit 2", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0)),
            ("Observed", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0)),  # the observed light group's pass
            ("Diffuse Color", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0)),  # Cycles' pass, with the observed group
            ("World Directions", "NodeSocketFloat", 0.0),  # 1: the image has the samples' ln D without AOV
        )
        + tuple((name, "NodeSocketFloat", 0.0) for name in VALUE_NAMES),
        (("Image", "NodeSocketColor", "out"),),
        nodes,
    )


def ensure_world_image(size: tuple[int, int] = (1, 1)) -> Image:
    """The float image of the pixels' world ``ln D`` (``world_doppler`` writes it), of ``size``."""
    image = bpy.data.images.get(names.WORLD_DOPPLER_IMAGE)
    if image is not None and (tuple(image.size) != tuple(size) or not image.is_float):
        if tuple(size) == (1, 1):
            return image  # any size will do for the group's node
        image.scale(*size)
    if image is None:
        image = bpy.data.images.new(names.WORLD_DOPPLER_IMAGE, *size, alpha=True, float_buffer=True)
        image.colorspace_settings.is_data = True  # ln D, not a colour
    return image


def ensure_compositor_group() -> NodeTree:
    lut_images.ensure_doppler_matrix_lut()
    for name in lut_images.ILLUMINANT_LUT_NAMES:
        if bpy.data.images.get(name) is None:
            lut_images.ensure_illuminant_lut(name, 0.0)
    ensure_world_image()
    version = (names.GROUP_VERSION_KEY, names.COMPOSITOR_GROUPS_VERSION)
    ensure_group(materials.gamut_map_group(COMPOSITOR_GAMUT_MAP, "CompositorNodeTree"), *version)
    return ensure_group(compositor_group(), *version)


def colour_stage_values(snap: Snapshot) -> dict[str, Any]:
    """Values of the compositor group's flag inputs, from the snapshot."""
    values = materials.settings_values(snap)
    values = {name: values[name] for name in VALUE_NAMES if name in values}
    if _stage_mode["mode"] == "PASS_THROUGH":  # spectral passes: the rendered values unchanged
        values.update({"Use Doppler": 0.0, "Spectral Searchlight": 0.0, "Camera Power": values["Power of D"]})
    return values


# What the stage outputs: COLOUR (the fast mode) or PASS_THROUGH (a spectral pass).
_stage_mode = {"mode": "COLOUR"}


def set_stage_mode(mode: str) -> None:
    """Switch the stage's output for the next renders (written at the next sync)."""
    if mode not in ("COLOUR", "PASS_THROUGH"):
        raise ValueError(mode)
    _stage_mode["mode"] = mode


def _inserted_nodes(scene):
    tree = compat.compositor_tree(scene)
    if tree is None or not is_applied(scene):
        return tree, []
    names = [record["group_node"] for record in scene[SAVED_KEY]["inserted"]]
    return tree, [tree.nodes[name] for name in names if name in tree.nodes]


def write_colour_stage(scene: Scene, snap: Snapshot) -> bool:
    """Write the effect flags into the inserted group nodes (only where they changed).

    ``D`` itself comes from the AOV, computed by Cycles for every frame. The flags are written
    at every sync (a setting's update callback and depsgraph_update_post), not only before a render: Blender's
    animation render shows its compositor what a render_pre or frame_change_pre handler wrote
    one frame late (measured with 5.0.1). They are plain values, not drivers, so the file
    renders the same without the add-on.
    """
    tree, nodes = _inserted_nodes(scene)
    if not nodes:
        return False
    if _stage_mode["mode"] == "PASS_THROUGH":
        # spectral passes: the lamps' colours are spectral values now, the groups stay as they were
        # (the stage passes every part through; their denoisers still match the denoised Image)
        temperatures = tuple(
            float(image.get(names.ILLUMINANT_KEY, 0.0)) if image is not None else 0.0
            for image in map(bpy.data.images.get, lut_images.ILLUMINANT_LUT_NAMES)
        )
    else:
        temperatures = light_groups.assign(scene, snap.lit_groups, light_groups.stand_ins(scene, snap.observed_lights))
        for name, temperature in zip(lut_images.ILLUMINANT_LUT_NAMES, temperatures, strict=True):
            lut_images.ensure_illuminant_lut(name, temperature)
    observed = any(obj.lightgroup == light_groups.OBSERVED for obj in scene.objects)
    light_groups.mute_observed_branch(nodes)
    values = colour_stage_values(snap)
    held = light_groups.KEY in scene  # else the view layers have no slot groups to link
    bypass = _stage_mode["mode"] == "COLOUR" and at_rest_throughout(scene, snap)
    records = []
    guided = set()  # view layers whose light groups are denoised: they need the denoising data passes
    for record in scene[SAVED_KEY]["inserted"]:
        node, layers = tree.nodes.get(record["group_node"]), tree.nodes.get(record["layers"])
        if node is None:
            continue
        for name, value in values.items():
            if node.inputs[name].default_value != value:
                node.inputs[name].default_value = value
        view_layer = scene.view_layers.get(layers.layer) if layers is not None else None
        denoised = bool(scene.cycles.use_denoising and view_layer is not None and view_layer.cycles.use_denoising)
        # muted: the pass as rendered
        mutes = [not denoised or not temperature for temperature in temperatures] + [not denoised or not observed]
        if view_layer is not None and not all(mutes):
            guided.add(view_layer.name)
        records.append((record, node, layers, mutes))
    _store_passes(scene, guided, observed)
    # Denoised light groups are recombined with the Image denoised apart: the stage is then no
    # identity to the last bit even at D = 1 (max(Image - Lit, 0) + Lit), and stays on.
    bypass = bypass and not guided
    for _record, node, _layers, _mutes in records:
        if node.mute != bypass:  # muted, the group passes its Image through
            node.mute = bypass
    _skip_own_compositor(scene, bypass)
    for record, node, layers, mutes in records:
        for slot, (name, mute) in enumerate(zip(record.get("denoisers", ()), mutes, strict=False), 1):
            denoiser = tree.nodes.get(name)
            if denoiser is None:
                continue
            if held and layers is not None:
                _link_light_group_pass(tree, layers, denoiser, slot, guides=not mute)
            if denoiser.mute != mute:
                denoiser.mute = mute
        if held and layers is not None and observed:
            light_groups.link_diffuse_colour(tree, layers, node)
    return True


def _store_passes(scene, guided, observed):
    """The denoising data passes (normal, albedo: the light groups' denoisers' guides) only on the
    view layers in ``guided``, and the Diffuse Color pass (the observed group's reflectance shift)
    only while the observed light group has lamps; otherwise as the user had them: Cycles writes
    them at every camera sample's first hit, a cost of every sample where nothing reads them."""
    saved = scene[SAVED_KEY]
    for view_layer in scene.view_layers:
        for key, owner, prop, needed in (
            ("denoising_passes", view_layer.cycles, "denoising_store_passes", view_layer.name in guided),
            ("diffuse_colour_pass", view_layer, "use_pass_diffuse_color", observed),
        ):
            stored = saved.get(key, {})
            wanted = bool(stored.get(view_layer.name)) or needed
            if view_layer.name in stored and getattr(owner, prop) != wanted:
                setattr(owner, prop, wanted)


def _skip_own_compositor(scene, bypass):
    """With the stage muted in a compositor tree the add-on created (the scene had none), the
    compositor would only copy the render: it is switched off then (its run cost 5.2 about 0.3 s
    of wall clock per render), and on again with the stage."""
    saved = scene[SAVED_KEY]
    if not saved.get("created_tree"):
        return
    wanted = not bypass  # Remove gives back the user's setting (the scene had no tree for it to run)
    if scene.render.use_compositing != wanted:
        scene.render.use_compositing = wanted


def at_rest_throughout(scene: Scene, snap: Snapshot) -> bool:
    """Whether the observer is at rest in every frame, with no moving light and no object moving
    with the camera (its render is laid over this one by the compositor): the velocity setting
    (not the camera's animation) is zero and neither keyed nor driven. Then ``D = 1`` at every
    pixel and the stage would give back the rendered values (to its tables' rounding, 2e-4), so
    it is muted and costs nothing (about 1.6 us of CPU per pixel with 5.2's compositor). A speed
    that changes from frame to frame keeps the stage on throughout: an animation render shows the
    compositor what a handler wrote one frame late (``write_colour_stage``)."""
    if snap.velocity_source == "CAMERA_ANIMATION" or snap.speed != 0.0 or snap.moving_lights:
        return False
    if snap.cockpit:  # the compositor lays the cockpit over the render (camera/cockpit.py)
        return False
    animation = scene.animation_data
    if animation is None:
        return True
    if len(animation.nla_tracks):
        return False
    paths = [curve.data_path for curve in compat.action_fcurves(animation)]
    paths += [driver.data_path for driver in animation.drivers]
    return not any(path.startswith("relativity.") for path in paths)


def _add_denoisers(tree, layers, node):
    """Per light group, a Denoise node between its pass and the stage (``node``), guided by the
    denoising data passes: Cycles' denoiser denoises the Image but not the light groups' passes,
    whose noise would come back with the rest of the pixel. Muted where not needed."""
    added = []
    for slot in range(1, len(light_groups.GROUPS) + 1):
        denoiser = tree.nodes.new("CompositorNodeDenoise")
        denoiser.name = denoiser.label = f"{node.name} Denoise {slot}"
        denoiser.location = (node.location.x - 200.0, node.location.y - 150.0 * slot)
        denoiser.mute = True
        tree.links.new(denoiser.outputs["Image"], node.inputs[GROUP_INPUTS[slot - 1]])
        _link_light_group_pass(tree, layers, denoiser, slot)
        added.append(denoiser.name)
    return added


def _link_light_group_pass(tree, layers, denoiser, slot, guides=True):
    """Link light group ``slot``'s pass into ``denoiser``, and with ``guides`` the denoising data
    passes (the Render Layers node shows a new light group's output, or the data passes switched
    on, only once it is updated; without the passes it has no such outputs)."""
    wanted = [(f"Combined_{light_groups.GROUPS[slot - 1]}", "Image")]
    if guides:
        wanted += [("Denoising Normal", "Normal"), ("Denoising Albedo", "Albedo")]
    missing = [(output, input_name) for output, input_name in wanted if not denoiser.inputs[input_name].is_linked]
    if not missing:
        return
    layers.update()
    outputs = layers.outputs
    for output_name, input_name in missing:
        if output_name in outputs:
            tree.links.new(outputs[output_name], denoiser.inputs[input_name])


def write_world_directions(scene: Scene, value: float) -> bool:
    """1: the samples without ln D AOV take the world image's ln D; 0: the world writes the AOV.
    False if an inserted group has no such input (a file set up before it: set up again)."""
    _tree, nodes = _inserted_nodes(scene)
    sockets = [node.inputs.get("World Directions") for node in nodes]
    if not nodes or None in sockets:
        return False
    for socket in sockets:
        if socket.default_value != value:
            socket.default_value = value
    return True


def is_applied(scene: Scene) -> bool:
    return SAVED_KEY in scene


def apply_colour_stage(scene: Scene, snap: Snapshot) -> None:
    """Insert the Doppler colour group after the scene's Render Layers nodes and write its flags."""
    group = ensure_compositor_group()
    if not is_applied(scene):
        saved = {
            "tree": compat.compositor_tree(scene).name if compat.compositor_tree(scene) else "",
            "use_compositing": scene.render.use_compositing,
            "added_aovs": [],
            "inserted": [],
            "created_tree": "",
        }
        tree = compat.compositor_tree(scene)
        if tree is None:
            tree = compat.new_compositor_tree(scene, SCENE_TREE_NAME)
            saved["created_tree"] = tree.name
        light_groups.hold(scene)
        # the denoising data passes (the light groups' denoisers' guides) as the user had them,
        # switched on where they are needed (_store_passes)
        saved["denoising_passes"] = {layer.name: layer.cycles.denoising_store_passes for layer in scene.view_layers}
        saved["diffuse_colour_pass"] = {layer.name: layer.use_pass_diffuse_color for layer in scene.view_layers}
        for view_layer in scene.view_layers:
            for aov_name in (materials.DONE_AOV, materials.LOG_DOPPLER_AOV, materials.COVERAGE_AOV):
                if aov_name not in view_layer.aovs:
                    aov = view_layer.aovs.add()
                    aov.name = aov_name
                    aov.type = "VALUE"
                    saved["added_aovs"].append([view_layer.name, aov_name])
        # (not a Render Layers node of another scene: the cockpit's, camera/cockpit.py, is at rest)
        for layers in [
            node
            for node in tree.nodes
            if node.bl_idname == "CompositorNodeRLayers" and getattr(node, "scene", None) in (None, scene)
        ]:
            image = layers.outputs["Image"]
            targets = [(link.to_node.name, link.to_socket.identifier) for link in image.links]
            node = tree.nodes.new("CompositorNodeGroup")
            node.node_tree = group
            node.name = node.label = f"{COMPOSITOR_GROUP} {layers.name}"
            node.location = (layers.location.x + 250.0, layers.location.y)
            tree.links.new(image, node.inputs["Image"])
            for aov_name, socket_name in (
                (materials.DONE_AOV, "Done"),
                (materials.LOG_DOPPLER_AOV, "Log Doppler"),
                (materials.COVERAGE_AOV, "Coverage"),
            ):
                aov_output = layers.outputs.get(aov_name)
                if aov_output is not None:
                    tree.links.new(aov_output, node.inputs[socket_name])
            for to_node, to_socket in targets:
                socket = next(s for s in tree.nodes[to_node].inputs if s.identifier == to_socket)
                tree.links.new(node.outputs["Image"], socket)
            saved["inserted"].append(
                {
                    "group_node": node.name,
                    "layers": layers.name,
                    "targets": targets,
                    "denoisers": _add_denoisers(tree, layers, node),
                }
            )
        scene.render.use_compositing = True
        scene[SAVED_KEY] = saved
    write_colour_stage(scene, snap)


def remove_colour_stage(scene: Scene) -> bool:
    """Restore the compositor (tree, links, AOVs, the compositing switch) exactly."""
    if not is_applied(scene):
        return False
    saved = scene[SAVED_KEY].to_dict()
    tree = compat.compositor_tree(scene)
    if tree is not None:
        for record in saved["inserted"]:
            for name in [record["group_node"], *record.get("denoisers", ())]:
                node = tree.nodes.get(name)
                if node is not None:
                    tree.nodes.remove(node)
            layers = tree.nodes.get(record["layers"])
            for to_node, to_socket in record["targets"]:
                target = tree.nodes.get(to_node)
                if layers is None or target is None:
                    continue
                socket = next((s for s in target.inputs if s.identifier == to_socket), None)
                if socket is not None:
                    tree.links.new(layers.outputs["Image"], socket)
    light_groups.release(scene)
    for name, stored in saved.get("denoising_passes", {}).items():
        view_layer = scene.view_layers.get(name)
        if view_layer is not None:
            view_layer.cycles.denoising_store_passes = stored
    for name, stored in saved.get("diffuse_colour_pass", {}).items():
        view_layer = scene.view_layers.get(name)
        if view_layer is not None:
            view_layer.use_pass_diffuse_color = stored
    for view_layer_name, aov_name in saved["added_aovs"]:
        view_layer = scene.view_layers.get(view_layer_name)
        if view_layer is not None and aov_name in view_layer.aovs:
            view_layer.aovs.remove(view_layer.aovs[aov_name])
    compat.restore_compositor_tree(scene, saved["tree"])
    if saved["created_tree"]:
        created = bpy.data.node_groups.get(saved["created_tree"])
        if created is not None and created.users == 0:
            bpy.data.node_groups.remove(created)
    scene.render.use_compositing = saved["use_compositing"]
    del scene[SAVED_KEY]
    return True
