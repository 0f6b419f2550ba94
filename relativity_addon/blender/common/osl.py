"""OSL compilation support: whether this Blender can compile OSL, and compiling camera shaders.

Cycles compiles an OSL camera shader with its own Python add-on (``cycles.osl``), which imports
the bundled ``oslquery`` module. A real Blender install has it on ``sys.path``; the ``bpy`` wheel
from PyPI ships it in ``bpy/<version>/python/lib/python3.X/site-packages`` without adding that
folder, and then compilation fails and the render silently uses an empty shader.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from bpy.types import Camera


NO_OSL = "This Blender build has no OSL (Open Shading Language)"
NO_OSL_COMPILER = "This Blender build cannot compile OSL shaders (Open Shading Language)"


class OSLUnavailableError(RuntimeError):
    """Cycles cannot compile OSL here (a build without OSL, or without its shader compiler)."""


def unavailable_reason() -> str | None:
    """Why this Blender cannot render the add-on's OSL shaders (one line for the user), or None.

    The one place the add-on decides whether OSL is available: Cycles must be built with OSL
    (``_cycles.with_osl``; Debian's 5.2 is not) and its ``oslquery`` module must import, from the
    wheel's bundled folder if needed."""
    try:
        import _cycles  # type: ignore[import-not-found]  # Cycles' C module, no stubs
    except ImportError:
        return NO_OSL
    if not getattr(_cycles, "with_osl", False):
        return NO_OSL
    if not _import_oslquery():
        return NO_OSL_COMPILER
    return None


def _import_oslquery() -> bool:
    """Whether ``import oslquery`` works, adding the wheel's bundled site-packages if needed."""
    try:
        import oslquery  # noqa: F401

        return True
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
    except ImportError:
        return False
    return True


def ensure_oslquery_importable() -> None:
    """Make ``import oslquery`` work; OSLUnavailableError (one line for the user) if OSL cannot
    be compiled here."""
    reason = unavailable_reason()
    if reason is not None:
        raise OSLUnavailableError(reason)


@contextlib.contextmanager
def compiling() -> Iterator[None]:
    """Around anything that makes Cycles compile an OSL text datablock (assigning a script node's
    or camera's shader, ``cycles.osl.update_*``): Cycles' own add-on compiles an in-memory text
    to a temporary ``.oso`` file it never deletes (``osl_compile`` in ``cycles/osl.py``, 40-170 kB
    a compile). The temporary files go to a private folder removed afterwards, so nothing is left
    in the user's temporary folder."""
    previous = tempfile.tempdir
    with tempfile.TemporaryDirectory(prefix="relativity-osl-") as folder:
        tempfile.tempdir = folder
        try:
            yield
        finally:
            tempfile.tempdir = previous


def compile_custom_camera(camera_data: Camera) -> list[str]:
    """Compile the camera's OSL shader with Cycles; return the list of error messages.

    An empty list means Cycles reported success; the caller still checks that the shader's
    parameters appeared in ``camera_data.cycles_custom``.
    """
    ensure_oslquery_importable()
    try:
        from cycles import engine, osl
    except ImportError as error:
        raise OSLUnavailableError("Cycles is not available in this Blender") from error
    if not engine.with_osl():
        raise OSLUnavailableError(NO_OSL)

    errors = []

    def report(kind: str, message: object) -> None:
        if {"ERROR", "WARNING"} & set(kind):
            errors.append(str(message))

    with compiling():
        ok = osl.update_custom_camera_shader(camera_data, report)
    if not ok and not errors:
        errors.append("Custom Camera shader compilation failed")
    return errors
