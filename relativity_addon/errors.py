"""Errors the add-on reports to its users. Imports neither bpy nor numpy, so the Blender glue, the
batch script and the physics core's callers can all share it."""


class RelativityError(Exception):
    """A user-facing problem that prevents a physically correct render (one-line message).

    The message is shown as it is (an operator's report, the panel's warnings, the batch
    script's last line before it exits non-zero), never with a traceback: it names what is wrong
    and, where there is one, what to do about it.
    """


class BatchError(Exception):
    """A one-line reason why the batch render (``examples/render.py``) cannot proceed."""
