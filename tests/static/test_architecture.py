"""The package's shape, read from its source (no Blender): every module belongs to one part, each
part imports only the parts below it, no import cycles, the physics core free of bpy and of the
rest of the package, the stage list in the docs the one in the code, no module past about 500
lines."""

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "relativity_addon"
DOCS = Path(__file__).resolve().parents[2] / "docs" / "architecture.md"
MAX_LINES = 560  # "about 500", counted after `ruff format` (which spreads long calls over lines)

# The parts, lowest first, and what each may import (besides itself). The read side (scene) imports
# no stage; the two render paths (camera, geometry) import nothing from each other; everything that
# writes the effect sits below pipeline, which alone knows them all; the panel and operators (ui)
# sit on top. docs/architecture.md draws the same picture.
ALLOWED = {
    "physics": set(),
    "errors": set(),
    "common": {"physics", "errors"},
    "scene": {"common", "physics", "errors"},
    "camera": {"scene", "common", "physics", "errors"},
    "geometry": {"scene", "common", "physics", "errors"},
    "colour": {"camera", "scene", "common", "physics", "errors"},
    "lights": {"colour", "geometry", "camera", "scene", "common", "physics", "errors"},
    "pipeline": {"lights", "colour", "geometry", "camera", "scene", "common", "physics", "errors"},
    "ui": {"pipeline", "lights", "colour", "geometry", "camera", "scene", "common", "physics", "errors"},
    "blender": {"ui", "pipeline", "geometry"},  # blender/__init__.py: registers ui, bakes and handlers
    "batch": {"common", "physics", "errors"},  # the script side: no bpy at import, Blender glue only lazily
    "root": {"blender"},  # relativity_addon/__init__.py: register() / unregister()
}
SUBPACKAGES = ("common", "scene", "camera", "geometry", "colour", "lights", "pipeline", "ui")


def part_of(module):
    """The part a module belongs to, or None (a module outside every part)."""
    parts = module.split(".")
    if parts[0] != "relativity_addon":
        return None
    if len(parts) == 1:
        return "root"
    if parts[1] in ("physics", "batch", "errors") and (len(parts) == 2 or parts[1] != "errors"):
        return parts[1]
    if parts[1] == "blender":
        if len(parts) == 2:
            return "blender"
        if parts[2] in SUBPACKAGES:
            return parts[2]
    return None


def upward_imports(graph):
    """(module, imported module) pairs that break the parts' order."""
    return sorted(
        (module, target)
        for module, targets in graph.items()
        for target in targets
        if part_of(target) != part_of(module) and part_of(target) not in ALLOWED[part_of(module)]
    )


def _modules():
    modules = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    return modules


def _imports(name, path, modules):
    """Package modules that ``name`` imports (relative and absolute, at any depth of the file)."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                if f"{target}.{alias.name}" in modules:
                    found.add(f"{target}.{alias.name}")
                elif target in modules:
                    found.add(target)
        elif isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name in modules}
    found.discard(name)
    return found


MODULES = _modules()
GRAPH = {name: _imports(name, path, MODULES) for name, path in MODULES.items()}


def _find_cycle(graph):
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for target in sorted(graph[node]):
            if state.get(target) == "open":
                return stack[stack.index(target) :] + [target]
            if target not in state:
                cycle = visit(target)
                if cycle:
                    return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node)
            if cycle:
                return cycle
    return None


def test_the_walk_sees_the_package():
    assert "relativity_addon.blender.pipeline.effect" in GRAPH
    assert "relativity_addon.blender.camera.exact_camera" in GRAPH["relativity_addon.blender.pipeline.effect"]
    assert "relativity_addon.physics.shutter" in GRAPH["relativity_addon.blender.scene.snapshot"]


def test_cycle_finder_finds_a_planted_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}
    assert _find_cycle(graph) == ["a", "b", "c", "a"]
    assert _find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycles():
    assert _find_cycle(GRAPH) is None


def test_every_module_belongs_to_a_part():
    outside = [name for name in MODULES if part_of(name) is None]
    assert not outside, f"modules outside every part (add them to a part in ALLOWED): {outside}"


def test_part_finder_refuses_a_planted_module_outside_every_part():
    assert part_of("relativity_addon.blender.newthing") is None
    assert part_of("relativity_addon.helpers") is None
    assert part_of("relativity_addon.blender.lights.moving_lights") == "lights"


def test_each_part_imports_only_the_parts_below_it():
    assert upward_imports(GRAPH) == []


def test_order_check_finds_planted_upward_imports():
    planted = dict(GRAPH)
    snapshot = "relativity_addon.blender.scene.snapshot"
    planted[snapshot] = GRAPH[snapshot] | {"relativity_addon.blender.colour.materials"}  # read side -> stage
    planted["relativity_addon.physics.lorentz"] = {"relativity_addon.errors"}  # physics -> rest of the package
    planted["relativity_addon.blender.camera.exact_camera"] = {"relativity_addon.blender.geometry.modifier"}
    assert upward_imports(planted) == [
        ("relativity_addon.blender.camera.exact_camera", "relativity_addon.blender.geometry.modifier"),
        ("relativity_addon.blender.scene.snapshot", "relativity_addon.blender.colour.materials"),
        ("relativity_addon.physics.lorentz", "relativity_addon.errors"),
    ]


def _stage_names():
    """The names of pipeline/stages.py's STAGES, read from its source (it needs bpy to import)."""
    tree = ast.parse((PACKAGE / "blender" / "pipeline" / "stages.py").read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.AnnAssign) and getattr(node.target, "id", None) == "STAGES":
            return [call.args[0].value for call in node.value.elts]
    raise AssertionError("no STAGES in pipeline/stages.py")


def test_the_docs_list_the_stages_of_the_code_in_order():
    text = DOCS.read_text(encoding="utf-8")
    table = text[text.index("## The stages") :]
    documented = re.findall(r"^\| \d+ \| ([^|]+?) \|", table, flags=re.M)
    assert documented == _stage_names()


def test_physics_core_and_errors_never_import_bpy():
    bpy_free = ("relativity_addon.errors",)
    for name, path in MODULES.items():
        if name.startswith("relativity_addon.physics") or name in bpy_free:
            tree = ast.parse(path.read_text(encoding="utf-8"))
            imported = {
                alias.name.split(".")[0]
                for node in ast.walk(tree)
                if isinstance(node, ast.Import)
                for alias in node.names
            }
            imported |= {
                (node.module or "").split(".")[0]
                for node in ast.walk(tree)
                if isinstance(node, ast.ImportFrom) and not node.level
            }
            assert not imported & {"bpy", "mathutils", "bpy_extras"}, name


def test_no_module_is_over_about_500_lines():
    long = {name: n for name, path in MODULES.items() if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, long
