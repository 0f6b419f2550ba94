"""Helpers for tests that enable the add-on in the ``bpy`` wheel (fixtures are in conftest.py).

Importing this module does not import ``bpy``; ``tests/conftest.py`` must have set
``BLENDER_USER_RESOURCES`` before the first ``import bpy``.
"""

EXTENSION_REPO = "user_default"
ADDON_MODULE = f"bl_ext.{EXTENSION_REPO}.relativity_addon"
# Module name prefixes whose classes and handlers count as the add-on's leftovers.
_ADDON_PREFIXES = (ADDON_MODULE, "relativity_addon")


def _raise(ex):
    raise ex


def _is_ours(obj):
    return getattr(obj, "__module__", "").startswith(_ADDON_PREFIXES)


def registered_addon_classes():
    """bpy classes defined by the add-on that are still registered with Blender."""
    import bpy

    found, stack = [], [bpy.types.bpy_struct]
    while stack:
        cls = stack.pop()
        for sub in cls.__subclasses__():
            stack.append(sub)
            if _is_ours(sub) and getattr(sub, "is_registered", False):
                found.append(sub)
    return found


def remove_addon_leftovers():
    """Unregister classes and remove handlers the add-on left behind (they survive a reset)."""
    import bpy

    for name in dir(bpy.app.handlers):
        handlers = getattr(bpy.app.handlers, name)
        if isinstance(handlers, list):
            handlers[:] = [h for h in handlers if not _is_ours(h)]
    for cls in registered_addon_classes():
        bpy.utils.unregister_class(cls)


def enable_addon(module=ADDON_MODULE):
    """Enable the add-on like the Preferences checkbox does; any exception propagates."""
    import addon_utils

    mod = addon_utils.enable(module, default_set=True, handle_error=_raise)
    assert mod is not None, f"addon_utils.enable({module!r}) failed"
    return mod


def disable_addon(module=ADDON_MODULE):
    """Disable the add-on (runs its ``unregister``); any exception propagates."""
    import addon_utils

    addon_utils.disable(module, default_set=True, handle_error=_raise)


def install_extension_zip(zip_path, repo=EXTENSION_REPO):
    """Install the zip into a local extensions repository, as Install from Disk does."""
    import bpy

    result = bpy.ops.extensions.package_install_files(
        filepath=str(zip_path),
        repo=repo,
        enable_on_install=False,
    )
    assert result == {"FINISHED"}, result
