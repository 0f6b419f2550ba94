"""Every public function and method of the glue (blender/, batch/, the package's __init__ and errors)
annotates all its parameters (but self and cls) and its return, read from the source (no Blender), so
that mypy checks them whole (issue 24)."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "relativity_addon"
CHECKED = (
    sorted((PACKAGE / "blender").rglob("*.py"))
    + sorted((PACKAGE / "batch").rglob("*.py"))
    + [PACKAGE / "__init__.py", PACKAGE / "errors.py"]
)


def _public_functions(tree):
    """(qualified name, def node) of each public function: module level, or a method of a public class
    (nested functions are private to their function)."""

    def walk(body, prefix):
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith("_"):
                yield f"{prefix}{node.name}", node
            elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                yield from walk(node.body, f"{prefix}{node.name}.")
            elif isinstance(node, ast.If):  # `if TYPE_CHECKING:` / version branches at module level
                yield from walk(node.body + node.orelse, prefix)

    return walk(tree.body, "")


def missing_annotations(source):
    """'name: what' for each public function of ``source`` lacking a parameter's or the return's
    annotation."""
    missing = []
    for name, node in _public_functions(ast.parse(source)):
        args = node.args
        positional = args.posonlyargs + args.args
        is_method = "." in name and not any(
            isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list
        )
        if is_method and positional and positional[0].arg in ("self", "cls"):
            positional = positional[1:]
        params = positional + args.kwonlyargs + [a for a in (args.vararg, args.kwarg) if a is not None]
        unannotated = [a.arg for a in params if a.annotation is None]
        if unannotated:
            missing.append(f"{name}: parameters {', '.join(unannotated)}")
        if node.returns is None:
            missing.append(f"{name}: return")
    return missing


def test_every_public_function_of_the_glue_is_annotated():
    missing = [
        f"{path.relative_to(PACKAGE.parent)}::{entry}"
        for path in CHECKED
        for entry in missing_annotations(path.read_text(encoding="utf-8"))
    ]
    assert not missing, f"{len(missing)} missing annotations:\n" + "\n".join(missing)


def test_the_walk_sees_the_glue():
    assert PACKAGE / "blender" / "pipeline" / "effect.py" in CHECKED
    assert PACKAGE / "batch" / "farm.py" in CHECKED
    assert len(CHECKED) > 40


def test_the_check_finds_planted_gaps():
    source = """
def ok(a: int, *args: str, b: float = 1.0, **kw: int) -> None: ...
def no_return(a: int): ...
def bare(a, b: int) -> int: ...
def _private(a): ...
class Panel:
    def draw(self, context): ...
    @classmethod
    def poll(cls, context: object) -> bool: ...
    @staticmethod
    def helper(self) -> None: ...
    def _hidden(self, x): ...
    def outer(self) -> None:
        def inner(y): ...
class _Hidden:
    def run(self, x): ...
if True:
    def branch(*args) -> None: ...
"""
    assert missing_annotations(source) == [
        "no_return: return",
        "bare: parameters a",
        "Panel.draw: parameters context",
        "Panel.draw: return",
        "Panel.helper: parameters self",
        "branch: parameters args",
    ]
