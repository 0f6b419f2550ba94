"""The add-on's handlers, in one table: each brings the effect up to date through ``effect.sync``.

Order within a frame change: ``frame_change_pre`` writes the camera's parameters and the colour
factors for the new frame (Cycles reads shader values written there, also in an animation
render); ``frame_change_post`` updates the apparent geometry, which needs the new frame's
evaluated meshes. ``depsgraph_update_post`` follows every edit. Only objects whose inputs
changed are recomputed (the frame is one of them), and values are written only where they
changed, so the handlers' own writes end the loop. ``render_pre`` runs before every render,
attaching the Doppler colour to materials added since Set Up. ``render_init`` (once per still or
animation render, on the main thread) first evaluates the frame again when a keyframed object was
moved without a key (the render evaluates its keys: ``_keys_before_render``), then puts an
Apparent Geometry scene with a moving observer behind the exact camera for the render;
``render_complete``/``render_cancel`` take it back to the boosted-mesh preview
(``effect.begin_final_render``). A handler never raises: a problem
becomes the scene's warning and, for the exact camera, a black (never a wrong) image; a render of a
set-up scene whose sync is refused is recorded in ``render_notice`` (the panel shows it, and a popup
after the render when Blender has a window), also when the exact camera's Type or the Render Engine
was changed after Set Up, which renders without the relativistic camera.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
from bpy.app.handlers import persistent

from ..camera import exact_camera
from ..common import busy
from ..geometry import apparent_meshes, keyframed
from ..scene import animation
from . import effect, render_notice, stages

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Scene


def _sync(scene, **options):
    try:
        return effect.sync(scene, **options)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: not synced: {type(error).__name__}: {error}")
        return None


# (scene, frame, subframe, {object session_uid: keys signature}) of the last frame_change_pre: its
# frame_change_post reads no key again (between the two, Blender evaluates the frame, no script runs).
_keys_read: list[tuple | None] = [None]


@persistent
def frame_change_pre(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    kept: dict[object, object] = {}
    with animation.signed_once(kept):
        _sync(scene, update_geometry=False, record=False)  # (frame_change_post records)
    _keys_read[0] = (scene.name, scene.frame_current, scene.frame_subframe, kept)


@persistent
def frame_change_post(scene: Scene, depsgraph: Depsgraph | None = None) -> None:
    read, _keys_read[0] = _keys_read[0], None
    same = read is not None and read[:3] == (scene.name, scene.frame_current, scene.frame_subframe)
    with animation.signed_once(read[3] if same and read is not None else None):
        _sync(scene, depsgraph=depsgraph, in_frame_change=True)
    if apparent_meshes.deferred() and not bpy.app.background:
        # positions of a new subdivision, computed outside the frame change (the batch script
        # syncs after each frame change itself; timers do not run in the background)
        name = scene.name
        bpy.app.timers.register(lambda: _sync_later(name), first_interval=0.0)


def _sync_later(name):
    scene = bpy.data.scenes.get(name)
    if scene is not None:
        _sync(scene)


@persistent
def depsgraph_update_post(scene: Scene, depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, depsgraph=depsgraph)


@persistent
def render_pre(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    _sync(scene, update_geometry=False, attach_new_materials=True, before_render=True)
    try:
        _tell_if_refused(scene)
    except Exception as error:  # noqa: BLE001
        print(f"Relativity: {type(error).__name__}: {error}")


def _tell_if_refused(scene):
    """A set-up scene whose sync was refused renders black (exact camera) or its last valid state:
    record why for the panel and the popup (``render_notice``)."""
    camera_object = scene.camera
    exact = camera_object is not None and camera_object.type == "CAMERA" and exact_camera.is_applied(camera_object.data)
    if not exact and effect.applied_method(scene) is None:
        render_notice.render_accepted(scene)  # never set up: an ordinary render
        return
    # the OSL camera renders (black when invalid) only as a Custom camera in Cycles; a Type or
    # Render Engine changed after Set Up renders without it
    osl_renders = exact and camera_object.data.type == "CUSTOM" and scene.render.engine == "CYCLES"
    black = osl_renders and not camera_object.data.cycles_custom.get("settings_valid", False)
    if not black and effect.last_snapshot(scene) is not None:
        render_notice.render_accepted(scene)
        return
    warnings = effect.scene_warnings(scene)
    reason = warnings[0] if warnings else "the relativistic camera is invalid"
    render_notice.render_refused(scene, reason, black, relativistic=osl_renders or not exact)


@persistent
def render_init(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    busy.render_started()
    try:
        _keys_before_render(scene)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: {type(error).__name__}: {error}")
    try:
        effect.begin_final_render(scene)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: the final render stays the boosted-mesh preview: {error}")
    try:
        stages.render_init(scene)
    except Exception as error:  # noqa: BLE001 - a handler must never stop Blender or the render
        print(f"Relativity: {type(error).__name__}: {error}")


def _keys_before_render(scene):
    """A set-up scene whose keyframed objects were moved without a key (``keyframed.off_their_keys``)
    is evaluated at its frame again before the render, as the render evaluates it (its keys win):
    otherwise the add-on's inputs, computed from the values the viewport shows, would not be those of
    the object rendered (a silently wrong image). Said on the console and, with a window, in a popup."""
    if effect.applied_method(scene) is None:
        return
    moved = keyframed.off_their_keys(scene)
    if not moved:
        return
    scene.frame_set(scene.frame_current, subframe=scene.frame_subframe)
    listed = ", ".join(repr(obj.name) for obj in moved[:3]) + (f" and {len(moved) - 3} more" if len(moved) > 3 else "")
    reason = (
        f"{listed} moved without a key: rendered where the keys put {'it' if len(moved) == 1 else 'them'} "
        f"at frame {scene.frame_current}, as Blender renders (insert a key to keep a move)"
    )
    print(f"Relativity: {reason}")
    render_notice.tell("Relativity: a change without a key is not rendered", reason)


@persistent
def render_end(scene: Scene, _depsgraph: Depsgraph | None = None) -> None:
    busy.render_ended()
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
    render_notice.register()
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler not in handlers:
            handlers.append(handler)


def unregister() -> None:
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
    render_notice.unregister()
