"""Telling the user, in the application, that a render of a set-up scene was refused.

A render started with F12 is Blender's operator, not ours: it finishes, and the exact camera,
marked invalid by the refused sync, renders black (never a wrong image). ``render_pre``
(``handlers.py``) records the reason here; the panel reads it (:func:`last_refusal`), and when
Blender has a window a popup names it after the render. The render handlers run on the render
thread, which must not touch the UI: they queue the notice, and a timer on the main thread shows
it (the pattern of ``bpy.app.timers``' documentation). In background mode nothing is queued: the
batch script checks the camera itself and exits 1 with the reason.
"""

from __future__ import annotations

import queue
from typing import TYPE_CHECKING

import bpy

if TYPE_CHECKING:
    from bpy.types import Scene

POLL_SECONDS = 0.5

_last = {}  # scene name -> why its last render was refused
_pending = queue.Queue()  # (title, reason) for the main thread


def render_refused(scene: Scene, reason: str, black: bool, relativistic: bool = True) -> None:
    """Record that the render of ``scene`` starting now is refused for ``reason`` (one line);
    ``black``: the exact camera renders black (else the last valid state is rendered, or, not
    ``relativistic``, an ordinary picture: the exact camera's Type or the engine changed). Any thread."""
    _last[scene.name] = reason
    if not _background():
        if black:
            title = "Relativity: this render is black"
        elif not relativistic:
            title = "Relativity: this render is not relativistic"
        else:
            title = "Relativity: this render is not up to date"
        _pending.put((title, reason))


def tell(title: str, reason: str) -> None:
    """A popup with ``reason`` (one line) when Blender has a window; nothing in background mode
    (the batch script and the panel say it there). Any thread."""
    if not _background():
        _pending.put((title, reason))


def _background():
    return bpy.app.background


def render_accepted(scene: Scene) -> None:
    _last.pop(scene.name, None)


def last_refusal(scene: Scene) -> str | None:
    """Why the last render of ``scene`` was refused, or None."""
    return _last.get(scene.name)


def _popup(title, reason):
    if _background():  # the window manager of background Blender has windows, but a popup there crashes
        return
    window_manager = bpy.context.window_manager

    def draw(menu, _context):
        menu.layout.label(text=reason)
        menu.layout.label(text="The Relativity panel (View3D > Sidebar) says what to change")

    window = window_manager.windows[0] if window_manager.windows else None
    if window is None:
        return
    with bpy.context.temp_override(window=window):
        window_manager.popup_menu(draw, title=title, icon="ERROR")


def show_pending() -> float:
    """The main-thread timer: show every queued notice (the last one per reason). Never raises."""
    shown = set()
    while True:
        try:
            notice = _pending.get_nowait()
        except queue.Empty:
            break
        if notice in shown:
            continue
        shown.add(notice)
        try:
            _popup(*notice)
        except Exception as error:  # noqa: BLE001 - a timer must never stop Blender
            print(f"Relativity: {notice[1]} (no popup: {error})")
    return POLL_SECONDS


def register() -> None:
    if not _background() and not bpy.app.timers.is_registered(show_pending):
        bpy.app.timers.register(show_pending, first_interval=POLL_SECONDS, persistent=True)


def unregister() -> None:
    if bpy.app.timers.is_registered(show_pending):
        bpy.app.timers.unregister(show_pending)
    _last.clear()
