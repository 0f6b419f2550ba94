"""Re-entrancy guard: evaluating the depsgraph inside the add-on's own update fires the
depsgraph handlers again, and a nested evaluation from a handler crashes Blender. Code that
evaluates the depsgraph or steps frames runs inside :func:`computing`; handlers return at once
while :func:`is_computing`."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

import bpy

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


_render = {"running": False}


def render_started() -> None:
    """``render_init``: a render (F12, Render Animation) runs until :func:`render_ended`."""
    _render["running"] = True


def render_ended() -> None:
    """``render_complete`` / ``render_cancel``."""
    _render["running"] = False


def rendering() -> bool:
    """Whether a render runs: handlers then run between its frames, and data made or deleted there
    is freed under the render (Blender 5.2 crashed, docs/cockpit.md). ``is_job_running`` alone is
    False in a blocking render (background mode, the ``bpy`` module)."""
    return _render["running"] or bool(getattr(bpy.app, "is_job_running")("RENDER"))  # noqa: B009


_keeping = {"depth": 0}


@contextmanager
def keeping_stand_ins() -> Iterator[None]:
    """While Bake for Render Anywhere steps its frames (``pipeline/bake.py``): the stand-in lamps of
    moving lights and their copies on moving objects are kept under their names from frame to frame
    (made when first needed, never deleted; those a frame does not use hidden from renders), so
    every frame holds the same datablocks and what changes is keyframes."""
    _keeping["depth"] += 1
    try:
        yield
    finally:
        _keeping["depth"] -= 1


def keeps_stand_ins() -> bool:
    return _keeping["depth"] > 0
