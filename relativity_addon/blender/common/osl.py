"""OSL compilation support: make Cycles' ``oslquery`` importable and compile camera shaders.

Cycles compiles an OSL camera shader with its own Python add-on (``cycles.osl``), which imports
the bundled ``oslquery`` module. A real Blender install has it on ``sys.path``; the ``bpy`` wheel
from PyPI ships it in ``bpy/<version>/python/lib/python3.X/site-packages`` without adding that
folder, and then compilation fails and the render silently uses an empty shader.
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from bpy.types import Camera


class OSLUnavailableError(RuntimeError):
    """Cycles cannot compile OSL here (no ``oslquery``, or a build without OSL)."""


def ensure_oslquery_importable() -> None:
    """Make ``import oslquery`` work, adding the wheel's bundled site-packages if needed."""
    try:
        import oslquery  # noqa: F401

        return
    except ImportError:
        pass
    import bpy

    version = "%d.%d" % bpy.app.version[:2]
    python = "python%d.%d" % sys.version_info[:2]
    roots = [os.path.dirname(bpy.__file__)]
    roots += [os.path.dirname(os.path.dirname(path)) for path in bpy.utils.script_paths()]
    for root in roots:
        candidate = os.path.join(root, version, "python", "lib", python, "site-packages")
        if os.path.isdir(os.path.join(candidate, "oslquery")) and candidate not in sys.path:
            sys.path.append(candidate)
            break
    try:
        import oslquery  # noqa: F401
    except ImportError as error:
        raise OSLUnavailableError(
            "Cycles' oslquery module is missing, so OSL camera shaders cannot be compiled"
        ) from error


def compile_custom_camera(camera_data: Camera) -> list[str]:
    """Compile the camera's OSL shader with Cycles; return the list of error messages.

    An empty list means Cycles reported success; the caller still checks that the shader's
    parameters appeared in ``camera_data.cycles_custom``.
    """
    ensure_oslquery_importable()
    try:
        from cycles import engine, osl
    except ImportError as error:
        raise OSLUnavailableError("the Cycles add-on is not available") from error
    if not engine.with_osl():
        raise OSLUnavailableError("this Blender build has no OSL support")

    errors = []

    def report(kind: str, message: object) -> None:
        if {"ERROR", "WARNING"} & set(kind):
            errors.append(str(message))

    ok = osl.update_custom_camera_shader(camera_data, report)
    if not ok and not errors:
        errors.append("Custom Camera shader compilation failed")
    return errors
