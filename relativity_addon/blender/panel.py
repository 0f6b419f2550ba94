"""The N-panel: View3D > Sidebar > Relativity.

``scene_warnings(scene)`` and ``object_warnings(scene, obj)`` compute the live warnings the panel
shows; they are plain functions so that tests (and the batch script) can use them without a UI.
"""

import math

import bpy
from bpy.types import Panel

from . import animation, ops
from .camera import RelativityError

# An edge longer than this fraction of its distance to the camera is too coarse for the
# apparent-geometry path to curve (aberration bends straight lines; only vertices move).
COARSE_EDGE_FRACTION = 0.25


def observer_speed(scene):
    """(|beta|, source note): from the setting, or from the camera animation at this frame."""
    settings = scene.relativity
    if settings.velocity_source == "CAMERA_ANIMATION":
        beta = animation.camera_beta_at(scene, animation.current_frame(scene))
        return math.sqrt(sum(b * b for b in beta))
    return settings.speed


def scene_warnings(scene):
    """One-line problems that would stop or falsify a relativistic render of ``scene``."""
    warnings = []
    settings = scene.relativity
    try:
        speed = observer_speed(scene)
        if not math.isfinite(speed) or speed >= 1.0:
            warnings.append(f"Speed {speed:.4g} c: must be below the speed of light")
    except RelativityError as error:
        warnings.append(str(error))
    if scene.render.engine != "CYCLES":
        warnings.append("Render engine is not Cycles: the relativistic camera needs Cycles (OSL camera)")
    elif getattr(scene.cycles, "device", "CPU") == "GPU":
        warnings.append("Cycles renders OSL cameras on the CPU (or OptiX) only: set Device to CPU")
    camera_object = scene.camera
    if camera_object is None or camera_object.type != "CAMERA":
        warnings.append("The scene has no active camera")
    elif camera_object.data.type != "PERSP" and not ops.camera.is_applied(camera_object.data):
        warnings.append(f"Camera {camera_object.name!r} is not a perspective camera")
    if settings.method == "GEOMETRY" and ops.geometry_module() is None:
        warnings.append("Apparent Geometry could not be loaded: use Exact Camera")
    return warnings


def longest_edge_fraction(scene, obj):
    """Longest mesh edge divided by its midpoint's distance to the camera (world units)."""
    import numpy as np

    mesh = obj.data
    camera_object = scene.camera
    if camera_object is None or len(mesh.edges) == 0 or len(mesh.edges) > 200_000:
        return 0.0
    coordinates = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", coordinates)
    coordinates = coordinates.reshape(-1, 3)
    matrix = np.array(obj.matrix_world)
    world = coordinates @ matrix[:3, :3].T + matrix[:3, 3]
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int64)
    mesh.edges.foreach_get("vertices", edges)
    a, b = world[edges[0::2]], world[edges[1::2]]
    lengths = np.linalg.norm(b - a, axis=1)
    distances = np.linalg.norm((a + b) / 2.0 - np.array(camera_object.matrix_world.translation), axis=1)
    return float(np.max(lengths / np.maximum(distances, 1e-9)))


def object_warnings(scene, obj):
    warnings = []
    if obj is None or obj.type != "MESH" or scene.relativity.method != "GEOMETRY":
        return warnings
    # the modifier halves every edge once per tessellation level before moving the vertices
    levels = obj.relativity.tessellation if hasattr(obj, "relativity") else 0
    fraction = longest_edge_fraction(scene, obj) / 2**levels
    if fraction > COARSE_EDGE_FRACTION:
        warnings.append(
            f"Edges up to {fraction:.2f}x their distance to the camera: too coarse to curve, raise Tessellation"
        )
    geometry = ops.geometry_module()
    error = geometry.object_error(obj) if geometry is not None else None
    bake = bake_status(scene, obj)
    if error is not None:  # the last update failed: the viewport shows an older state
        warnings.append(error)
    elif bake is not None and bake[1] is None and bake[2] is not None:
        warnings.append(bake[2])
    return warnings


def bake_status(scene, obj):
    """For an ANIMATION mesh: (bake operator, what is baked or None, why a bake is needed or None);
    None for other objects. A needed bake that is missing is an object warning."""
    geometry = ops.geometry_module()
    settings = getattr(obj, "relativity", None)
    if geometry is None or settings is None or obj.type != "MESH" or settings.motion != "ANIMATION":
        return None
    if settings.use_deformation:
        baked = "Deformation baked" if geometry.bake_mesh(obj) is not None else None
        return "relativity.bake_deformation", baked, "Deforming mesh: press Bake Deformation"
    bake = geometry.motion_bake(obj)
    if bake is not None:
        first, per_frame, matrices = bake
        last = first + (len(matrices) - 1) / per_frame
        return "relativity.bake_motion", f"Motion baked: frames {first:g} to {last:g}", None
    problem = animation.keyframe_motion_problem(obj, scene)
    needed = f"{problem}: keyframes are not its motion, press Bake Motion" if problem else None
    return "relativity.bake_motion", None, needed


class RELATIVITY_PT_observer(Panel):
    bl_idname = "RELATIVITY_PT_observer"
    bl_label = "Relativity"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Relativity"

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "relativity")

    def draw(self, context):
        scene = context.scene
        settings = scene.relativity
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False

        row = layout.row(align=True)
        row.menu("RELATIVITY_MT_paper_setups_presets", text="Paper Setups")

        layout.prop(settings, "method")
        layout.prop(settings, "velocity_source")
        row = layout.row(align=True)
        row.menu("RELATIVITY_MT_speed_presets", text="Speed")
        row.operator("relativity.speed_preset_add", text="", icon="ADD")
        row.operator("relativity.speed_preset_add", text="", icon="REMOVE").remove_active = True
        column = layout.column()
        column.enabled = settings.velocity_source == "MANUAL"
        column.prop(settings, "beta")
        try:
            speed = observer_speed(scene)
        except RelativityError:
            speed = math.nan
        box = layout.box()
        box.label(text=f"Speed: {speed:.6g} c")
        box.label(text=f"Gamma: {ops.gamma_of_speed(speed):.6g}" if speed < 1.0 else "Gamma: undefined (speed >= c)")

        row = layout.row(align=True)
        row.menu("RELATIVITY_MT_speed_of_light_presets", text="Speed of Light")
        row.operator("relativity.speed_of_light_preset_add", text="", icon="ADD")
        row.operator("relativity.speed_of_light_preset_add", text="", icon="REMOVE").remove_active = True
        layout.prop(settings, "speed_of_light")

        row = layout.row(align=True)
        row.menu("RELATIVITY_MT_shutter_presets", text="Shutter")
        row.operator("relativity.shutter_preset_add", text="", icon="ADD")
        row.operator("relativity.shutter_preset_add", text="", icon="REMOVE").remove_active = True
        layout.prop(settings, "shutter_model")
        layout.prop(settings, "shutter_time")
        if settings.shutter_model == "ARBITRARY_PLANE" or settings.use_lorentz_window:
            layout.prop(settings, "shutter_plane_point")
            layout.prop(settings, "shutter_plane_normal")
        layout.prop(settings, "use_lorentz_window")

        column = layout.column(heading="Effects")
        column.prop(settings, "use_geometry")
        column.prop(settings, "use_doppler")
        column.prop(settings, "use_searchlight")
        row = column.row()
        row.active = settings.use_searchlight
        row.prop(settings, "use_chang_searchlight")

        for warning in scene_warnings(scene):
            layout.label(text=warning, icon="ERROR")

        column = layout.column(align=True)
        column.operator("relativity.setup_scene", icon="PLAY")
        column.operator("relativity.remove_all", icon="X")
        if settings.velocity_source == "CAMERA_ANIMATION":
            column.operator("relativity.check_animation", icon="TIME")


class RELATIVITY_PT_object(Panel):
    bl_idname = "RELATIVITY_PT_object"
    bl_label = "Active Object"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Relativity"
    bl_parent_id = "RELATIVITY_PT_observer"

    @classmethod
    def poll(cls, context):
        return context.object is not None and hasattr(context.scene, "relativity")

    def draw(self, context):
        obj = context.object
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.label(text=obj.name, icon="OBJECT_DATA")
        settings = getattr(obj, "relativity", None) if hasattr(bpy.types.Object, "relativity") else None
        if settings is None:
            layout.label(text="No per-object settings in this version")
        else:
            for prop in settings.bl_rna.properties:
                if prop.identifier not in {"rna_type", "name"}:
                    layout.prop(settings, prop.identifier)
        bake = bake_status(context.scene, obj)
        if bake is not None:
            operator, baked, _ = bake
            if baked is not None:
                layout.label(text=baked, icon="CHECKMARK")
            layout.operator(operator, icon="REC")
        for warning in object_warnings(context.scene, obj):
            layout.label(text=warning, icon="ERROR")


classes = (RELATIVITY_PT_observer, RELATIVITY_PT_object)
