"""Does the modifier's fixed cost per mesh grow with its node group's size? Timed in one process.

    python benchmarks/lean_group.py [--size 2M] [--rounds 3] [--render]

artist_chain.py's 1,000-object scene (988 grids of 2,025 vertices, Constant Velocity 0.5c,
tessellation at its default: the edges' bound clears every grid) is set up. Then, in alternating
rounds, every applied mesh's modifier is given one of these groups, every mesh tagged and the
depsgraph evaluated as the render's does it (handlers out; process CPU time counts Blender's
threads, which waiting for a core does not):

- ``full``: the add-on's group as built (``node_group.node_group_spec``);
- ``path, full interface``: a group holding only the nodes the constant closed form with a clearing
  bound runs (the rest positions stored, the closed form's Set Position, the velocity and the
  verdict stored), with the full group's interface;
- ``path, own inputs``: the same nodes with only the inputs they read;
- ``tiny``: a Set Position by an offset and one stored attribute (a plain scene's modifier);
- ``off``: the modifiers switched off.

Each variant's modifiers get every input's value by name from the full group's. ``--render`` also
renders the scene (64x48, 4 samples) with each variant, the plain scene beside it. Medians of the
rounds; on a loaded machine read the CPU times and the ratios measured side by side.
"""

import argparse
import os
import statistics
import sys
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import artist_chain  # noqa: E402


def path_spec(name, interface):
    """The nodes the constant closed form with a clearing bound runs: the add-on's lean group
    (``node_group.lean_node_group_spec``) under another name and interface."""
    import dataclasses

    from relativity_addon.blender.geometry import node_group

    return dataclasses.replace(node_group.lean_node_group_spec(), name=name, inputs=interface)


def tiny_spec(name):
    from relativity_addon.blender.common.nodes import Group, Literal, Node, vmath

    nodes = {
        "position": Node("GeometryNodeInputPosition"),
        "offset": vmath("ADD", "position.Position", (0.01, 0.0, 0.0)),
        "moved": Node("GeometryNodeSetPosition", {"Geometry": "group.Geometry", "Position": "offset.Vector"}),
        "stored": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "moved.Geometry", "Name": Literal("tiny"), "Value": "position.Position"},
            {"data_type": "FLOAT_VECTOR", "domain": "POINT"},
        ),
    }
    return Group(
        name,
        "GeometryNodeTree",
        (("Geometry", "NodeSocketGeometry", None),),
        (("Geometry", "NodeSocketGeometry", "stored.Geometry"),),
        nodes,
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="2M")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--render", action="store_true")
    options = parser.parse_args()

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    from relativity_addon.blender.common import compat, names
    from relativity_addon.blender.common.nodes import build_group
    from relativity_addon.blender.geometry import modifier, node_group

    load = os.getloadavg()
    print(f"Blender {bpy.app.version_string}, load average at start: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    size = artist_chain.parse_size(options.size)
    effect_scene, plain_scene, movers, _plain = artist_chain.build(bpy, "objects", size, "constant", None, (64, 48), 4)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}, "Set Up failed"
    bpy.context.evaluated_depsgraph_get()
    modifiers = [modifier.find_modifier(obj) for obj in movers]
    full = modifiers[0].node_group
    full_spec = node_group.node_group_spec()
    used = {"Geometry", "Seen Velocity", "Cache", *node_group.CLOSED_FORM_INPUTS, "Inverse Gamma Squared"}
    groups = {
        "full": full,
        "path, full interface": build_group(path_spec("Lean full interface", full_spec.inputs)),
        "path, own inputs": build_group(
            path_spec("Lean own inputs", tuple(item for item in full_spec.inputs if item[0] in used))
        ),
        "tiny": build_group(tiny_spec("Tiny")),
    }

    def identifiers(group):
        return {
            item.name: item.identifier
            for item in group.interface.items_tree
            if item.item_type == "SOCKET" and item.in_out == "INPUT" and item.name != "Geometry"
        }

    full_ids = identifiers(full)

    def plain(value):  # not a view into the modifier's properties, which a new group frees
        return tuple(value) if hasattr(value, "__len__") else value

    values = [{name: plain(compat.modifier_input(mod, ident)) for name, ident in full_ids.items()} for mod in modifiers]
    for group in groups.values():
        group.use_fake_user = True

    def give(label):
        group = groups["full" if label == "off" else label]
        ids = identifiers(group)
        for mod, kept in zip(modifiers, values, strict=True):
            if mod.node_group != group:
                mod.node_group = group
            for name, ident in ids.items():
                if kept.get(name) is not None:
                    compat.set_modifier_input(mod, ident, kept[name])
            mod.show_viewport = mod.show_render = label != "off"
        bpy.context.evaluated_depsgraph_get()

    def evaluation():
        for obj in movers:
            obj.update_tag()
        wall, cpu = time.perf_counter(), time.process_time()
        bpy.context.evaluated_depsgraph_get()
        return time.perf_counter() - wall, time.process_time() - cpu

    def render(scene):
        wall, cpu = time.perf_counter(), time.process_time()
        bpy.ops.render.render(scene=scene.name)
        return time.perf_counter() - wall, time.process_time() - cpu

    labels = [*groups, "off"]
    evaluations = {label: [] for label in labels}
    renders = {label: [] for label in ["plain", *labels]}
    probe = movers[len(movers) // 2]
    with artist_chain.without_addon_handlers(bpy):
        for _round in range(options.rounds):
            for label in labels:
                give(label)
                if label in ("full", "path, full interface", "path, own inputs"):
                    mesh = probe.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
                    print(f"  {label}: probe vertex {tuple(round(v, 5) for v in mesh.vertices[7].co)}")
                evaluations[label].append(evaluation())
                if options.render:
                    renders[label].append(render(effect_scene))
            if options.render:
                renders["plain"].append(render(plain_scene))
        give("full")

    print(f"\n{len(movers)} meshes, {options.rounds} rounds; the modifiers evaluated again (every mesh tagged):")
    for label, rows in evaluations.items():
        wall = statistics.median(w for w, _c in rows)
        cpu = statistics.median(c for _w, c in rows)
        nodes = len(groups[label].nodes) if label in groups else 0
        print(f"  {label:<22} {nodes:4d} nodes  wall {wall * 1e3:7.1f} ms  process CPU {cpu * 1e3:7.1f} ms")
    if options.render:
        print("F12 (64x48, 4 samples):")
        for label, rows in renders.items():
            wall = statistics.median(w for w, _c in rows)
            cpu = statistics.median(c for _w, c in rows)
            ratio = statistics.median(w / p for (w, _c), (p, _pc) in zip(rows, renders["plain"], strict=True))
            print(f"  {label:<22} wall {wall:7.3f} s ({ratio:.2f}x plain)  process CPU {cpu:7.3f} s")
    load = os.getloadavg()
    print(f"load average at end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    del names
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat as _compat

    _compat.run_main(main)
