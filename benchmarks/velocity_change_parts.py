"""A velocity change on artist_chain.py's grid, its parts timed apart in one process.

    python benchmarks/velocity_change_parts.py [--size 2M] [--rounds 15] [--motion constant|eased]

The grid of ``artist_chain.py`` (one mesh, Constant Velocity 0.5c, or ``eased``: its Bezier location
keys, tessellation at its default) is set up; each round rewrites the plain scene's positions
(``artist_chain.plain_rewrite``, handlers out), then changes the grid's velocity (eased: the
observer's, as ``artist_chain.py`` does) the panel's way and reads a vertex after
``evaluated_depsgraph_get``. Printed, medians of the rounds: the whole change (wall), the update
callback (wall, and the main thread's CPU time: Python, which waiting for a core does not count),
the evaluation (wall, the handler's sync taken out), the ``depsgraph_update_post`` sync (wall and
CPU), the plain rewrite and the ratio. On a loaded machine the CPU times stay where the wall times
swing; the modifier's evaluation runs on Blender's threads, so its CPU time is not the main
thread's.
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="2M")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--motion", default="constant", choices=("constant", "eased"))
    options = parser.parse_args()

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    from relativity_addon.blender.pipeline import effect

    load = os.getloadavg()
    print(f"Blender {bpy.app.version_string}, load average at start: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    size = artist_chain.parse_size(options.size)
    scene, plain_scene, movers, plain = artist_chain.build(bpy, "grid", size, options.motion, None, (64, 48), 4)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}, "Set Up failed"
    grid = movers[0]
    grid.relativity.beta = (artist_chain.BETA + 0.02, 0.0, 0.0)
    artist_chain.read_vertex(bpy, grid, bpy.context.evaluated_depsgraph_get())

    syncs = []
    sync = effect.sync

    def timed_sync(*args, **kwargs):
        wall, cpu = time.perf_counter(), time.thread_time()
        try:
            return sync(*args, **kwargs)
        finally:
            syncs.append((time.perf_counter() - wall, time.thread_time() - cpu))

    effect.sync = timed_sync  # the callback's sync, then the handler's
    rows = []
    try:
        for round_ in range(options.rounds):
            with artist_chain.without_addon_handlers(bpy):
                plain_time = artist_chain.timed(artist_chain.plain_rewrite, bpy, plain_scene, plain, 1e-3)
            syncs.clear()
            start, start_cpu = time.perf_counter(), time.thread_time()
            if options.motion == "constant":
                grid.relativity.beta = (artist_chain.BETA + 0.01 * (round_ % 2 + 1), 0.0, 0.0)
            else:
                scene.relativity.beta = (0.0, 0.0, 0.01 * (round_ % 2 + 1))
            called, called_cpu = time.perf_counter(), time.thread_time()
            artist_chain.read_vertex(bpy, grid, bpy.context.evaluated_depsgraph_get())
            end = time.perf_counter()
            handler = syncs[-1] if len(syncs) > 1 else (0.0, 0.0)
            rows.append(
                {
                    "whole": end - start,
                    "callback": called - start,
                    "callback CPU": called_cpu - start_cpu,
                    "evaluation": end - called - handler[0],
                    "handler sync": handler[0],
                    "handler sync CPU": handler[1],
                    "plain": plain_time,
                    "ratio": (end - start) / plain_time,
                }
            )
    finally:
        effect.sync = sync
    for name in rows[0]:
        value = statistics.median(row[name] for row in rows)
        print(f"{name:<18}{value:>9.2f}" if name == "ratio" else f"{name:<18}{value * 1e3:>9.2f} ms")
    load = os.getloadavg()
    print(f"load average at end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
