"""What the fast mode's observed light group (moving blackbody lights' stand-ins, compositing.py)
costs an exact-camera render: the compositor stage as built, with that group's reflectance-shift
branch forced on, and with the branch cut out of the group.

    python benchmarks/observed_group_cost.py [--samples 1] [--resolution 640x480] [--repeats 5]

The scene of ``camera_overhead.py`` (no moving light, as in most scenes: the stage mutes the
branch, ``light_groups.mute_observed_branch``) with the exact camera at 0.5c. The three variants
are rendered alternately after a warm-up round, so that load from other processes hits them
alike; the median ratio of each round's time to the cut-out variant's is printed, wall clock and
CPU (user + system of this process), with the load average. Few samples and a large frame make
the compositor's share of the render large.
"""

import argparse
import os
import statistics
import sys
import tempfile

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def main():
    import camera_overhead as co

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1)
    parser.add_argument("--resolution", default="640x480")
    parser.add_argument("--repeats", type=int, default=5)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon
    from relativity_addon.blender.common import names
    from relativity_addon.blender.pipeline import effect

    relativity_addon.register()
    scene = co.build_scene(bpy, resolution, options.samples)
    scene.relativity.beta = (0.0, 0.48, -0.13)
    effect.apply(scene)
    group = bpy.data.node_groups[names.COMPOSITOR_GROUP]
    branch = group.nodes["observed_seen"]
    total = group.nodes["lit_seen"].inputs[1]
    plain = next(node for node in group.nodes if node.bl_idname == "NodeGroupInput").outputs["Observed"]
    assert branch.mute, "no moving light: the stage mutes the branch"

    def variant(mute, source):
        def set_up():
            branch.mute = mute
            group.links.new(source, total)

        return set_up

    cases = (
        ("branch cut out", variant(True, plain)),
        ("as built (muted)", variant(True, branch.outputs["Result"])),
        ("branch on", variant(False, branch.outputs["Result"])),
    )
    out = tempfile.mkdtemp(prefix="observed-group-cost-")
    times = {label: [] for label, _ in cases}
    for round_index in range(options.repeats + 1):  # the first round warms up
        for label, set_up in cases:
            set_up()
            seconds = co.timed_render_clocks(bpy, scene, os.path.join(out, f"{round_index}.png"))
            if round_index:
                times[label].append(seconds)
    variant(True, branch.outputs["Result"])()
    effect.remove(scene)
    rounds = f"{options.repeats} alternating rounds"
    print(f"{options.resolution}, {options.samples} samples, {rounds} ({co.load_average()}):")
    reference = times[cases[0][0]]
    for label, _ in cases:
        wall, cpu = (statistics.median(t[k] for t in times[label]) for k in (0, 1))
        ratio_wall, ratio_cpu = (
            statistics.median(t[k] / r[k] for t, r in zip(times[label], reference, strict=True)) for k in (0, 1)
        )
        print(
            f"  {label:17s} wall {wall:6.3f} s  cpu {cpu:6.3f} s  / cut out: wall {ratio_wall:.3f}  cpu {ratio_cpu:.3f}"
        )


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
