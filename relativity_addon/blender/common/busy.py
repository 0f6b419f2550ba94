"""Re-entrancy guard: evaluating the depsgraph inside the add-on's own update fires the
depsgraph handlers again, and a nested evaluation from a handler crashes Blender. Code that
evaluates the depsgraph or steps frames runs inside :func:`computing`; handlers return at once
while :func:`is_computing`."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterator

_depth = 0


@contextmanager
def computing() -> Iterator[None]:
    global _depth
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1


def is_computing() -> bool:
    return _depth > 0
