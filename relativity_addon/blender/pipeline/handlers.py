"""The add-on's handlers, in one table: each brings the effect up to date through ``effect.sync``.

Order within a frame change: ``frame_change_pre`` writes the camera's parameters and the colour
factors for the new frame (Cycles reads shader values written there, also in an animation
render); ``frame_change_post`` updates the apparent geometry, which needs the new frame's
evaluated meshes. ``depsgraph_update_post`` follows every edit. Only objects whose inputs
changed are recomputed (the frame is one of them), and values are written only where they
changed, so the handlers' own writes end the loop. ``render_pre`` runs before every render,
attaching the Doppler colour to materials added since Set Up. ``render_init`` (once per still or
animation render) puts an Apparent Geometry scene with a moving observer behind the exact camera
for the render, ``render_complete``/``render_cancel`` take it back to the boosted-mesh preview
(``effect.begin_final_render``). A handler never raises: a problem
becomes the scene's warning and, for the exact camera, a black (never a wrong) image.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
from bpy.app.handlers import persistent

from . import effect

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Scene


def _sync(scene, **options):
    try:
        effect.sync(scene, **options)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: not synced: {type(error).__name__}: {error}")


@persistent
def frame_change_pre(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, update_geometry=False)


@persistent
def frame_change_post(scene: Scene, depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, depsgraph=depsgraph)


@persistent
def depsgraph_update_post(scene: Scene, depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, depsgraph=depsgraph)


@persistent
def render_pre(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, update_geometry=False, attach_new_materials=True, before_render=True)


@persistent
def render_init(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    try:
        effect.begin_final_render(scene)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: the final render stays the boosted-mesh preview: {error}")


@persistent
def render_end(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    try:
        effect.end_final_render(scene)
    except Exception as error:  # noqa: BLE001
        print(f"Relativity: not restored after the render: {type(error).__name__}: {error}")


HANDLERS = (
    ("frame_change_pre", frame_change_pre),
    ("frame_change_post", frame_change_post),
    ("depsgraph_update_post", depsgraph_update_post),
    ("render_pre", render_pre),
    ("render_init", render_init),
    ("render_complete", render_end),
    ("render_cancel", render_end),
)


def register() -> None:
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler not in handlers:
            handlers.append(handler)


def unregister() -> None:
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
