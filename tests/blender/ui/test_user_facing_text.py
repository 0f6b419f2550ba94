"""What the user reads: every message starts with a capital letter and names what the user sees in
the panel, never an internal identifier (``BLENDER_EEVEE_NEXT``, ``bake_deformation``, a module).

A sweep of the add-on's source (its syntax tree, no Blender) finds the messages: the first
argument of every ``RelativityError`` and ``OSLUnavailableError``, operator reports, poll
messages, panel labels, and what the warning functions (``warnings``, ``*_warning(s)``,
``_record``) return or collect. Functions named ``*problem`` return a reason that follows a
colon, so they may start lower-case, but name no identifier either. Then two messages are read
from a real scene (the render engine's name) on Blender itself.
"""

import ast
import importlib
import re
from pathlib import Path

import pytest

import pipeline_helpers as wh

PACKAGE = Path(__file__).resolve().parents[3] / "relativity_addon" / "blender"
ERRORS = ("RelativityError", "OSLUnavailableError")
WARNING_FUNCTION = re.compile(r"warnings?$|^_record$")
FRAGMENT_FUNCTION = re.compile(r"problem$")
# UPPER_SNAKE enum identifiers, snake_case Python names, module and file names
IDENTIFIER = re.compile(r"\b[A-Z][A-Z0-9]*_[A-Z0-9_]+\b|\b[a-z][a-z0-9]*_[a-z0-9_]+\b|\boslquery\b|\b\w+\.py\b")
# settings whose value is an enum identifier: shown raw they read 'BLENDER_EEVEE_NEXT', 'ORTHO', ...
ENUM_ATTRIBUTES = {"engine", "type", "panorama_type", "method", "shutter_model", "velocity_source", "device"}


def _leading_text(node):
    """The literal text a message starts with, or None if it starts with a value."""
    while isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        node = node.left
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr) and node.values and isinstance(node.values[0], ast.Constant):
        return node.values[0].value
    return None


def _messages(tree):
    """(kind, node, may start lower-case) for every user-facing message in a module."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            if name in ERRORS and node.args:
                yield name, node.args[0], False
            elif name == "report" and len(node.args) >= 2:
                yield name, node.args[1], False
            elif name == "poll_message_set" and node.args:
                yield name, node.args[0], False
            elif name == "label":
                yield from ((name, kw.value, False) for kw in node.keywords if kw.arg == "text")
        if isinstance(node, ast.FunctionDef) and (
            WARNING_FUNCTION.search(node.name) or FRAGMENT_FUNCTION.search(node.name)
        ):
            fragment = bool(FRAGMENT_FUNCTION.search(node.name))
            for sub in ast.walk(node):
                if isinstance(sub, ast.Return) and sub.value is not None:
                    yield node.name, sub.value, fragment
                elif isinstance(sub, ast.Call) and isinstance(sub.func, ast.Attribute) and sub.func.attr == "append":
                    yield from ((node.name, arg, fragment) for arg in sub.args)
                elif isinstance(sub, ast.List):
                    yield from ((node.name, element, fragment) for element in sub.elts)
                elif isinstance(sub, ast.ListComp):
                    yield node.name, sub.elt, fragment


def _problems(node, fragment):
    found = []
    leading = _leading_text(node)
    if leading is not None and leading[:1].islower() and not fragment:
        found.append("starts lower-case")
    for sub in ast.walk(node):
        if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
            found += [f"names {name!r}" for name in IDENTIFIER.findall(sub.value)]
        if (
            isinstance(sub, ast.FormattedValue)
            and isinstance(sub.value, ast.Attribute)
            and sub.value.attr in ENUM_ATTRIBUTES
        ):
            found.append(f"shows the identifier {ast.unparse(sub.value)}")
    return found


def test_every_message_starts_upper_case_and_names_no_identifier():
    found = []
    count = 0
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for kind, node, fragment in _messages(tree):
            if not isinstance(node, (ast.Constant, ast.JoinedStr, ast.BinOp)):
                continue  # a variable or a call: its text is checked where it is made
            count += 1
            for problem in _problems(node, fragment):
                found.append(f"{path.relative_to(PACKAGE)}:{node.lineno} ({kind}) {problem}: {ast.unparse(node)[:90]}")
    assert count > 100  # the sweep finds the messages
    assert not found, "\n".join(found)


def _effect(bpy):
    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.pipeline.effect")


@pytest.mark.parametrize("method", ["CAMERA", "GEOMETRY"])
def test_render_engine_named_as_in_the_panel(relativity_addon, factory_blender, method):
    """EEVEE is 'EEVEE' in the render properties, 'BLENDER_EEVEE_NEXT' (4.5) or 'BLENDER_EEVEE'
    (5.2) inside: the scene's warnings say the first."""
    bpy = factory_blender
    scene, _, sphere = wh.new_scene(bpy, samples=1)
    scene.relativity.method = method
    scene.relativity.beta = (0.0, 0.0, -0.5)
    sphere.relativity.enabled = True
    engine = next(e for e in ("BLENDER_EEVEE_NEXT", "BLENDER_EEVEE") if e in _engines(bpy))
    scene.render.engine = engine
    bpy.context.view_layer.update()
    shown = bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items[engine].name
    warnings = [w for w in _effect(bpy).scene_warnings(scene) if "Cycles" in w]
    assert warnings and all(f" {shown}" in w and engine not in w for w in warnings), warnings
    assert all(w[:1].isupper() for w in _effect(bpy).scene_warnings(scene))


def _engines(bpy):
    return {item.identifier for item in bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items}
