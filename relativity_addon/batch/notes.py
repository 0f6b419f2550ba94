"""The N-panel's lines on the command line: printed once per run as ``render.py: note: ...``, by the
batch script (``batch.panel_lines`` after Set Up and each frame) and by a farm's coordinator (the
lines each frame's reply carries, ``farm.py``). Pure Python: the coordinator has no Blender."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable


def say(lines: Iterable[str], said: set[str], log: Callable[..., object]) -> None:
    """Each of ``lines`` not in ``said`` printed as ``render.py: note: ...`` and added to it: a
    pipeline user sees what an artist sees in the N-panel, once per run."""
    for line in lines:
        if line not in said:
            said.add(line)
            log(f"render.py: note: {line}", flush=True)
