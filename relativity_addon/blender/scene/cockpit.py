"""The read side of objects moving with the camera (``Object.relativity.moves_with_camera``):
which objects of a scene are at rest in the camera's frame (Gray et al. 2020, appendix A).

``camera/cockpit.py`` renders them at rest and lays them over the relativistic render;
``snapshot.moving_lights`` gives a light among them the camera's velocity (docs/cockpit.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import census

if TYPE_CHECKING:
    from bpy.types import Object, Scene


def moves_with_camera(obj: Object) -> bool:
    return bool(obj.relativity.moves_with_camera)


def offered(scene: Scene, obj: Object) -> bool:
    """Whether the panel offers *Moves With Camera*: ``obj`` hangs under the scene's camera (its
    parent, or a parent's parent)."""
    camera = scene.camera if scene is not None else None
    link = obj.parent
    while link is not None and camera is not None:
        if link == camera:
            return True
        link = link.parent
    return False


def object_names(scene: Scene) -> tuple[str, ...]:
    """The scene's objects that move with the camera, lights included, sorted by name."""
    return tuple(
        sorted(entry.obj.name for entry in census.entries(scene) if entry.with_camera and entry.type != "CAMERA")
    )
