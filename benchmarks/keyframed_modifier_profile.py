"""Where the keyframed modifier's evaluation goes (issue 26): the 2M grid of ``artist_chain.py``
on keyframed motion, set up, then the apparent-geometry modifier re-evaluated (the object tagged,
the depsgraph updated, a vertex read) with copies of its node group that differ in one part, in
ONE process, rounds alternating between the variants; each variant's time is printed with its
ratio to the group as built (``as built``) and to the group with Keyframed off (nothing solved).

    python benchmarks/keyframed_modifier_profile.py [--size 2M] [--rounds 5] [--variants ...] [--motion eased]

Variants: ``steps1``/``steps2``/``steps3``/``steps4`` (the closed-form steps; fewer send more
points to the Python path, more cost more), ``single`` (every step reads the first step's
interval: the cost without per-point Sample Index, not the right positions), ``off`` (Keyframed
off), ``capture`` (the captures of the rest positions, nothing solved).
With ``--motion eased`` (Blender's default Bezier keys: the polynomial solve,
``geometry/polynomial_nodes.py``), the variants are ``built``, ``off``, ``onestep`` / ``twosteps``
(``Polynomial One Step`` forced on / off, whether or not the window allows one: what the second
closed-form step costs) and
``transform`` (the polynomial's terms by Transform Points on matrices combined from the same inputs,
as before issue 26's multiply-adds). With ``--motion constant`` (Constant Velocity 0.5c, the closed form
on the lean group: the edges' bound clears the grid), ``folded`` and ``unfolded``: the modifier's
``Folded`` on and off (``uniform_motion.FOLD_LIMIT``). Process CPU time (Blender's threads, not the wait for a
core) is printed beside the wall time.
Times are of the whole modifier (subdivision check, rest, solve, the velocity, the verdict). The
grid's linear keys would get the closed form (``animation.straight_keys``): taken out here.
"""

import argparse
import dataclasses
import os
import statistics
import sys
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import artist_chain  # noqa: E402


def transform_terms(spec):
    """The polynomial's terms ``P_i = C_i p`` by one Transform Point each (a matrix combined from the
    same vector inputs) in place of the multiply-adds, in ``spec`` (changed in place)."""
    from relativity_addon.blender.common.nodes import Node
    from relativity_addon.physics.polynomial_motion import DEGREE

    for power in range(DEGREE + 1):
        entries = {}
        for column, part in enumerate(("X", "Y", "Z", "Offset"), start=1):
            spec.nodes[f"kt_c{power}{column}"] = Node(
                "ShaderNodeSeparateXYZ", {"Vector": f"group.Polynomial {power} {part}"}
            )
            for row, axis in enumerate("XYZ", start=1):
                entries[f"Column {column} Row {row}"] = f"kt_c{power}{column}.{axis}"
        spec.nodes[f"kt_m{power}"] = Node("FunctionNodeCombineMatrix", entries)
        spec.nodes[f"kt_p{power}"] = Node(
            "FunctionNodeTransformPoint", {"Vector": "position.Position", "Transform": f"kt_m{power}.Matrix"}
        )
    for node in spec.nodes.values():
        for key, value in node.inputs.items():
            if isinstance(value, str) and value.startswith("kp_p") and value.endswith("Z.Vector"):
                node.inputs[key] = f"kt_p{value[4]}.Vector"


def variant_group(bpy, name, steps=None, single=False, capture_only=False, transform=False):
    """A copy of the modifier's node group named ``name``, built with ``steps`` steps and (``single``)
    every step's Sample Index at the first step's interval."""
    from relativity_addon.blender.common import nodes as common_nodes
    from relativity_addon.blender.geometry import keyframed_nodes, node_group

    saved = keyframed_nodes.STEPS, keyframed_nodes.Node
    try:
        if steps is not None:
            keyframed_nodes.STEPS = steps
        if single:

            def node(kind, inputs=None, props=None):
                inputs = dict(inputs or {})
                if kind == "GeometryNodeSampleIndex" and str(inputs.get("Index", "")).endswith("_j"):
                    inputs["Index"] = "kf0_j"
                return common_nodes.Node(kind, inputs, props or {})

            keyframed_nodes.Node = node
        spec = node_group.node_group_spec()
    finally:
        keyframed_nodes.STEPS, keyframed_nodes.Node = saved
    if transform:
        transform_terms(spec)
    if capture_only:  # the captures of the rest positions alone: what solving nothing costs
        for capture in ("kf_capture", "kf_capture_whole"):
            spec.nodes[capture].inputs.update({"Seen": "position.Position", "Beta": "position.Position", "Inside": 1.0})
    return common_nodes.build_group(dataclasses.replace(spec, name=name))


def use_group(mod, group):
    """``mod`` on ``group`` with the same input values (read and set by name)."""
    from relativity_addon.blender.common import compat

    old = {item.name: item.identifier for item in mod.node_group.interface.items_tree if item.item_type == "SOCKET"}
    values = {name: compat.modifier_input(mod, identifier) for name, identifier in old.items()}
    # copies: 4.5's vector values are views into the modifier's properties, freed with the group
    values = {name: tuple(v) if hasattr(v, "to_list") or hasattr(v, "__len__") else v for name, v in values.items()}
    mod.node_group = group
    for item in group.interface.items_tree:
        if item.item_type == "SOCKET" and item.in_out == "INPUT" and values.get(item.name) is not None:
            compat.set_modifier_input(mod, item.identifier, values[item.name])


def modifier_input(mod, name):
    from relativity_addon.blender.common import compat

    identifier = next(i.identifier for i in mod.node_group.interface.items_tree if i.name == name)
    return compat.modifier_input(mod, identifier)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="2M")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--variants", default=None)
    parser.add_argument("--motion", default="keyframed", choices=("keyframed", "eased", "constant"))
    options = parser.parse_args()
    eased = options.motion == "eased"
    constant = options.motion == "constant"
    if options.variants is None:
        options.variants = "built,off,twosteps,transform" if eased else "built,off,steps1,steps2,single"
        options.variants = "folded,unfolded" if constant else options.variants
    import bpy

    from relativity_addon import batch
    from relativity_addon.blender.common import compat
    from relativity_addon.blender.geometry import modifier

    batch.enable_addon()
    # linear keys draw a straight line, which the update gives the closed form (animation.straight_keys):
    # the keyframed solve is what this measures
    batch.addon_module("scene.animation").straight_keys = lambda *_args: None
    size = artist_chain.parse_size(options.size)
    scene, _plain, movers, _ = artist_chain.build(bpy, "grid", size, options.motion, None, (64, 48), 4, only="Effect")
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    obj = movers[0]
    depsgraph = bpy.context.evaluated_depsgraph_get()
    artist_chain.read_vertex(bpy, obj, depsgraph)
    mod = modifier.find_modifier(obj)
    built = mod.node_group
    groups = {}
    for name in options.variants.split(","):
        if name in ("built", "off", "folded", "unfolded"):
            groups[name] = built
        elif name.startswith("steps"):
            groups[name] = variant_group(bpy, f"profile {name}", steps=int(name[5:]))
        elif name == "capture":
            groups[name] = variant_group(bpy, "profile capture", capture_only=True)
        elif name == "single":
            groups[name] = variant_group(bpy, "profile single", single=True)
        elif name in ("onestep", "twosteps", "transform"):
            groups[name] = variant_group(bpy, f"profile {name}", transform=name == "transform")
    times = {name: [] for name in groups}
    cpu = {name: [] for name in groups}

    def keyframed_on(value):
        if constant:
            return
        identifier = next(i.identifier for i in mod.node_group.interface.items_tree if i.name == "Keyframed")
        compat.set_modifier_input(mod, identifier, value)

    def one_step(value):
        identifier = next(i.identifier for i in mod.node_group.interface.items_tree if i.name == "Polynomial One Step")
        compat.set_modifier_input(mod, identifier, value)

    if eased:
        print("the grid's own Polynomial One Step:", modifier_input(mod, "Polynomial One Step"))
        print("Polynomial:", modifier_input(mod, "Polynomial"), "Keyframed:", modifier_input(mod, "Keyframed"))
        steps = bool(modifier_input(mod, "Polynomial One Step"))

    with artist_chain.without_addon_handlers(bpy):
        for round_ in range(options.rounds + 1):
            for name, group in groups.items():
                use_group(mod, group)
                keyframed_on(name != "off")
                if eased:
                    one_step({"onestep": True, "twosteps": False}.get(name, steps))
                if constant:
                    modifier.set_inputs(mod, {"Folded": name == "folded"})
                obj.update_tag()
                artist_chain.read_vertex(bpy, obj, depsgraph)  # settle the switch's evaluation
                obj.update_tag()
                start, start_cpu = time.perf_counter(), time.process_time()
                depsgraph.update()
                artist_chain.read_vertex(bpy, obj, depsgraph)
                if round_:  # the first round warms up
                    times[name].append(time.perf_counter() - start)
                    cpu[name].append(time.process_time() - start_cpu)
                keyframed_on(True)
        use_group(mod, built)
        if eased:
            one_step(steps)
    vertices = len(obj.evaluated_get(depsgraph).data.vertices)
    print(f"\nkeyframed modifier, {vertices:,} evaluated vertices, {options.rounds} rounds (load {os.getloadavg()})")
    first = next(iter(times))  # "as built": the first variant's
    base, off = statistics.median(times.get("built", times[first])), statistics.median(times.get("off", [1]))
    for name, values in times.items():
        median, median_cpu = statistics.median(values), statistics.median(cpu[name])
        print(
            f"{name:>9} {median:8.3f}s  {median / base:5.2f}x as built  {median / off:6.2f}x off"
            f"  CPU {median_cpu * 1000:7.1f} ms"
        )


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
