"""A Volume object whose blackbody reads a temperature grid is seen at ``D T`` per point (fast mode).

A VDB written with Blender's bundled ``openvdb`` module: a ``temperature`` grid of 2.5 where
x < 0 and 4.0 where x > 0 over a 6 x 4 x 2 m slab, read by a Principled Volume (density 0,
Blackbody Intensity 1, Temperature 1000 K, Temperature Attribute ``temperature``): Cycles emits
``sigma T^4`` times a unit-luminance blackbody colour at ``T`` = 2500 K and 4000 K, fading to 0 K
at the grid's edges. Observer moving toward it at 0.5c. The rule (docs/spectral-model.md,
"Temperature grids"): a blackbody whose total is ``sigma T^4`` is seen as one at ``D T`` with
total ``sigma (D T)^4``, so each half must be seen as colour-science's blackbody at ``D T`` and
its luminance must change by ``D^4`` (Weiskopf et al. 1999 eq. 15, docs/physics.md) times the
slab's path-length change under aberration, ``D`` from each pixel's viewing direction.
"""

import sys
from pathlib import Path

import numpy as np
import pytest
from test_volume_blackbody import _slab_path_ratio

import colour_helpers as dh

RESOLUTION = (64, 48)
BETA = (0.0, 0.0, -0.5)
BASE_TEMPERATURE = 1000.0
HALVES = {"cool": (2.5, (slice(20, 28), slice(18, 26))), "hot": (4.0, (slice(20, 28), slice(38, 46)))}
VOXEL = 0.1  # m


def _openvdb(bpy):
    """Blender's bundled ``openvdb`` module (the wheel ships it outside ``sys.path``)."""
    version = ".".join(bpy.app.version_string.split(".")[:2])
    python = f"python{sys.version_info.major}.{sys.version_info.minor}"
    folder = Path(bpy.__file__).parent / version / "python" / "lib" / python / "site-packages"
    if str(folder) not in sys.path:
        sys.path.append(str(folder))
    import openvdb

    return openvdb


def write_two_temperature_vdb(bpy, path):
    """A ``temperature`` grid over x in [-3, 3], y in [-2, 2], z in [-6, -4] (voxel centres):
    2.5 for x < 0, 4.0 for x > 0."""
    openvdb = _openvdb(bpy)
    counts = (61, 41, 21)
    values = np.empty(counts, dtype=np.float32)
    x = -3.0 + VOXEL * np.arange(counts[0])
    values[...] = np.where(x < -1e-6, HALVES["cool"][0], HALVES["hot"][0])[:, None, None]
    values[np.abs(x) < 1e-6] = 0.5 * (HALVES["cool"][0] + HALVES["hot"][0])
    grid = openvdb.FloatGrid()
    grid.name = "temperature"
    grid.transform = openvdb.createLinearTransform(voxelSize=VOXEL)
    grid.copyFromArray(values, ijk=(-30, -20, -60))
    openvdb.write(str(path), grids=[grid])


def measured_border(scene):
    """Render only the box around the HALVES' windows with a pixel to spare (the picture keeps its
    size): Cycles seeds each pixel by its own position, so those pixels come out the same."""
    width, height = RESOLUTION
    windows = [window for _grid, window in HALVES.values()]
    top, bottom = min(w[0].start for w in windows) - 1, max(w[0].stop for w in windows) + 1
    left, right = min(w[1].start for w in windows) - 1, max(w[1].stop for w in windows) + 1
    scene.render.use_border, scene.render.use_crop_to_border = True, False
    scene.render.border_min_y, scene.render.border_max_y = 1.0 - bottom / height, 1.0 - top / height
    scene.render.border_min_x, scene.render.border_max_x = left / width, right / width


def grid_scene(bpy, tmp_path, samples=16):
    scene, camera = dh.emitter_scene(bpy, samples=samples, resolution=RESOLUTION)
    measured_border(scene)  # only the halves' pixels are measured
    path = tmp_path / "temperature.vdb"
    write_two_temperature_vdb(bpy, path)
    material = dh.volume_material(bpy, "Fire", Density=0.0, Blackbody_Intensity=1.0, Temperature=BASE_TEMPERATURE)
    material.node_tree.nodes["Principled Volume"].inputs["Temperature Attribute"].default_value = "temperature"
    volume = bpy.data.volumes.new("Fire")
    volume.filepath = str(path)
    volume.materials.append(material)
    obj = bpy.data.objects.new("Fire", volume)
    scene.collection.objects.link(obj)
    return scene, camera, material


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3))


def observe(scene):
    """The observer moving toward the slab at ``BETA`` (the exact camera), ``c = 1``."""
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0


def halves_off(bpy, scene, camera, image, y_rest, power=4, label="", luminance=0.02):
    """The halves of ``image`` (rows top first) not seen as colour-science's blackbody at ``D T``
    (Delta E 2000 <= 1) with their rest luminance ``y_rest`` times ``D^power`` and the slab's
    path-length change (within ``luminance``), ``D`` from each pixel's viewing direction.

    The fast mode shifts Cycles' own emission (the Principled Volume reads the grid as at rest): 2 %
    (16 samples: 0.9955 / 1.0015 on Blender 5.2, 0.9993 / 1.0001 on 4.5; 0.966 / 0.971 on 5.2 when
    the group rebuilt the emission from an Attribute node). The spectral passes rebuild it from the
    Attribute node, which Blender 5.2 reads 2.9 % dimmer than the Principled Volume: 5 % there."""
    doppler = dh.pixel_doppler(bpy, scene, camera, BETA)
    path = _slab_path_ratio(bpy, scene, camera)
    failures = []
    for name, (grid, window) in HALVES.items():
        temperature = grid * BASE_TEMPERATURE
        xyz = _xyz(image, window)
        d = doppler[window].ravel()
        expected_colour = np.mean(dh.blackbody_xyz_colour_science(d * temperature), axis=0)
        delta_e = dh.delta_e_2000_normalised(xyz.mean(axis=0), expected_colour)
        ratio = xyz[:, 1].mean() / np.mean(y_rest[name] * path[window].ravel() * d**power)
        print(
            f"{label}{name} ({temperature:.0f} K): D {d.mean():.3f}, Delta E {delta_e:.3f}, "
            f"Y / D^{power} Y_rest {ratio:.4f}"
        )
        if not (delta_e <= 1.0 and ratio == pytest.approx(1.0, abs=luminance)):
            failures.append(name)
    return failures


@pytest.mark.parametrize("searchlight", [True, False], ids=["searchlight", "rest_brightness"])
def test_temperature_grid_is_seen_at_d_t_with_d4_luminance(relativity_addon, tmp_path, searchlight):
    """With the searchlight off (Doppler only, Rest Brightness) the power is 0: ``D^0``, the rest
    luminance with the colour of ``D T``."""
    bpy = __import__("bpy")
    power = 4 if searchlight else 0
    scene, camera, material = grid_scene(bpy, tmp_path)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {}
    for name, (grid, window) in HALVES.items():
        xyz = _xyz(rest, window)
        y_rest[name] = xyz[:, 1]
        assert y_rest[name].min() > 0.05, name
        # the setup: Cycles' rest colour is the blackbody at Temperature x grid
        delta_e = dh.delta_e_2000_normalised(xyz.mean(axis=0), dh.blackbody_xyz_colour_science(grid * BASE_TEMPERATURE))
        print(f"{name} at rest: Y {y_rest[name].mean():.3f}, Delta E to {grid * BASE_TEMPERATURE:.0f} K {delta_e:.3f}")
        assert delta_e < 1.0, name
    links_before = sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links)
    nodes_before = len(material.node_tree.nodes)

    observe(scene)
    scene.relativity.use_searchlight = searchlight
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving))
    assert not halves_off(bpy, scene, camera, moving, y_rest, power)

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links) == links_before
    assert len(material.node_tree.nodes) == nodes_before


def test_temperature_grid_in_spectral_mode_is_seen_at_d_t_with_d4_luminance(relativity_addon, tmp_path):
    """The same grid in the spectral mode (3 passes, docs/spectral-model.md, "Temperature grids"):
    camera rays see the gas's scene-frame spectrum whose shift is Cycles' own emission at ``D T``,
    so each half must be colour-science's blackbody at ``D T`` (Delta E 2000 <= 1) with its rest
    luminance times ``D^4`` (eq. 15) and the slab's path-length change. Refused before (the passes
    had no rule for grids)."""
    bpy = __import__("bpy")
    scene, camera, material = grid_scene(bpy, tmp_path)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: _xyz(rest, window)[:, 1] for name, (_grid, window) in HALVES.items()}
    links_before = sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links)
    nodes_before = len(material.node_tree.nodes)

    observe(scene)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    spectral_render = dh.addon_module(relativity_addon, "pipeline.spectral_render")
    pixels, _info = spectral_render.render(scene, 3)
    spectral = pixels[::-1, :, :3].astype(float)  # top row first, like the EXR reader
    assert np.all(np.isfinite(spectral)) and spectral.min() >= 0.0
    assert not halves_off(bpy, scene, camera, spectral, y_rest, label="spectral ", luminance=0.05)

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links) == links_before
    assert len(material.node_tree.nodes) == nodes_before


def test_a_grid_set_up_by_an_earlier_version_gets_the_principled_volume_fed(relativity_addon, tmp_path):
    """Group version 10 shifts grid gas through the Principled Volume's own Temperature and Tint; a
    file set up before (the group's outputs not linked there) gets them linked at the next attach
    (every render attaches), and Remove still gives the links back. No render."""
    bpy = __import__("bpy")
    volumes = dh.addon_module(relativity_addon, "colour.volumes")
    scene, _camera, material = grid_scene(bpy, tmp_path)
    tree = material.node_tree
    links_before = sorted((link.from_node.name, link.to_node.name) for link in tree.links)
    observe(scene)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    principled = tree.nodes["Principled Volume"]
    group = tree.nodes[f"{volumes.NODE_PREFIX} Principled Volume"]
    for name in ("Temperature", "Blackbody Tint"):
        assert principled.inputs[name].links[0].from_node == group, name
        tree.links.remove(principled.inputs[name].links[0])  # the wiring of version 9
    volumes.attach_scene(scene)
    for name in ("Temperature", "Blackbody Tint"):
        assert principled.inputs[name].is_linked and principled.inputs[name].links[0].from_node == group, name
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sorted((link.from_node.name, link.to_node.name) for link in tree.links) == links_before
    assert principled.inputs["Temperature"].default_value == BASE_TEMPERATURE
