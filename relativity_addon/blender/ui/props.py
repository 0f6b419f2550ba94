"""Scene settings of the relativity add-on: ``bpy.types.Scene.relativity``.

Everything lives in the scene (saved with the .blend, animatable, undoable). Changing a setting
calls ``effect.setting_changed``, which brings whichever render path is applied up to date.
"""

from collections.abc import Callable
from typing import Any

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
)
from bpy.types import Context

from ...physics.shutter import ShutterModel
from ..pipeline import effect

METHOD_ITEMS = (
    ("CAMERA", "Exact Camera", "Relativistic OSL camera: exact for scenes at rest (Gray et al. 2020)"),
    (
        "GEOMETRY",
        "Apparent Geometry",
        "Deform meshes to their apparent positions (retarded positions seen from the moving camera)",
    ),
)

GEOMETRY_RENDER_ITEMS = (
    (
        "EXACT",
        "Exact Camera",
        "Final render with a moving observer: the exact camera photographs the moving objects at their "
        "retarded positions in the scene frame, so lamps, shadows and the world are right (Cycles, "
        "perspective camera)",
    ),
    (
        "PREVIEW",
        "Boosted Meshes",
        "Final render as the viewport preview: meshes carried into the observer frame; lamps, shadows "
        "and the world are not transformed (not exact under lamps)",
    ),
)

_SHUTTER_DESCRIPTIONS = {
    "PINHOLE": ("Pinhole", "Every ray passes the aperture centre at the shutter time (no depth of field)"),
    "APERTURE_PLANE": ("Aperture Plane", "Every ray passes its lens point at the shutter time"),
    "DETECTOR_PLANE": ("Detector Plane", "Every ray reaches the detector at the shutter time (ideal lens)"),
    "FOCUS_SURFACE": ("Focus Surface", "Every ray passes the focus plane at the shutter time"),
    "FIXED_POINT_SURFACE": (
        "Fixed-Point Surface",
        "Each focus-plane point opens when it is a spatial fixed point of the boost (Gray eq. 4)",
    ),
    "ARBITRARY_PLANE": ("Arbitrary Plane", "Every ray crosses a given plane at the shutter time (Gray eq. B5)"),
}
# In the physics core's order, which is the shader's ``shutter_model`` integer code.
SHUTTER_MODEL_ITEMS = tuple((model.name, *_SHUTTER_DESCRIPTIONS[model.name]) for model in ShutterModel)
SHUTTER_MODELS = tuple(item[0] for item in SHUTTER_MODEL_ITEMS)

IMAGING_ELEMENT_ITEMS = (
    (
        "IDEAL_LENS",
        "Ideal Lens",
        "Every ray from an object point to its image takes the same time (equal optical path): the "
        "detector-plane shutter is stigmatic (Gray Fig. 6a)",
    ),
    (
        "PHASE_HOLOGRAM",
        "Phase Hologram",
        "A phase hologram of the lens: same ray directions, no time delays, so the detector-plane shutter "
        "blurs (Gray Fig. 6b)",
    ),
)

WINDOW_SHUTTER_ITEMS = (
    (
        "WINDOW_PLANE",
        "In the Window",
        "The shutter sits in the window, the plane of spatial fixed points for the shutter time (Gray eq. 6), "
        "and opens at the shutter time: the photo equals the photo at rest (Gray Fig. 9); the shutter model "
        "is not used",
    ),
    (
        "SHUTTER_MODEL",
        "Shutter Model",
        "The shutter model times the rays; the window stays in the plane of spatial fixed points for the "
        "Window Time: a residual distortion unless the rays cross it at that time (Gray Fig. 10)",
    ),
)


VELOCITY_SOURCE_ITEMS = (
    ("MANUAL", "Manual", "The observer velocity is the Velocity setting"),
    (
        "CAMERA_ANIMATION",
        "Camera Animation",
        "The observer velocity follows the active camera's keyframed motion at each frame; "
        "the Velocity setting is not used",
    ),
)


def velocity_property(what: str, update: Callable[[Any, Context], None]) -> Any:
    """A velocity as a fraction of c in world axes (``|beta| < 1`` is checked where it is used)."""
    return FloatVectorProperty(
        name="Velocity (c)",
        description=f"{what} in world coordinates as a fraction of c; |beta| < 1",
        size=3,
        subtype="XYZ",
        default=(0.0, 0.0, 0.0),
        soft_min=-0.999,
        soft_max=0.999,
        update=update,
    )


def _settings_changed(self, context):
    effect.setting_changed(self.id_data)


def _speed(self):
    return sum(component * component for component in self.beta) ** 0.5


class RELATIVITY_PG_scene_settings(bpy.types.PropertyGroup):
    speed_of_light: FloatProperty(
        name="Speed of Light",
        description="Speed of light in scene units per second (299792458 for metres and real light)",
        default=299792458.0,
        min=1e-9,
        soft_max=1e9,
        update=_settings_changed,
    )
    beta: velocity_property("Observer (camera) velocity", _settings_changed)
    velocity_source: EnumProperty(
        name="Velocity From",
        items=VELOCITY_SOURCE_ITEMS,
        default="MANUAL",
        update=_settings_changed,
    )
    speed: FloatProperty(
        name="Speed (c)",
        description="Observer speed |beta| as a fraction of c",
        get=_speed,
    )
    method: EnumProperty(
        name="Method",
        items=METHOD_ITEMS,
        default="CAMERA",
        update=_settings_changed,
    )
    geometry_final_render: EnumProperty(
        name="Final Render",
        description="How Apparent Geometry renders a moving observer with F12 and in the batch script",
        items=GEOMETRY_RENDER_ITEMS,
        default="EXACT",
        update=_settings_changed,
    )
    shutter_model: EnumProperty(
        name="Shutter",
        description="Where and when the idealised shutter opens (Gray et al. 2020, section 3)",
        items=SHUTTER_MODEL_ITEMS,
        default="PINHOLE",
        update=_settings_changed,
    )
    shutter_time: FloatProperty(
        name="Shutter Time",
        description="Camera-frame time t_S (seconds) at which the shutter opens",
        default=0.0,
        update=_settings_changed,
    )
    shutter_plane_point: FloatVectorProperty(
        name="Shutter Plane Point",
        description="A point of the arbitrary shutter plane, in the camera's local coordinates "
        "(Blender convention: the camera looks down -Z)",
        size=3,
        subtype="TRANSLATION",
        default=(0.0, 0.0, -1.0),
        update=_settings_changed,
    )
    shutter_plane_normal: FloatVectorProperty(
        name="Shutter Plane Normal",
        description="Normal of the arbitrary shutter plane, in the camera's local coordinates",
        size=3,
        subtype="XYZ",
        default=(0.0, 0.0, -1.0),
        update=_settings_changed,
    )
    imaging_element: EnumProperty(
        name="Lens",
        description="The detector-plane shutter's imaging element (Gray et al. 2020, Fig. 6)",
        items=IMAGING_ELEMENT_ITEMS,
        default="IDEAL_LENS",
        update=_settings_changed,
    )
    use_lorentz_window: BoolProperty(
        name="Lorentz Window",
        description="Lorentz-transformation window in a plane of spatial fixed points (Gray eq. 6), "
        "which undoes the change of ray direction (Gray section 4)",
        default=False,
        update=_settings_changed,
    )
    lorentz_window_shutter: EnumProperty(
        name="Window Shutter",
        description="Which shutter times the rays through the Lorentz window",
        items=WINDOW_SHUTTER_ITEMS,
        default="WINDOW_PLANE",
        update=_settings_changed,
    )
    lorentz_window_time: FloatProperty(
        name="Window Time",
        description="Camera-frame time t_W (seconds) whose plane of spatial fixed points (Gray eq. 6) "
        "holds the Lorentz window, when the shutter model times the rays",
        default=0.0,
        update=_settings_changed,
    )
    use_geometry: BoolProperty(
        name="Aberration",
        description="Relativistic ray geometry (aberration, Lorentz shift of the ray origin)",
        default=True,
        update=_settings_changed,
    )
    use_time_of_flight: BoolProperty(
        name="Time of Flight Only",
        description="Teaching aid (Gray et al. 2020, Fig. 1c): light-travel time without the Lorentz "
        "transformation (Galilean). A point is seen where it was when its light left it, in the camera's "
        "frame; no length contraction, searchlight or Doppler colour. Exact camera only",
        default=False,
        update=_settings_changed,
    )
    use_doppler: BoolProperty(
        name="Doppler Colour",
        description="Doppler colour shift: blackbodies seen at D T, other colours through the spectral Doppler matrix",
        default=True,
        update=_settings_changed,
    )
    use_searchlight: BoolProperty(
        name="Searchlight",
        description="Radiance scales with D^4 (Weiskopf et al. 1999)",
        default=True,
        update=_settings_changed,
    )
    use_chang_searchlight: BoolProperty(
        name="Chang Searchlight (Wrong)",
        description="Comparison only: scale radiance by a single power of D as Chang et al. (1996) "
        "did, which Weiskopf et al. (1999) show is wrong by D^3",
        default=False,
        update=_settings_changed,
    )
    doppler_only_brightness: EnumProperty(
        name="Doppler Only",
        description="Brightness of Doppler colour without the searchlight",
        items=(
            ("REST", "Rest Brightness", "The shifted colour keeps the rest-frame brightness"),
            (
                "SPECTRUM",
                "Shifted Spectrum",
                "Weiskopf et al. (1999) Fig. 8: the shifted spectrum L(lambda D) with no further factor, "
                "so a blackbody at T shows Y(D T) / (D^5 Y(T)) of its rest brightness",
            ),
        ),
        default="REST",
        update=_settings_changed,
    )
    exposure_mode: EnumProperty(
        name="Exposure",
        description="Brightness of the frame under the searchlight",
        items=(
            ("FIXED", "Fixed", "Physically honest: the searchlight brightens the front and darkens the back as it is"),
            (
                "COMPENSATED",
                "Compensated",
                "One factor per frame from the observer's velocity and the field of view, exp(-4 <ln D>) over the "
                "image, so that a fly-through stays watchable; written into the output's metadata (Cycles, exact "
                "camera)",
            ),
        ),
        default="FIXED",
        update=_settings_changed,
    )
    fast_illuminant: EnumProperty(
        name="Lit By",
        description="Fast colour (F12): how the light that lamps sent onto surfaces is read as a spectrum, "
        "which the Doppler shift moves into view (emitters and the world seen directly are read as RGB "
        "colours in white light)",
        items=(
            (
                "AUTO",
                "Automatic",
                "Each blackbody lamp (lights, blackbody emitters, a blackbody world) by its "
                "temperature, through Cycles' light groups (two temperatures at most); other lamps in white",
            ),
            ("WHITE", "White", "Every lamp as 6504 K white light"),
            ("BLACKBODY", "Blackbody", "Every light object as a blackbody at the temperature below"),
        ),
        default="AUTO",
        update=_settings_changed,
    )
    fast_illuminant_temperature: FloatProperty(
        name="Temperature",
        description="Blackbody temperature of the light (K) for Lit By: Blackbody",
        default=5762.0,
        min=1000.0,
        max=40000.0,
        update=_settings_changed,
    )
    moving_light_shadows: EnumProperty(
        name="Moving-Light Shadows",
        description="How lights with a velocity cast shadows behind the exact camera (docs/moving-lights.md)",
        items=(
            (
                "BLENDED",
                "Blended Lamps",
                "Lamps on the light's path, each drawn out into a short line along it, each point's shadow "
                "blended from the two around its retarded position: shadow edges follow the retarded shadow "
                "without steps, softened along the motion over 1.25 lamp spacings",
                0,
            ),
            (
                "CONTINUOUS",
                "Continuous",
                "Thin strips along the light's path: each point's shadow rays go to the path around its own "
                "retarded position, so shadow edges follow the retarded shadow without steps, softened over "
                "half a lamp spacing; much noisier (measured: 2.9x the noise of Blended Lamps at the same samples, "
                "about the same render time)",
                1,
            ),
        ),
        default="BLENDED",
        update=_settings_changed,
    )
    spectral_passes: IntProperty(
        name="Spectral Passes",
        description="Colour passes of Render Spectral (three wavelengths each): "
        "more passes resolve the spectrum more finely (4: Delta E 2000 below 0.2 for blackbodies "
        "seen above 2000 K and every RGB colour)",
        default=4,
        min=1,
        soft_max=8,
        max=32,
    )


classes = (RELATIVITY_PG_scene_settings,)


def register() -> None:
    bpy.types.Scene.relativity = PointerProperty(type=RELATIVITY_PG_scene_settings)


def unregister() -> None:
    del bpy.types.Scene.relativity
