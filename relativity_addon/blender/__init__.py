"""Blender glue: property groups, node-tree builders, handlers, operators and panels.

Layers (docs/architecture.md): settings (props, objects) -> snapshot -> effect -> the render
paths (camera + osl; geometry + modifier + world_lines + bakes) and colour (colour, materials,
compositing, luts), on shared leaves (names, nodes, compat, busy, animation, sources).

Each module listed in ``_MODULES`` may define ``classes`` (registered in order, unregistered in
reverse) and ``register()`` / ``unregister()`` hooks for anything else it installs (properties
on ID types, handlers, preset paths). Modules are registered in list order and unregistered in
reverse, so a module may rely on everything listed before it.
"""

from __future__ import annotations

import importlib

_MODULES = (
    "ui.props",  # Scene.relativity
    "ui.objects",  # Object.relativity
    "ui.presets",  # preset menus and the shipped presets folder
    "ui.ops",  # Set Up, Remove, Check Camera Speed
    "geometry.bakes",  # Bake Motion, Bake Deformation
    "ui.panel",  # the N-panel
    "pipeline.handlers",  # the handler table (effect.sync)
)


def _modules():
    return [importlib.import_module(f".{name}", __name__) for name in _MODULES]


def register() -> None:
    import bpy

    for module in _modules():
        for cls in getattr(module, "classes", ()):
            bpy.utils.register_class(cls)
        if hasattr(module, "register"):
            module.register()


def unregister() -> None:
    import bpy

    for module in reversed(_modules()):
        if hasattr(module, "unregister"):
            module.unregister()
        for cls in reversed(getattr(module, "classes", ())):
            bpy.utils.unregister_class(cls)
