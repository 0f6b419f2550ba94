"""The spectral passes over blackbody gas: ray marching (what the add-on sets on Blender 5.x) against
5.x's default null scattering, side by side.

    .venv-5.2/bin/python benchmarks/volume_passes.py [--samples 16] [--resolution 64x48] [--passes 3] [--repeats 3]

The scene of ``tests/blender/colour/test_volume_temperature_grid.py``: a Volume object from a VDB
written with Blender's bundled ``openvdb`` module (a ``temperature`` grid of 2.5 for x < 0 and 4.0
for x > 0 over a 6 x 4 x 2 m slab), Principled Volume at 1000 K, density 0; observer at 0.5c toward
it. Rendered alternately: the spectral render as the add-on makes it (ray-marched passes) and the
same with the switch skipped (the scene's null scattering); each round's null-scattering time is
divided by that round's ray-marching time and the median ratio printed, with each half's luminance
in the two pictures (null scattering over ray marching). Blender 4.5 has only ray marching: nothing
to compare there.
"""

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

VOXEL = 0.1  # m


def _write_vdb(bpy, path):
    """Blender's bundled ``openvdb`` (the wheel ships it outside ``sys.path``): the two-temperature grid."""
    version = ".".join(bpy.app.version_string.split(".")[:2])
    python = f"python{sys.version_info.major}.{sys.version_info.minor}"
    folders = (parent / version / "python" / "lib" / python / "site-packages" for parent in Path(bpy.__file__).parents)
    sys.path.append(str(next(folder for folder in folders if folder.is_dir())))
    import openvdb

    counts = (61, 41, 21)
    x = -3.0 + VOXEL * np.arange(counts[0])
    values = np.empty(counts, dtype=np.float32)
    values[...] = np.where(x < 0.0, 2.5, 4.0)[:, None, None]
    grid = openvdb.FloatGrid()
    grid.name = "temperature"
    grid.transform = openvdb.createLinearTransform(voxelSize=VOXEL)
    grid.copyFromArray(values, ijk=(-30, -20, -60))
    openvdb.write(str(path), grids=[grid])


def build_scene(bpy, resolution, samples, folder):
    from camera_overhead import empty_cycles_scene

    from relativity_addon.blender.common import compat

    scene = empty_cycles_scene(bpy, resolution, samples)
    scene.world = bpy.data.worlds.new("World")
    compat.world_node_tree(scene.world).nodes["Background"].inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    path = Path(folder) / "temperature.vdb"
    _write_vdb(bpy, path)
    material = bpy.data.materials.new("Fire")
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    gas = tree.nodes.new("ShaderNodeVolumePrincipled")
    gas.inputs["Density"].default_value = 0.0
    gas.inputs["Blackbody Intensity"].default_value = 1.0
    gas.inputs["Temperature"].default_value = 1000.0
    gas.inputs["Temperature Attribute"].default_value = "temperature"
    tree.links.new(gas.outputs[0], tree.nodes.new("ShaderNodeOutputMaterial").inputs["Volume"])
    volume = bpy.data.volumes.new("Fire")
    volume.filepath = str(path)
    volume.materials.append(material)
    scene.collection.objects.link(bpy.data.objects.new("Fire", volume))
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--passes", type=int, default=3)
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy
    from camera_overhead import load_average

    import relativity_addon
    from relativity_addon.blender.colour import volumes
    from relativity_addon.blender.common import compat
    from relativity_addon.blender.pipeline import effect, spectral_render

    relativity_addon.register()
    scene = build_scene(bpy, resolution, options.samples, tempfile.mkdtemp(prefix="volume-passes-"))
    if compat.volume_ray_marching(scene) is None:
        print(f"Blender {bpy.app.version_string}: Cycles has only ray marching, nothing to compare")
        return
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = (0.0, 0.0, -0.5)
    scene.relativity.speed_of_light = 1.0
    effect.apply(scene)
    marching_materials = volumes.blackbody_materials

    def spectral(ray_marching):
        volumes.blackbody_materials = marching_materials if ray_marching else (lambda _scene: [])
        try:
            start = time.perf_counter()
            pixels, _info = spectral_render.render(scene, options.passes)
            return time.perf_counter() - start, pixels
        finally:
            volumes.blackbody_materials = marching_materials

    def half_luminance(pixels):
        y = pixels[..., :3] @ np.array([0.2126729, 0.7151522, 0.0721750])
        width = y.shape[1]
        return y[:, : width // 2].sum(), y[:, width // 2 :].sum()

    spectral(True)  # warm-up: shader compilation, kernels
    marching, null, ratios, luminance = [], [], [], []
    for _round in range(options.repeats):
        seconds_marching, pixels_marching = spectral(True)
        seconds_null, pixels_null = spectral(False)
        marching.append(seconds_marching)
        null.append(seconds_null)
        ratios.append(seconds_null / seconds_marching)
        luminance.append(np.array(half_luminance(pixels_null)) / np.array(half_luminance(pixels_marching)))
    print(
        f"Blender {bpy.app.version_string}, {options.resolution}, {options.samples} samples, {options.passes} passes, "
        f"{options.repeats} alternating rounds, {load_average()} (at the end), medians:"
    )
    print(f"  ray marching (the add-on)  {statistics.median(marching):7.2f} s")
    print(
        f"  null scattering            {statistics.median(null):7.2f} s   ratio {statistics.median(ratios):6.1f}"
        f"   (ratios {min(ratios):.1f}-{max(ratios):.1f})"
    )
    cool, hot = np.median(np.array(luminance), axis=0)
    print(f"  picture luminance, null scattering / ray marching: 2500 K half {cool:.3f}, 4000 K half {hot:.3f}")


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
