"""The package's shape, read from its source (no Blender): no import cycles, the render paths
independent of each other, the physics core free of bpy, no module past about 500 lines."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "relativity_addon"
MAX_LINES = 520  # "about 500"

# The render paths and the colour stage write their part from the snapshot; only effect.py knows
# them all.
PARTS = {
    "camera": {"relativity_addon.blender.camera.exact_camera", "relativity_addon.blender.common.osl"},
    "geometry": {
        "relativity_addon.blender.geometry.apparent_meshes", "relativity_addon.blender.geometry.modifier",
        "relativity_addon.blender.geometry.motion", "relativity_addon.blender.geometry.bakes",
    },
    "colour": {
        "relativity_addon.blender.colour.doppler_colour", "relativity_addon.blender.colour.materials",
        "relativity_addon.blender.colour.compositing", "relativity_addon.blender.colour.lut_images",
        "relativity_addon.blender.colour.world_colour",
    },
}


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
                return stack[stack.index(target):] + [target]
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


@pytest.mark.parametrize("part", sorted(PARTS))
def test_render_paths_and_colour_import_nothing_from_each_other(part):
    others = set().union(*(modules for name, modules in PARTS.items() if name != part))
    for module in PARTS[part]:
        assert not GRAPH[module] & others, f"{module} imports {sorted(GRAPH[module] & others)}"


def test_physics_core_and_errors_never_import_bpy():
    bpy_free = ("relativity_addon.errors", "relativity_addon.physics.shipped_luts")
    for name, path in MODULES.items():
        if name.startswith("relativity_addon.physics") or name in bpy_free:
            tree = ast.parse(path.read_text(encoding="utf-8"))
            imported = {alias.name.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.Import)
                        for alias in node.names}
            imported |= {(node.module or "").split(".")[0] for node in ast.walk(tree)
                         if isinstance(node, ast.ImportFrom) and not node.level}
            assert not imported & {"bpy", "mathutils", "bpy_extras"}, name


def test_no_module_is_over_about_500_lines():
    long = {name: n for name, path in MODULES.items() if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, long
