"""Presets through Blender's own preset system: menus, add/remove operators, shipped preset files.

The shipped presets live in the top-level ``presets/relativity/<kind>/`` folder of the repository;
the extension build copies it into the package as ``presets/``, and ``register`` adds the folder
holding it with ``bpy.utils.register_preset_path``. Each preset is a small Python file run by
``script.execute_preset``; presets the user saves with the "+" button go to the user's scripts
folder (``presets/relativity/<kind>/``) like any other Blender preset.

Kinds: ``speed`` (|beta| along the current direction, or the camera's view from rest),
``speed_of_light`` (real and slow light), ``shutter`` (Gray et al. shutter models) and
``paper_setups`` (Weiskopf et al. 1999 street and Sun; Gray et al. 2020 beta = (0.1, 0, 0.99), Figs. 9, 10 and 11).
"""

import os

import bpy
from bl_operators.presets import AddPresetBase
from bpy.types import Menu, Operator

PRESET_ROOT = "relativity"
_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_registered_path = None


def preset_search_path() -> str | None:
    """The folder containing ``presets/relativity``: the package (built extension) or, when the
    add-on runs from a source checkout, the repository root."""
    for candidate in (_PACKAGE_DIR, os.path.dirname(_PACKAGE_DIR)):
        if os.path.isdir(os.path.join(candidate, "presets", PRESET_ROOT)):
            return candidate
    return None


def preset_subdir(kind: str) -> str:
    return f"{PRESET_ROOT}/{kind}"


def preset_files(kind: str) -> list[str]:
    """Absolute paths of all presets of ``kind`` Blender can see, sorted by file name."""
    files = []
    for directory in bpy.utils.preset_paths(preset_subdir(kind)):
        files += [os.path.join(directory, name) for name in os.listdir(directory) if name.endswith(".py")]
    return sorted(files, key=os.path.basename)


def _preset_menu(kind, label):
    return type(
        f"RELATIVITY_MT_{kind}_presets",
        (Menu,),
        {
            "bl_label": label,
            "preset_subdir": preset_subdir(kind),
            "preset_operator": "script.execute_preset",
            "draw": Menu.draw_preset,
        },
    )


RELATIVITY_MT_speed_presets = _preset_menu("speed", "Speed Presets")
RELATIVITY_MT_speed_of_light_presets = _preset_menu("speed_of_light", "Speed of Light Presets")
RELATIVITY_MT_shutter_presets = _preset_menu("shutter", "Shutter Presets")
RELATIVITY_MT_paper_setups_presets = _preset_menu("paper_setups", "Paper Setups")

_DEFINES = ["settings = bpy.context.scene.relativity"]


class RELATIVITY_OT_speed_preset_add(AddPresetBase, Operator):
    """Save the observer velocity as a preset, or remove the chosen one"""

    bl_idname = "relativity.speed_preset_add"
    bl_label = "Add Velocity Preset"
    preset_menu = "RELATIVITY_MT_speed_presets"
    preset_subdir = preset_subdir("speed")
    preset_defines = _DEFINES
    preset_values = ["settings.velocity_source", "settings.beta"]


class RELATIVITY_OT_speed_of_light_preset_add(AddPresetBase, Operator):
    """Save the speed of light as a preset, or remove the chosen one"""

    bl_idname = "relativity.speed_of_light_preset_add"
    bl_label = "Add Speed of Light Preset"
    preset_menu = "RELATIVITY_MT_speed_of_light_presets"
    preset_subdir = preset_subdir("speed_of_light")
    preset_defines = _DEFINES
    preset_values = ["settings.speed_of_light"]


class RELATIVITY_OT_shutter_preset_add(AddPresetBase, Operator):
    """Save the shutter settings as a preset, or remove the chosen one"""

    bl_idname = "relativity.shutter_preset_add"
    bl_label = "Add Shutter Preset"
    preset_menu = "RELATIVITY_MT_shutter_presets"
    preset_subdir = preset_subdir("shutter")
    preset_defines = _DEFINES
    preset_values = [
        "settings.shutter_model",
        "settings.shutter_time",
        "settings.shutter_plane_point",
        "settings.shutter_plane_normal",
        "settings.imaging_element",
        "settings.use_lorentz_window",
        "settings.lorentz_window_shutter",
        "settings.lorentz_window_time",
    ]


classes = (
    RELATIVITY_MT_speed_presets,
    RELATIVITY_MT_speed_of_light_presets,
    RELATIVITY_MT_shutter_presets,
    RELATIVITY_MT_paper_setups_presets,
    RELATIVITY_OT_speed_preset_add,
    RELATIVITY_OT_speed_of_light_preset_add,
    RELATIVITY_OT_shutter_preset_add,
)


def register() -> None:
    global _registered_path
    path = preset_search_path()
    if path is not None and bpy.utils.register_preset_path(path):
        _registered_path = path


def unregister() -> None:
    global _registered_path
    if _registered_path is not None:
        bpy.utils.unregister_preset_path(_registered_path)
        _registered_path = None
