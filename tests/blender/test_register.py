"""The add-on registers and unregisters cleanly, twice in a row, leaving nothing behind.

The add-on is enabled the way Blender does it for a user: the built zip is installed into the
``user_default`` extensions repository (a temporary one, see ``tests/conftest.py``) with
``bpy.ops.extensions.package_install_files``, then enabled and disabled as
``bl_ext.user_default.relativity_addon`` with ``addon_utils.enable`` / ``addon_utils.disable``,
which is what the checkbox in Preferences > Add-ons calls.
"""

import sys

import bpy

from blender_support import ADDON_MODULE, disable_addon, enable_addon

# ID types the add-on may hang settings on; all must look the same after unregistering.
PROPERTY_OWNERS = ("Scene", "Object", "Camera", "World", "Material", "Mesh", "WindowManager")


def registered_python_classes():
    """Names of all classes registered from Python (panels, operators, property groups...)."""
    names, stack = [], [bpy.types.bpy_struct]
    while stack:
        for cls in stack.pop().__subclasses__():
            stack.append(cls)
            if cls.__module__ != "bpy.types" and getattr(cls, "is_registered", False):
                names.append(f"{cls.__module__}.{cls.__qualname__}")
    return sorted(names)


def _handler_names(handlers):
    return [f"{h.__module__}.{h.__qualname__}" for h in handlers]


def blender_state():
    """Everything an add-on can register, as comparable plain data."""
    handlers = {
        name: _handler_names(getattr(bpy.app.handlers, name))
        for name in dir(bpy.app.handlers)
        if isinstance(getattr(bpy.app.handlers, name), list)
    }
    properties = {
        owner: (
            sorted(getattr(bpy.types, owner).bl_rna.properties.keys()),
            sorted(dir(getattr(bpy.types, owner))),
        )
        for owner in PROPERTY_OWNERS
    }
    keyconfig = bpy.context.window_manager.keyconfigs.addon
    keymap_items = (
        sorted((km.name, kmi.idname) for km in keyconfig.keymaps for kmi in km.keymap_items) if keyconfig else []
    )
    return {
        "types": sorted(dir(bpy.types)),
        "classes": registered_python_classes(),
        "handlers": handlers,
        "properties": properties,
        "keymap_items": keymap_items,
        "preset_paths": sorted(bpy.utils._preset_path_registry),
        "data": {
            name: len(getattr(bpy.data, name))
            for name in dir(bpy.data)
            if isinstance(getattr(bpy.data, name), bpy.types.bpy_prop_collection)
        },
    }


def _diff(before, after):
    return {key: (before[key], after[key]) for key in before if before[key] != after[key]}


def test_register_unregister_twice_leaves_nothing(relativity_addon):
    disable_addon()
    before = blender_state()
    for _ in range(2):
        enable_addon()
        assert relativity_addon in bpy.context.preferences.addons
        assert relativity_addon in sys.modules
        disable_addon()
        assert relativity_addon not in bpy.context.preferences.addons
        assert _diff(before, blender_state()) == {}


def test_enabled_from_the_installed_extension(relativity_addon):
    module = sys.modules[relativity_addon]
    assert relativity_addon == ADDON_MODULE
    assert "extensions" in module.__file__ and "user_default" in module.__file__


def test_state_snapshot_sees_leftovers(factory_blender):
    """The comparison above can fail: a leaked class, handler and property all show up."""

    class RELATIVITY_PG_leak(bpy.types.PropertyGroup):
        speed: bpy.props.FloatProperty()

    def leaked_handler(scene, depsgraph):
        pass

    before = blender_state()
    bpy.utils.register_class(RELATIVITY_PG_leak)
    bpy.types.Scene.relativity_leak = bpy.props.PointerProperty(type=RELATIVITY_PG_leak)
    bpy.app.handlers.frame_change_post.append(leaked_handler)
    try:
        changed = _diff(before, blender_state())
    finally:
        bpy.app.handlers.frame_change_post.remove(leaked_handler)
        del bpy.types.Scene.relativity_leak
        bpy.utils.unregister_class(RELATIVITY_PG_leak)
    assert {"classes", "handlers", "properties"} <= changed.keys()
    assert _diff(before, blender_state()) == {}
