"""The N-panel: View3D > Sidebar > Relativity, with sub-panels as Blender's own panels have them.

Nothing here computes: the warnings come from the effect's last sync (``effect.scene_warnings``,
``mesh_notes.object_warnings``), and so does the speed taken from the camera's animation.
"""

import math
import textwrap

from bpy.types import Context, Panel

from ..common import osl
from ..pipeline import bake, effect, mesh_notes, render_notice
from ..scene import cockpit

CHARACTER_WIDTH = 7.0  # pixels per character of the sidebar's text at UI scale 1 (a mean)
LABEL_MARGIN = 60.0  # pixels of a label row not given to its text (icon, padding, scroll bar)


def _split(layout):
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout


def _lines(context, text):
    """``text`` split into lines that fit the region's width (a label cuts what does not fit);
    one line where no region is drawn into."""
    region = getattr(context, "region", None)
    if region is None:
        return [text]
    width = region.width
    preferences = getattr(context, "preferences", None)
    scale = (preferences.system.ui_scale if preferences is not None else 0.0) or 1.0  # 0 in background
    columns = max(16, int((width - LABEL_MARGIN) / (CHARACTER_WIDTH * scale)))
    return textwrap.wrap(text, columns) or [""]


def _message(layout, context, text, icon="ERROR"):
    """A warning drawn whole: wrapped to the sidebar's width, the icon on its first line."""
    column = layout.column(align=True)
    for number, line in enumerate(_lines(context, text)):
        column.label(text=line, icon=icon if number == 0 else "BLANK1")


def _preset_row(layout, kind, label):
    row = layout.row(align=True)
    row.menu(f"RELATIVITY_MT_{kind}_presets", text=label)
    row.operator(f"relativity.{kind}_preset_add", text="", icon="ADD")
    row.operator(f"relativity.{kind}_preset_add", text="", icon="REMOVE").remove_active = True


class _RelativityPanel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Relativity"

    @classmethod
    def poll(cls, context: Context) -> bool:
        return context.scene is not None


class RELATIVITY_PT_main(_RelativityPanel, Panel):
    bl_idname = "RELATIVITY_PT_main"
    bl_label = "Relativity"

    def draw(self, context: Context) -> None:
        scene = context.scene
        layout = _split(self.layout)
        layout.menu("RELATIVITY_MT_paper_setups_presets", text="Paper Setups")
        layout.prop(scene.relativity, "method")
        no_osl = osl.unavailable_reason()
        if scene.relativity.method == "GEOMETRY":
            layout.prop(scene.relativity, "geometry_final_render")
            _message(layout, context, "The viewport shows the boosted-mesh preview", icon="INFO")
            if no_osl is not None and scene.relativity.geometry_final_render == "EXACT":
                _message(layout, context, f"{no_osl}: the final render is the boosted-mesh preview too")
        notice = effect.setup_notice(scene)
        if notice is not None:
            _message(layout, context, notice)
        refused = render_notice.last_refusal(scene)
        if refused is not None:
            _message(layout, context, f"Last render refused: {refused}")
        for warning in effect.scene_warnings(scene):
            _message(layout, context, warning)
        column = layout.column(align=True)
        column.operator("relativity.setup_scene", icon="PLAY")
        column.operator("relativity.remove_all", icon="X")
        baked = bake.baked_frames(scene)
        if baked is not None:
            layout.label(text=f"Baked frames {baked[0]}-{baked[1]}: bake again after changes", icon="INFO")
        layout.operator("relativity.bake_render_anywhere", icon="RENDER_ANIMATION")


class RELATIVITY_PT_observer(_RelativityPanel, Panel):
    bl_idname = "RELATIVITY_PT_observer"
    bl_label = "Observer"
    bl_parent_id = "RELATIVITY_PT_main"

    def draw(self, context: Context) -> None:
        scene = context.scene
        settings = scene.relativity
        layout = _split(self.layout)
        layout.prop(settings, "velocity_source")
        _preset_row(layout, "speed", "Speed")
        column = layout.column()
        column.enabled = settings.velocity_source == "MANUAL"
        column.prop(settings, "beta")
        if settings.velocity_source == "CAMERA_ANIMATION":  # as of the last sync: no F-curves in draw
            snap = effect.last_snapshot(scene)
            speed = snap.speed if snap is not None else math.nan
        else:
            speed = settings.speed
        box = layout.box()
        if math.isnan(speed):  # the camera's animation was not read: the last sync was refused
            box.label(text="Speed: unknown (see the warning above)")
        else:
            box.label(text=f"Speed: {speed:.6g} c")
            gamma = 1.0 / math.sqrt(1.0 - speed * speed) if speed < 1.0 else math.nan
            box.label(text=f"Gamma: {gamma:.6g}" if speed < 1.0 else "Gamma: undefined (speed >= c)")
        tau = effect.traveller_time(context.scene)  # as of the last sync
        if tau is not None:
            fps = context.scene.render.fps / context.scene.render.fps_base
            box.label(text=f"Scene time: {context.scene.frame_current / fps:.4g} s")
            box.label(text=f"Traveller's time: {tau:.4g} s")
        if settings.velocity_source == "CAMERA_ANIMATION":
            layout.operator("relativity.check_animation", icon="TIME")
        _preset_row(layout, "speed_of_light", "Speed of Light")
        layout.prop(settings, "speed_of_light")


class RELATIVITY_PT_shutter(_RelativityPanel, Panel):
    bl_idname = "RELATIVITY_PT_shutter"
    bl_label = "Camera and Shutter"
    bl_parent_id = "RELATIVITY_PT_main"

    def draw(self, context: Context) -> None:
        settings = context.scene.relativity
        layout = _split(self.layout)
        _preset_row(layout, "shutter", "Shutter")
        layout.prop(settings, "shutter_model")
        layout.prop(settings, "shutter_time")
        if settings.shutter_model == "DETECTOR_PLANE":
            layout.prop(settings, "imaging_element")
        if settings.shutter_model == "ARBITRARY_PLANE":
            layout.prop(settings, "shutter_plane_point", text="Plane Point")
            layout.prop(settings, "shutter_plane_normal", text="Plane Normal")
        layout.prop(settings, "use_lorentz_window")
        if settings.use_lorentz_window:
            layout.prop(settings, "lorentz_window_shutter")
            if settings.lorentz_window_shutter == "SHUTTER_MODEL":
                layout.prop(settings, "lorentz_window_time")


class RELATIVITY_PT_effects(_RelativityPanel, Panel):
    bl_idname = "RELATIVITY_PT_effects"
    bl_label = "Effects"
    bl_parent_id = "RELATIVITY_PT_main"

    def draw(self, context: Context) -> None:
        settings = context.scene.relativity
        layout = _split(self.layout)
        column = layout.column(heading="Effects")
        column.prop(settings, "use_geometry")
        row = column.row()
        row.active = settings.use_geometry and settings.method == "CAMERA"
        row.prop(settings, "use_time_of_flight")
        time_of_flight = settings.use_time_of_flight
        if time_of_flight:
            _message(
                column,
                context,
                "Light delay only (Galilean, Gray Fig. 1c): no contraction, searchlight or Doppler",
                icon="INFO",
            )
        elif settings.method != "CAMERA":
            _message(column, context, "Time of Flight Only: exact camera only", icon="INFO")
        colour = column.column()
        colour.active = not time_of_flight
        colour.prop(settings, "use_doppler")
        colour.prop(settings, "use_searchlight")
        row = colour.row()
        row.active = settings.use_searchlight and not time_of_flight
        row.prop(settings, "use_chang_searchlight", text="Chang (Wrong)")
        row = colour.row()
        row.active = settings.use_doppler and not settings.use_searchlight and not time_of_flight
        row.prop(settings, "doppler_only_brightness")
        if settings.method == "CAMERA":
            row = colour.column(align=True)  # one line each: side by side the sidebar cut "Blackbody"
            row.active = settings.use_doppler and not time_of_flight
            row.prop(settings, "fast_illuminant")
            if settings.fast_illuminant == "BLACKBODY":
                row.prop(settings, "fast_illuminant_temperature", text="Temperature")
            snap = effect.last_snapshot(context.scene)
            if snap is not None and snap.lit_groups and settings.fast_illuminant == "AUTO":
                kelvins = ", ".join(f"{group.temperature:.0f} K" for group in snap.lit_groups)
                colour.label(text=f"Blackbody lamps: {kelvins}", icon="LIGHT")
        column = layout.column()
        column.active = settings.use_searchlight and not time_of_flight
        column.prop(settings, "exposure_mode")
        snap = effect.last_snapshot(context.scene)
        if settings.exposure_mode == "COMPENSATED" and snap is not None:
            column.label(text=f"Exposure x{snap.exposure:.4g} ({math.log2(snap.exposure):+.2f} stops)")
        if settings.method == "CAMERA":
            layout.prop(settings, "moving_light_shadows", text="Moving Shadows")
            column = layout.column(heading="Spectral")
            column.prop(settings, "spectral_passes")
            column.operator("relativity.render_spectral", icon="RENDER_STILL")


class RELATIVITY_PT_object(_RelativityPanel, Panel):
    bl_idname = "RELATIVITY_PT_object"
    bl_label = "Active Object"
    bl_parent_id = "RELATIVITY_PT_main"

    @classmethod
    def poll(cls, context: Context) -> bool:
        return context.scene is not None and context.object is not None

    def draw(self, context: Context) -> None:
        obj = context.object
        settings = obj.relativity
        layout = _split(self.layout)
        layout.label(text=obj.name, icon="OBJECT_DATA")
        if settings.moves_with_camera or cockpit.offered(context.scene, obj):
            layout.prop(settings, "moves_with_camera")
            if settings.moves_with_camera and obj.type != "LIGHT":
                return
        if obj.type == "LIGHT":
            _draw_light(layout, context, obj)
            return
        if obj.type != "MESH":
            _message(layout, context, "Apparent geometry moves meshes only", icon="INFO")
            return
        layout.prop(settings, "enabled")
        column = layout.column()
        column.active = settings.enabled
        column.prop(settings, "motion")
        if settings.motion == "CONSTANT":
            column.prop(settings, "beta")
            column.prop(settings, "lights_scene")
        elif settings.motion == "ANIMATION":
            column.prop(settings, "use_deformation")
            column.prop(settings, "samples_per_frame")
        if settings.motion != "STATIC":
            column.prop(settings, "use_proper_time")
        column.prop(settings, "tessellation")
        column.prop(settings, "use_adaptive_tessellation")
        if settings.use_adaptive_tessellation:
            column.prop(settings, "tessellation_tolerance")
        column.prop(settings, "temperature", text="Temperature")
        bake = mesh_notes.bake_status(context.scene, obj)
        if bake is not None:
            operator, baked, _ = bake
            if baked is not None:
                column.label(text=baked, icon="CHECKMARK")
            column.operator(operator, icon="REC")
        for warning in mesh_notes.object_warnings(context.scene, obj):
            _message(layout, context, warning)


def _draw_light(layout, context, obj):
    """Lights: the same motion settings as meshes (blender/lights/moving_lights.py: point and spot lights
    with constant velocity on both paths; with the exact camera also sun and area lights and
    keyframed lights)."""
    settings = obj.relativity
    layout.prop(settings, "motion")
    kind = obj.data.type
    if settings.motion == "CONSTANT":
        layout.prop(settings, "beta")
        if kind not in ("POINT", "SPOT"):
            _message(
                layout,
                context,
                f"Moving {kind.lower()} lights: exact camera only (rendered at rest with Apparent Geometry)",
                icon="INFO",
            )
    elif settings.motion == "ANIMATION":
        _message(
            layout, context, "Animated lights: exact camera only (rendered at rest with Apparent Geometry)", icon="INFO"
        )
        if kind == "SUN":
            _message(layout, context, "A sun moves with its keyframes' velocity at the frame", icon="INFO")


classes = (
    RELATIVITY_PT_main,
    RELATIVITY_PT_observer,
    RELATIVITY_PT_shutter,
    RELATIVITY_PT_effects,
    RELATIVITY_PT_object,
)
