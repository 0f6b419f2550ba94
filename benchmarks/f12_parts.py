"""Where F12's extra time goes on artist_chain.py's scenes, its parts timed apart in one process.

    python benchmarks/f12_parts.py [--size 2M] [--scene objects] [--motion constant] [--rounds 3]

The scene of ``artist_chain.py`` (``--scene objects``: 988 grids of 2,025 vertices at 2M) is set
up. In alternating rounds, each render of the same scene, 64x48 at 4 samples:

- ``plain``: the plain scene (nothing set up, the add-on's handlers out);
- ``effect``: the set-up scene, each add-on handler that the render calls timed (wall, and the
  main thread's CPU time: Python, which waiting for a core does not count);
- ``effect, no handlers``: the set-up scene with the add-on's handlers out (what the render's
  own depsgraph and Cycles cost: the modifiers evaluated from scratch);
- ``effect, caches detached``: as the last, every modifier's ``Cache`` input emptied (the cache
  objects out of the render's depsgraph; a closed-form mesh left whole reads nothing from its cache).

Then the modifiers' evaluation alone, as the render's depsgraph does it (every applied mesh tagged,
``evaluated_depsgraph_get``, handlers out), process CPU time (Blender's threads included): the
group the modifiers have (the full one, or the lean one where the bound clears) as built; with the
closed form's Set Position muted; with every Store Named Attribute, Remove Attribute and Set
Position muted; the modifiers off. Medians of the rounds; on a loaded
machine read the CPU times and the ratios measured side by side.
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

STORES = ("store_verdict", "unmarked", "kf_store_window", "store_rest", "whole_rest", "store_beta")
MOVES = ("whole_seen", "set_position")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="2M")
    parser.add_argument("--scene", default="objects")
    parser.add_argument("--motion", default="constant")
    parser.add_argument("--rounds", type=int, default=3)
    options = parser.parse_args()

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    from relativity_addon.blender.common import compat
    from relativity_addon.blender.geometry import modifier
    from relativity_addon.blender.pipeline import handlers

    load = os.getloadavg()
    print(f"Blender {bpy.app.version_string}, load average at start: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    size = artist_chain.parse_size(options.size)
    effect_scene, plain_scene, movers, _plain = artist_chain.build(
        bpy, options.scene, size, options.motion, None, (64, 48), 4
    )
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}, "Set Up failed"
    bpy.context.evaluated_depsgraph_get()
    modifiers = [modifier.find_modifier(obj) for obj in movers]
    caches = [modifier.cache_object(obj) for obj in movers]
    cache_input = modifier._input_identifiers(modifiers[0].node_group)["Cache"]

    calls = []

    def timed_handler(name, handler):
        def run(scene, depsgraph=None):
            wall, cpu = time.perf_counter(), time.thread_time()
            handler(scene, depsgraph)
            calls.append((name, time.perf_counter() - wall, time.thread_time() - cpu))

        run.__module__ = handler.__module__  # artist_chain.without_addon_handlers takes it out too
        return run

    for name, handler in handlers.HANDLERS:
        listed = getattr(bpy.app.handlers, name)
        listed[listed.index(handler)] = timed_handler(name, handler)

    def render(scene):
        wall, cpu = time.perf_counter(), time.process_time()
        bpy.ops.render.render(scene=scene.name)
        return time.perf_counter() - wall, time.process_time() - cpu

    def attach_caches(attached):
        for obj, mod, cache in zip(movers, modifiers, caches, strict=True):
            compat.set_modifier_input(mod, cache_input, cache if attached else None)
            obj.update_tag()
        bpy.context.evaluated_depsgraph_get()

    for cache in caches:
        cache.use_fake_user = True  # kept while detached (the modifier is its only user)
    renders = {"plain": [], "effect": [], "effect, no handlers": [], "effect, caches detached": []}
    handler_rows = []
    for _round in range(options.rounds):
        with artist_chain.without_addon_handlers(bpy):
            renders["plain"].append(render(plain_scene))
        calls.clear()
        renders["effect"].append(render(effect_scene))
        handler_rows.append(list(calls))
        with artist_chain.without_addon_handlers(bpy):
            renders["effect, no handlers"].append(render(effect_scene))
            attach_caches(False)
            renders["effect, caches detached"].append(render(effect_scene))
            attach_caches(True)
    for cache in caches:
        cache.use_fake_user = False

    tree = modifiers[0].node_group  # the full group, or the lean one (its nodes on that path have the same names)

    def evaluation(muted, enabled=True):
        for node in tree.nodes:
            node.mute = node.name in muted
        for mod in modifiers:
            mod.show_viewport = enabled
        bpy.context.evaluated_depsgraph_get()
        for obj in movers:
            obj.update_tag()
        wall, cpu = time.perf_counter(), time.process_time()
        bpy.context.evaluated_depsgraph_get()
        return time.perf_counter() - wall, time.process_time() - cpu

    variants = {
        "as built": ((), True),
        "closed form's Set Position muted": (MOVES, True),
        "stores and Set Position muted": (STORES + MOVES, True),
        "modifiers off": ((), False),
    }
    evaluations = {label: [] for label in variants}
    with artist_chain.without_addon_handlers(bpy):
        for _round in range(options.rounds):
            for label, (muted, enabled) in variants.items():
                evaluations[label].append(evaluation(muted, enabled))
        evaluation((), True)

    print(f"\n{options.scene}, {size:,} vertices, {options.motion}: {len(movers)} meshes, {options.rounds} rounds")
    plain_wall = statistics.median(wall for wall, _cpu in renders["plain"])
    for label, rows in renders.items():
        wall = statistics.median(w for w, _c in rows)
        cpu = statistics.median(c for _w, c in rows)
        ratio = statistics.median(w / p for (w, _c), (p, _pc) in zip(rows, renders["plain"], strict=True))
        print(f"F12 {label:<26} wall {wall:7.3f} s ({ratio:.2f}x plain)  process CPU {cpu:7.3f} s")
    print(f"(plain F12 wall {plain_wall:.3f} s)")
    print("handlers the effect's render called (medians over the rounds, in call order):")
    for index, (name, _wall, _cpu) in enumerate(handler_rows[0]):
        walls = [row[index][1] for row in handler_rows if index < len(row)]
        cpus = [row[index][2] for row in handler_rows if index < len(row)]
        wall, cpu = statistics.median(walls) * 1e3, statistics.median(cpus) * 1e3
        print(f"  {name:<22} wall {wall:7.1f} ms  main-thread CPU {cpu:7.1f} ms")
    print("the modifiers evaluated again (every applied mesh tagged):")
    for label, rows in evaluations.items():
        wall = statistics.median(w for w, _c in rows)
        cpu = statistics.median(c for _w, c in rows)
        print(f"  {label:<34} wall {wall * 1e3:7.1f} ms  process CPU {cpu * 1e3:7.1f} ms")
    load = os.getloadavg()
    print(f"load average at end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat as _compat

    _compat.run_main(main)
