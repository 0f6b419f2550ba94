"""Set Up and Remove leave nothing in the temporary folder.

Cycles' own add-on compiles an in-memory OSL text (a camera's shader, a script node's) to a
temporary ``.oso`` file it never deletes (``osl_compile`` in ``cycles/osl.py``): 40-170 kB a
compile, and one day of this suite had piled up 17,875 of them (2.9 GB) in ``/tmp``. The add-on
compiles into a private folder it removes (``common.osl.compiling``)."""

import importlib
import tempfile

import numpy as np
import pytest
import test_interreflection as bounce
from test_moving_point_light import _floor_scene

from blender_support import ADDON_MODULE
from relativity_addon.blender.common import osl


@pytest.fixture
def temporary(relativity_addon, factory_blender, tmp_path, monkeypatch):
    """The process's temporary folder, empty, for the time of the test (skipped without OSL)."""
    if osl.unavailable_reason() is not None:
        pytest.skip(osl.unavailable_reason())
    folder = tmp_path / "temporary"
    folder.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    return folder


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _left(folder):
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*"))


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
def test_moving_lamp_and_camera_leave_no_temporary_files(factory_blender, temporary, method):
    """The exact camera and the stand-in lamps' script nodes (CAMERA), the moving-light group's
    script nodes (GEOMETRY): compiled at Set Up, again on Remove (the camera's shader restored)."""
    scene, _camera, _lamp = _floor_scene(factory_blender, occluder=True, method=method)
    _effect().apply(scene)
    assert any(node.bl_idname == "ShaderNodeScript" for tree in _trees(factory_blender) for node in tree.nodes)
    _effect().remove(scene)
    assert _left(temporary) == []


def test_bounce_correction_leaves_no_temporary_files(factory_blender, temporary):
    """The inter-reflection script node, compiled at Set Up and on every sync that changes it."""
    beta = np.array([bounce.EACH, 0.0, 0.0])
    scene, _ = bounce._scene(factory_blender, beta, -beta)
    scene.cycles.shading_system = True
    _effect().apply(scene)
    assert any(node.bl_idname == "ShaderNodeScript" for tree in _trees(factory_blender) for node in tree.nodes)
    _effect().remove(scene)
    assert _left(temporary) == []


def _trees(bpy):
    trees = [material.node_tree for material in bpy.data.materials if material.node_tree]
    trees += [light.node_tree for light in bpy.data.lights if light.node_tree]
    return trees + list(bpy.data.node_groups)
