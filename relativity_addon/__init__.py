"""Relativity: photograph what a camera moving near the speed of light would really see.

The physics core (``relativity_addon.physics``) imports numpy and colour-science but never
``bpy``; the Blender glue lives in ``relativity_addon.blender`` and is imported only when
Blender registers the extension, so the core stays importable (and testable) without Blender.
"""


def register() -> None:
    from . import blender

    blender.register()


def unregister() -> None:
    from . import blender

    blender.unregister()
