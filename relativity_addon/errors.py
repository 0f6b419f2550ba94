"""The add-on's one user-facing error type, free of ``bpy`` so that the batch script and the
physics-facing code can raise and catch it without Blender."""


class RelativityError(Exception):
    """A user-facing problem that prevents a physically correct render (one-line message)."""
