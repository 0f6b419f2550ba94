"""Ray-visibility flags switched off while the effect is applied and given back on removal: the
user's values are kept in an ID property on the object (so a saved file restores them too)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterable

    from bpy.types import Object


def hide(obj: Object, key: str, attributes: Iterable[str]) -> None:
    """Switch ``attributes`` (``visible_camera``, ``visible_diffuse``, ...) off, the user's values
    saved under ``key`` the first time."""
    if key not in obj:
        obj[key] = {name: bool(getattr(obj, name)) for name in attributes}
    for name in attributes:
        if getattr(obj, name):
            setattr(obj, name, False)


def saved(obj: Object, key: str, name: str) -> bool:
    """The user's value of ``name`` (saved under ``key`` while hidden, else the object's own)."""
    values = obj.get(key)
    return bool(getattr(obj, name) if values is None else values[name])


def restore(obj: Object, key: str) -> bool:
    """Give back the values saved under ``key``; whether there were any."""
    values = obj.get(key)
    if values is None:
        return False
    values = values.to_dict()
    del obj[key]
    for name, value in values.items():
        if getattr(obj, name) != value:
            setattr(obj, name, value)
    return True
