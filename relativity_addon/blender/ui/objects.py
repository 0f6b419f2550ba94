"""Per-object settings of the apparent-geometry path: ``bpy.types.Object.relativity``.

Saved with the .blend and animatable. Changing a setting syncs the effect at once
(``effect.object_changed``: the object's apparent positions and colour for the current frame), so the viewport follows.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from ..pipeline import effect
from .props import velocity_property

MOTION_ITEMS = (
    ("STATIC", "Static", "At rest in the scene (still seen moving when the observer moves)"),
    (
        "CONSTANT",
        "Constant Velocity",
        "Uniform motion with the velocity below (world axes, fraction of c); "
        "the object is where Blender draws it at the current frame",
    ),
    (
        "ANIMATION",
        "Animation",
        "The object's animated transform at each vertex's retarded time: its keyframes "
        "under its parents (deltas included), or its baked motion (Bake Motion) when constraints, "
        "drivers or NLA move it",
    ),
)


def _settings_changed(self, context):
    scene = getattr(context, "scene", None)
    if scene is not None:
        effect.object_changed(scene, self.id_data)


def _velocity_changed(self, context):
    scene = getattr(context, "scene", None)
    if scene is not None:
        effect.velocity_changed(scene, self.id_data)


class RELATIVITY_PG_object_settings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="Apparent Geometry",
        description="Deform this mesh to where the observer sees it (light-travel time, observer boost)",
        default=True,
        update=_settings_changed,
    )
    motion: EnumProperty(
        name="Motion",
        description="Where the object's world line comes from",
        items=MOTION_ITEMS,
        default="STATIC",
        update=_settings_changed,
    )
    beta: velocity_property("Constant velocity", _velocity_changed)
    temperature: FloatProperty(
        name="Blackbody Temperature",
        description="Emitter temperature in kelvin for Doppler-shifted blackbody emission (0: not an emitter)",
        default=0.0,
        min=0.0,
        soft_max=40000.0,
        subtype="TEMPERATURE",
        update=_settings_changed,
    )
    lights_scene: BoolProperty(
        name="Lights the Scene",
        description="A moving emitter (Constant Velocity): its light on other surfaces comes from its retarded "
        "positions with eq. 19's beaming, drawn as a moving point light at its origin with its mean intensity "
        "(emission times area / 4); its own emission then reaches camera rays only (docs/moving-lights.md)",
        default=False,
        update=_settings_changed,
    )
    moves_with_camera: BoolProperty(
        name="Moves With Camera",
        description="At rest in the camera's frame, as a cockpit, window frame, visor or HUD (Gray et al. 2020, "
        "appendix A): rendered as at rest in front of a camera at rest and laid over the relativistic render; "
        "a light moves with the camera's velocity (docs/cockpit.md)",
        default=False,
        update=_settings_changed,
    )
    tessellation: IntProperty(
        name="Tessellation",
        description="Subdivision levels added before deforming, so that straight edges can look curved; "
        "with Adaptive, the most levels, given only to faces whose edges need them (0: never subdivide)",
        default=4,
        min=0,
        max=6,
        update=_settings_changed,
    )
    use_adaptive_tessellation: BoolProperty(
        name="Adaptive",
        description="Subdivide only the faces with an edge whose image, drawn straight between the moved "
        "vertices, strays from the true curved image by more than the Tolerance; the other faces keep their "
        "topology (off: every face gets the Tessellation levels)",
        default=True,
        update=_settings_changed,
    )
    tessellation_tolerance: FloatProperty(
        name="Tolerance",
        description="Largest error left on an edge's image, in pixels at the render resolution (the camera's "
        "view of the boosted-mesh preview): an edge straying further is subdivided, up to Tessellation levels",
        default=0.5,
        min=0.01,
        soft_max=10.0,
        subtype="PIXEL",
        update=_settings_changed,
    )
    use_deformation: BoolProperty(
        name="Deforming",
        description="The mesh deforms (armature, shape keys, modifiers before this one): use evaluated "
        "vertex positions baked over the frame range (bake_deformation) instead of the keyframed transform",
        default=False,
        update=_settings_changed,
    )
    use_proper_time: BoolProperty(
        name="Proper Time",
        description="The object's own animation (rotation and scale keys, keyframed shape keys) plays at its "
        "proper time, integral of dt / gamma along its world line (location keys or the constant velocity), "
        "at each vertex's retarded time; off: at the scene's time",
        default=True,
        update=_settings_changed,
    )
    samples_per_frame: IntProperty(
        name="Samples per Frame",
        description="Animation samples per frame used to interpolate the motion at retarded times "
        "(keyframes, and the next motion or deformation bake)",
        default=8,
        min=1,
        max=256,
        update=_settings_changed,
    )


classes = (RELATIVITY_PG_object_settings,)


def register() -> None:
    bpy.types.Object.relativity = PointerProperty(type=RELATIVITY_PG_object_settings)


def unregister() -> None:
    del bpy.types.Object.relativity
