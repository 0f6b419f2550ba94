"""Render time of the bounce correction between moving objects (``lights/interreflection.py``).

    .venv-4.5/bin/python benchmarks/bounce_cost.py [--samples 256] [--scale 2] [--rounds 4]
    .venv-4.5/bin/python benchmarks/bounce_cost.py --movers 2,8,32 [--shared] [--samples 64] [--scale 1]

The scene of tests/blender/lights/test_interreflection.py (a sphere and a panel 0.5c apart, one
point lamp, one diffuse bounce, camera at rest), Set Up by the add-on, Cycles on the CPU, rendered
alternately per round in seven set-ups so that load from other processes hits them alike:

- **SVM**: Cycles' default shading, the correction kept out (the bounce uncorrected, 1.12x the physics);
- **SVM + factor**: the add-on's node form (``lights/bounce_nodes.py``) on both objects' materials;
- **SVM + factor, camera gate**: the node form's output behind a Mix Shader on Is Camera Ray whose
  camera side is the surface unchanged (the same image): whether SVM's jump over a mix input of
  weight zero skips the factor's nodes on camera rays;
- **SVM + factor, math only**: the node form with its box lookup and ``F`` evaluated on every ray
  (SVM has no branch that skips them), into one copy of the closure at weight 1 (``F > -1``)
  instead of eight at ``F / 8``: the nodes' cost without the copies (the image is uncorrected);
- **SVM + factor, copies only**: the eight copies at weight 1/8 each, ``F`` unused (Cycles drops
  the nodes nothing uses): the copies' cost without the nodes (the image is uncorrected);
- **OSL, no factor**: Open Shading Language on, the correction kept out (what OSL alone costs);
- **OSL + factor**: Open Shading Language on, the add-on's script node on both objects' materials.

With ``--movers N,M,...`` it measures instead how the cost grows with the number of moving
objects: the test's two plus ``N - 2`` small moving spheres (the same white material, each with
its own velocity, or with ``--shared`` one velocity and rotation for all the extra ones) far
behind the camera (they add no visible light), per count four set-ups rendered alternately
(**SVM**, **SVM + factor**, **OSL**, **OSL + factor**; the correction kept out where named so),
and for each: the time of Set Up (``effect.apply``), of a sync with nothing changed and of one
after a velocity changed, the nodes the scene's bounce group runs (its groups' nodes counted
inside), and the render time over the same round's SVM render. ``--limit N`` sets the node
form's limit on moving objects (``interreflection.MAX_NODE_MOVERS``) to measure it past the add-on's.

Prints each render's time, its ratio to the same round's SVM time, the median ratio over the
rounds, the factors over their own shading alone, and the load average before and after. Blender's
user resources in a fresh folder (``user_resources.py``); the process ends with ``os._exit`` after
printing, as bpy 4.5 can sit idle in its exit (removing its own temporary folders first).
"""

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [
    ROOT,
    os.path.join(ROOT, "tests"),
    os.path.join(ROOT, "tests", "blender", "camera"),
    os.path.join(ROOT, "tests", "blender", "lights"),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--scale", type=int, default=2, help="resolution over the test's 128 x 96")
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--movers", default="", help="numbers of moving objects, e.g. 2,8,32 (the growth)")
    parser.add_argument("--shared", action="store_true", help="the extra movers share one velocity and rotation")
    parser.add_argument("--limit", type=int, default=0, help="the node form's limit (0: the add-on's)")
    options = parser.parse_args()
    if options.movers:
        _growth(options)
        return

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    import test_interreflection as case

    from relativity_addon.blender.lights import interreflection
    from relativity_addon.blender.pipeline import effect

    case.RESOLUTION = (128 * options.scale, 96 * options.scale)
    case.SAMPLES = options.samples
    own_reason = interreflection._reason
    setups = {
        "SVM": (False, lambda *args: "kept out", None),
        "SVM + factor": (False, own_reason, None),
        "SVM + factor, camera gate": (False, own_reason, "camera gate"),
        "SVM + factor, math only": (False, own_reason, "math only"),
        "SVM + factor, copies only": (False, own_reason, "copies only"),
        "OSL, no factor": (True, lambda *args: "kept out", None),
        "OSL + factor": (True, own_reason, None),
    }
    print(f"load average before: {os.getloadavg()}")
    print(f"{case.RESOLUTION[0]} x {case.RESOLUTION[1]}, {options.samples} samples, 0.5c apart")
    ratios = {name: [] for name in setups}
    out = tempfile.mkdtemp(prefix="bounce_cost_")
    beta = np.array([-case.EACH, 0.0, 0.0])
    for round_index in range(options.rounds):
        times = {}
        for name, (use_osl, reason, variant) in setups.items():
            bpy.ops.wm.read_factory_settings(use_empty=True)
            scene, _ = case._scene(bpy, beta, -beta)
            scene.cycles.shading_system = use_osl
            interreflection._reason = reason
            effect.apply(scene)
            _rewire(bpy, variant)
            carrying = sum(interreflection.MATERIAL_KEY in m for m in bpy.data.materials)
            scene.render.filepath = os.path.join(out, f"{round_index}.exr")
            scene.render.image_settings.file_format = "OPEN_EXR"
            start = time.perf_counter()
            bpy.ops.render.render(write_still=True)
            times[name] = time.perf_counter() - start
            carrying = max(carrying, sum(interreflection.MATERIAL_KEY in m for m in bpy.data.materials))
            effect.remove(scene)
            interreflection._reason = own_reason
            print(f"round {round_index}, {name}: {times[name]:.2f} s (materials with the factor: {carrying})")
        for name in setups:
            ratios[name].append(times[name] / times["SVM"])
        print("  over SVM: " + ", ".join(f"{name} {times[name] / times['SVM']:.3f}" for name in setups))
    print("median over SVM: " + ", ".join(f"{name} {statistics.median(r):.3f}" for name, r in ratios.items()))
    factor = [b / a for a, b in zip(ratios["OSL, no factor"], ratios["OSL + factor"], strict=True)]
    print(f"median OSL + factor over OSL, no factor: {statistics.median(factor):.3f}")
    print(f"median SVM + factor over SVM: {statistics.median(ratios['SVM + factor']):.3f}")
    print(f"load average after: {os.getloadavg()}", flush=True)
    sys.stdout.flush()
    shutil.rmtree(out, ignore_errors=True)
    shutil.rmtree(getattr(user_resources, "FOLDER", out), ignore_errors=True)  # os._exit skips atexit
    os._exit(0)  # bpy 4.5 can sit idle in exit() after the renders


def _extra_movers(bpy, scene, count, shared):
    """``count`` small moving spheres with the scene's white material, far behind the camera (no
    visible light), each with its own velocity (or one for all: ``shared``)."""

    import camera_helpers as ch

    white = bpy.data.materials["White"]
    for index in range(count):
        row, column = divmod(index, 8)
        location = (-14.0 + 4.0 * column, -40.0 - 4.0 * row, -4.0 + 2.0 * (index % 3))
        sphere = ch.add_sphere(bpy, scene, location, 0.3, white, f"Extra {index}", 16, 8)
        sphere.rotation_euler = (0.0, 0.0, 0.0 if shared else 0.1 * index)
        sphere.relativity.enabled = True
        sphere.relativity.motion = "CONSTANT"
        speed = 0.2 if shared else 0.05 + 0.5 * index / max(count, 1)
        angle = 0.0 if shared else 0.7 * index
        sphere.relativity.beta = (speed * np.cos(angle), 0.0, speed * np.sin(angle))
    bpy.context.view_layer.update()


def _nodes_run(bpy, scene):
    """Nodes the scene's bounce group runs per shading point, its group nodes counted inside."""
    from relativity_addon.blender.common import names

    def count(tree):
        total = 0
        for node in tree.nodes:
            if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
                total += count(node.node_tree)
            elif node.bl_idname not in ("NodeGroupInput", "NodeGroupOutput", "NodeReroute", "NodeFrame"):
                total += 1
        return total

    name = scene.get(names.BOUNCE_GROUP_KEY)
    tree = bpy.data.node_groups.get(name) if isinstance(name, str) else None
    return count(tree) if tree is not None else 0


def _growth(options):
    """Set Up, sync and render time against the number of moving objects (module doc)."""
    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    import test_interreflection as case

    from relativity_addon.blender.lights import interreflection
    from relativity_addon.blender.pipeline import effect

    case.RESOLUTION = (128 * options.scale, 96 * options.scale)
    case.SAMPLES = options.samples
    if options.limit and hasattr(interreflection, "MAX_NODE_MOVERS"):
        interreflection.MAX_NODE_MOVERS = options.limit  # the node form measured past the add-on's limit
    own_reason = interreflection._reason
    kept_out = lambda *args: "kept out"  # noqa: E731
    setups = {"SVM": (False, kept_out), "SVM + factor": (False, own_reason), "OSL": (True, kept_out)}
    setups["OSL + factor"] = (True, own_reason)
    counts = [int(n) for n in options.movers.split(",")]
    print(f"load average before: {os.getloadavg()}")
    print(
        f"{case.RESOLUTION[0]} x {case.RESOLUTION[1]}, {options.samples} samples, movers {counts}"
        f"{' (extra ones sharing one velocity and rotation)' if options.shared else ''}"
    )
    out = tempfile.mkdtemp(prefix="bounce_cost_")
    beta = np.array([-case.EACH, 0.0, 0.0])
    ratios = {(n, name): [] for n in counts for name in setups}
    setup_times = {(n, name): [] for n in counts for name in setups}
    for round_index in range(options.rounds):
        for n in counts:
            times = {}
            for name, (use_osl, reason) in setups.items():
                bpy.ops.wm.read_factory_settings(use_empty=True)
                scene, _ = case._scene(bpy, beta, -beta)
                _extra_movers(bpy, scene, n - 2, options.shared)
                scene.cycles.shading_system = use_osl
                interreflection._reason = reason
                start = time.perf_counter()
                effect.apply(scene)
                applied = time.perf_counter() - start
                start = time.perf_counter()
                effect.sync(scene)
                synced = time.perf_counter() - start
                scene.objects["Sphere"].relativity.beta = (-case.EACH, 0.01, 0.0)
                start = time.perf_counter()
                effect.sync(scene)
                changed = time.perf_counter() - start
                nodes = _nodes_run(bpy, scene)
                carrying = sum(interreflection.MATERIAL_KEY in m for m in bpy.data.materials)
                lines = [w for w in effect.scene_warnings(scene) if "bounced" in w]
                scene.render.filepath = os.path.join(out, f"{round_index}.exr")
                scene.render.image_settings.file_format = "OPEN_EXR"
                start = time.perf_counter()
                bpy.ops.render.render(write_still=True)
                times[name] = time.perf_counter() - start
                effect.remove(scene)
                interreflection._reason = own_reason
                setup_times[(n, name)].append((applied, synced, changed))
                print(
                    f"round {round_index}, {n} movers, {name}: render {times[name]:.2f} s, Set Up {applied:.3f} s, "
                    f"sync {synced:.3f} s, sync after a change {changed:.3f} s, {nodes} nodes, "
                    f"materials with the factor: {carrying}{', panel: ' + lines[0] if lines else ''}",
                    flush=True,
                )
            for name in setups:
                ratios[(n, name)].append(times[name] / times["SVM"])
            print(f"  {n} movers over SVM: " + ", ".join(f"{k} {times[k] / times['SVM']:.3f}" for k in setups))
    print("median over the same round's SVM render (Set Up / sync / sync after a change, median s):")
    for n in counts:
        for name in setups:
            applied, synced, changed = (statistics.median(t) for t in zip(*setup_times[(n, name)], strict=True))
            print(
                f"  {n} movers, {name}: {statistics.median(ratios[(n, name)]):.3f}x "
                f"(Set Up {applied:.3f} s, sync {synced:.3f} s, after a change {changed:.3f} s)"
            )
    print(f"load average after: {os.getloadavg()}", flush=True)
    sys.stdout.flush()
    shutil.rmtree(out, ignore_errors=True)
    shutil.rmtree(getattr(user_resources, "FOLDER", out), ignore_errors=True)
    os._exit(0)


def _rewire(bpy, variant):
    """The factor group rewired for a cost breakdown (``variant``, see the module's doc)."""
    if variant is None:
        return
    from relativity_addon.blender.common import names
    from relativity_addon.blender.lights import bounce_nodes

    tree = bpy.data.node_groups[names.BOUNCE_FACTOR_GROUP]
    output = next(node for node in tree.nodes if node.bl_idname == "NodeGroupOutput")
    if variant == "camera gate":
        surface = next(node for node in tree.nodes if node.bl_idname == "NodeGroupInput").outputs["Surface"]
        gate = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(tree.nodes["path"].outputs["Is Camera Ray"], gate.inputs[0])
        tree.links.new(tree.nodes[f"double{bounce_nodes.DOUBLINGS - 1}"].outputs[0], gate.inputs[1])
        tree.links.new(surface, gate.inputs[2])
        tree.links.new(gate.outputs[0], output.inputs[0])
        return
    share = tree.nodes["scaled"].inputs[0]
    for link in list(share.links):
        tree.links.remove(link)
    if variant == "copies only":
        share.default_value = 1.0 / bounce_nodes.MAX_FACTOR
        return
    one = tree.nodes.new("ShaderNodeMath")
    one.operation = "GREATER_THAN"
    one.inputs[1].default_value = -1.0
    tree.links.new(tree.nodes["gain"].outputs[0], one.inputs[0])  # gain = 1 + use (F - 1) >= 0
    tree.links.new(one.outputs[0], share)
    tree.links.new(tree.nodes["scaled"].outputs[0], output.inputs[0])


if __name__ == "__main__":
    main()
