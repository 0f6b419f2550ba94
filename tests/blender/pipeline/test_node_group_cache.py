"""Built node groups are kept and appended again (``common/nodes.py``): the Apparent Geometry
group alone (410 nodes, 946 links) took 1.9-3 s of every Set Up to build from Python, about 15 ms
to append. The appended groups must be the built ones, leave no library or fake user in the
file, and replace an older version of a group for everything that uses it."""

import importlib
import shutil
from pathlib import Path

import scene_dump
import test_file_operations as files

from blender_support import ADDON_MODULE


def _module(name):
    return importlib.import_module(f"{ADDON_MODULE}.blender.{name}")


def _groups(bpy):
    return {group.name: scene_dump.node_tree_dump(bpy, group) for group in bpy.data.node_groups}


def test_appended_groups_are_the_built_ones(relativity_addon, factory_blender, monkeypatch):
    bpy = factory_blender
    nodes, names = _module("common.nodes"), _module("common.names")
    folder = Path(bpy.utils.extension_path_user(relativity_addon, path="node_groups", create=True))
    shutil.rmtree(folder)  # built at this Set Up, whatever earlier tests of the process kept
    scene = files._build(bpy, "GEOMETRY")
    effect = files._effect()
    effect.apply(scene)
    built = _groups(bpy)
    kept = sorted(folder.glob("*.blend"))
    assert names.GEOMETRY_GROUP in built and kept, "nothing was kept"
    effect.remove(scene)
    assert not bpy.data.node_groups

    def no_build(spec, keep_interface=False):
        if spec.name == names.GEOMETRY_GROUP:
            raise AssertionError(f"{spec.name} built again: the kept one was not appended")
        return build(spec, keep_interface)

    build = nodes.build_group
    monkeypatch.setattr(nodes, "build_group", no_build)
    effect.apply(scene)
    assert _groups(bpy) == built
    assert not bpy.data.libraries, [library.filepath for library in bpy.data.libraries]
    assert not [group.name for group in bpy.data.node_groups if group.use_fake_user]

    # A file holding an older version: the kept current one replaces it for the modifier using it
    # (the cube's, given the full group: at 32 x 24 the bounds clear its edges, so it has the lean one).
    group = bpy.data.node_groups[names.GEOMETRY_GROUP]
    cube_modifier = _module("geometry.modifier").find_modifier(scene.objects["Cube"])
    _module("geometry.modifier")._give_group(cube_modifier, group)
    group[names.GEOMETRY_GROUP_VERSION_KEY] = names.GEOMETRY_GROUP_VERSION - 1
    _module("geometry.modifier").ensure_node_group()
    current = bpy.data.node_groups[names.GEOMETRY_GROUP]
    assert current[names.GEOMETRY_GROUP_VERSION_KEY] == names.GEOMETRY_GROUP_VERSION
    assert [g.name for g in bpy.data.node_groups if g.name.startswith(names.GEOMETRY_GROUP)].count(
        names.GEOMETRY_GROUP
    ) == 1
    assert not [g.name for g in bpy.data.node_groups if g.name.startswith(f"{names.GEOMETRY_GROUP}.")]
    modifier = _module("geometry.modifier").find_modifier(scene.objects["Cube"])
    assert modifier is not None and modifier.node_group == current
    effect.remove(scene)
    assert not bpy.data.node_groups and not bpy.data.libraries
