"""The shutter-model codes are defined once (physics/shutter.py:ShutterModel): the OSL camera
compares its ``shutter_model`` parameter against the same integers, and the add-on's enum
property lists the same names in the same order (its index is the code the shader gets). Both
files are read as text: the shader needs Cycles to compile and props.py needs bpy."""

import ast
import re
from pathlib import Path

import pytest

from relativity_addon.physics.shutter import SHUTTER_MODEL_NAMES, ShutterModel

ADDON = Path(__file__).resolve().parents[2] / "relativity_addon"
SHADER = ADDON / "shaders" / "relativistic_camera.osl"
PROPS = ADDON / "blender" / "ui" / "props.py"


def _shader_source():
    source = SHADER.read_text()
    return re.sub(r"/\*.*?\*/|//[^\n]*", " ", source, flags=re.S)  # without comments


def test_shader_defines_one_code_per_model_equal_to_the_enum():
    defines = {
        name: int(value)
        for name, value in re.findall(r"^\s*#define\s+SHUTTER_(\w+)\s+(-?\d+)\s*$", _shader_source(), flags=re.M)
    }
    assert defines == {model.name: model.value for model in ShutterModel}


def test_shader_compares_shutter_model_only_against_the_defined_codes():
    source = _shader_source()
    compared = re.findall(r"\bshutter_model\s*(?:==|!=)\s*(\w+)|(\w+)\s*(?:==|!=)\s*shutter_model\b", source)
    operands = [left or right for left, right in compared]
    assert operands, "the shader no longer compares shutter_model: update this test"
    # Named codes only (a bare integer could drift from the enum unnoticed), and each one defined.
    assert all(operand.startswith("SHUTTER_") for operand in operands), operands
    assert {operand.removeprefix("SHUTTER_") for operand in operands} <= set(SHUTTER_MODEL_NAMES)
    # The models other than the pinhole all have their own branch (the pinhole is the != test).
    assert {operand.removeprefix("SHUTTER_") for operand in operands} >= set(SHUTTER_MODEL_NAMES) - {
        "APERTURE_PLANE"
    }  # aperture plane: t_L = t_S, the shader's default branch
    default = re.search(r"\bint\s+shutter_model\s*=\s*(\d+)", source)
    assert default and int(default.group(1)) == ShutterModel.PINHOLE


def test_names_are_the_enum_members_in_code_order():
    assert SHUTTER_MODEL_NAMES == tuple(model.name for model in sorted(ShutterModel))
    assert [model.value for model in ShutterModel] == list(range(len(ShutterModel)))
    assert ShutterModel("DETECTOR_PLANE") is ShutterModel.DETECTOR_PLANE is ShutterModel(2)
    with pytest.raises(ValueError):
        ShutterModel("NO_SUCH_MODEL")


def test_blender_property_items_follow_the_enum_order():
    tree = ast.parse(PROPS.read_text())
    items = next(
        (
            node.value
            for node in tree.body
            if isinstance(node, ast.Assign)
            and any(getattr(target, "id", None) == "SHUTTER_MODEL_ITEMS" for target in node.targets)
        ),
        None,
    )
    if not isinstance(items, ast.Tuple):
        pytest.skip("props.py no longer spells SHUTTER_MODEL_ITEMS out (built from the core's enum)")
    names = tuple(ast.literal_eval(item)[0] for item in items.elts)
    assert names == SHUTTER_MODEL_NAMES
