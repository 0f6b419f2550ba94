"""One frozen, validated snapshot of everything a relativistic render needs, read once from the
scene and its camera at the current (sub-)frame.

Every check of the observer's state lives here: the speed of light, the observer velocity (the
setting, or the camera's keyframed motion), the active camera, the shutter and the render engine.
The camera, geometry and colour modules write their part of the render from a :class:`Snapshot`
and never read ``scene.relativity`` themselves, so one setting reaches every render path by one
route (``effect.sync``).

Units and frames (docs/physics.md): scene time ``t = frame / fps`` in seconds, positions in scene
units, velocities as fractions of c in world axes; ``beta_camera`` is the same velocity in the
camera's local axes (Blender convention: the camera looks down its local -Z).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ...physics import exposure
from ...physics.shutter import ShutterModel
from ..common import compat, names, osl
from . import animation, census, cockpit, emitting_meshes, illuminants, lens, moving_objects, sources, temperatures

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    import numpy.typing as npt
    from bpy.types import Depsgraph, Object, PropertyGroup, Scene

Vector3 = tuple[float, float, float]


@dataclass(frozen=True)
class ColourFactors:
    """How the materials and the compositor scale and shift colour (docs/spectral-model.md)."""

    use_doppler: bool
    spectral_searchlight: bool  # exact visible brightness from the spectrum (Doppler and searchlight on)
    power_of_d: float  # brightness D^p besides the spectrum's (4, Chang's 1, 0, or -5 for L(lambda D) alone)
    camera_power: float  # the D^4 the exact camera's shader already applied (0 on the mesh path)
    camera_path: bool  # the exact (OSL) camera renders the observer's motion


@dataclass(frozen=True)
class MovingLight:
    """A light with constant velocity (``Object.relativity.motion == 'CONSTANT'``), read at the frame."""

    name: str
    kind: str  # Blender's light type: POINT, SPOT, SUN, AREA
    position: Vector3  # world, at the observer's time t_o: where Blender draws it
    beta: Vector3  # world axes, fraction of c
    intensity: Vector3  # W/sr per linear RGB channel in its own frame: power / (4 pi) times its colour
    axis: Vector3  # world direction of its local -Z (where a spot points)
    spot_size: float  # full cone angle, radians
    spot_blend: float
    motion: str = "CONSTANT"  # or ANIMATION: position and beta (at the frame) from its keyframes
    temperature: float = 0.0  # K, a blackbody light (sources.light_blackbody); 0: an RGB light


@dataclass(frozen=True)
class Snapshot:
    scene: str
    frame: float  # frame + sub-frame
    fps: float
    speed_of_light: float  # scene units per second
    beta: Vector3  # observer velocity, world axes, fraction of c
    velocity_source: str  # MANUAL or CAMERA_ANIMATION
    method: str  # CAMERA or GEOMETRY
    # The exact (OSL) camera renders the observer's motion: method CAMERA, or an Apparent Geometry
    # final render (the meshes then hold scene-frame retarded positions, see :func:`begin_final_render`)
    exact_camera: bool
    geometry_final_render: str  # EXACT or PREVIEW: how an Apparent Geometry final render is made
    engine: str
    camera: str  # camera object name
    camera_matrix: tuple  # its 4x4 world matrix at the frame (rows)
    shutter_model: str  # a ShutterModel name
    shutter_time: float  # camera-frame seconds
    shutter_plane_point: Vector3  # camera local axes
    shutter_plane_normal: Vector3
    use_lorentz_window: bool
    use_geometry: bool
    use_doppler: bool
    use_searchlight: bool
    use_chang_searchlight: bool
    exposure_mode: str  # FIXED or COMPENSATED
    exposure: float  # the one factor the camera multiplies the frame by (1 when FIXED)
    moving_lights: tuple[MovingLight, ...] = ()
    doppler_only_brightness: str = "REST"  # or SPECTRUM: Doppler without searchlight as Weiskopf's Fig. 8
    imaging_element: str = "IDEAL_LENS"  # or PHASE_HOLOGRAM: the detector-plane shutter's lens (Gray Fig. 6)
    lorentz_window_shutter: str = "WINDOW_PLANE"  # or SHUTTER_MODEL: what times rays through the window
    lorentz_window_time: float = 0.0  # camera-frame seconds: the window's plane of fixed points (SHUTTER_MODEL)
    # Gray's Fig. 1c: the Galilean transformation instead of the Lorentz one (use_doppler and
    # use_searchlight are then False: the mode shows the light-travel delay alone)
    use_time_of_flight: bool = False
    # the fast mode's blackbody lamps by temperature (illuminants.LitGroup): their light groups'
    # passes are read through their own tables (light_groups.py)
    lit_groups: tuple = ()
    # the moving blackbody lights whose stand-in lamps apply the observer's shift themselves, in the
    # fast mode's observed light group (illuminants.reads_observed)
    observed_lights: tuple[str, ...] = ()
    # the camera's image (``lens.projection``: the perspective view window or a panorama's
    # parameters) and whether it renders a stereo pair: stages take these, not the camera anew
    projection: tuple = ()
    stereo: bool = False
    # objects moving with the camera (``scene/cockpit.py``), rendered at rest by ``camera/cockpit.py``
    cockpit: tuple[str, ...] = ()
    # moving lights' stand-ins: strips along the path (CONTINUOUS) or point lamps (BLENDED)
    moving_light_shadows: str = "BLENDED"
    # the largest speed |beta| among the objects with their own velocity (``moving_objects.fastest_speed``:
    # the clamping stage's bound), read with the objects' other checks
    fastest_object: float = 0.0

    @property
    def time(self) -> float:
        """The observer's scene time ``t_o`` in seconds."""
        return self.frame / self.fps

    @property
    def speed(self) -> float:
        return math.sqrt(sum(b * b for b in self.beta))

    @property
    def gamma(self) -> float:
        return 1.0 / math.sqrt(1.0 - self.speed**2)

    @property
    def camera_position(self) -> np.ndarray:
        return np.array([row[3] for row in self.camera_matrix[:3]], dtype=np.float64)

    @property
    def world_to_camera(self) -> np.ndarray:
        """Rotation ``(3, 3)`` taking world vectors to camera axes (scale and shear removed): one SVD
        per camera matrix, not per call (the meshes' updates ask for it a few times an object)."""
        return _world_to_camera_of(self.camera_matrix).copy()

    @property
    def beta_camera(self) -> np.ndarray:
        return self.world_to_camera @ np.array(self.beta)

    @property
    def mesh_observer(self) -> tuple[float, np.ndarray, np.ndarray]:
        """``(t, x, beta)``: the event and velocity the apparent meshes are computed for.

        Behind the exact camera the meshes stay in the scene frame (``beta`` 0) and are seen from
        the aperture centre at the shutter time ``t_S`` (camera frame), Gray eq. (1):
        ``t = t_o + gamma t_S``, ``x = x_cam + gamma beta c t_S``. On the boosted-mesh preview they
        are seen from ``(t_o, x_cam)`` and carried into the observer frame."""
        if not self.exact_camera:
            return self.time, self.camera_position, np.array(self.beta, dtype=np.float64)
        dt = self.gamma * self.shutter_time
        beta = np.array(self.beta, dtype=np.float64)
        return self.time + dt, self.camera_position + beta * (self.speed_of_light * dt), np.zeros(3)

    @property
    def shutter_code(self) -> int:
        """The OSL shader's integer code of the shutter model (the physics core's enum value)."""
        return int(ShutterModel[self.shutter_model])

    @property
    def colour(self) -> ColourFactors:
        spectral = self.use_searchlight and self.use_doppler and not self.use_chang_searchlight
        if not self.use_searchlight or spectral:
            power = 0.0
        else:
            power = 1.0 if self.use_chang_searchlight else 4.0
        if self.use_doppler and not self.use_searchlight and self.doppler_only_brightness == "SPECTRUM":
            # L(lambda D) alone (Weiskopf et al. 1999, Fig. 8): eq. 14's visible factor without its D^5
            spectral, power = True, -5.0
        camera_path = self.exact_camera
        return ColourFactors(
            use_doppler=self.use_doppler,
            spectral_searchlight=spectral,
            power_of_d=power,
            camera_power=4.0 if (camera_path and self.use_searchlight) else 0.0,
            camera_path=camera_path,
        )


def _finite(values):
    return all(math.isfinite(value) for value in values)


def current_frame(scene: Scene) -> float:
    return scene.frame_current + scene.frame_subframe


def check_velocity(beta: Iterable[float], what: str) -> tuple[float, ...]:
    """``beta`` as a float tuple; RelativityError unless finite and below the speed of light (the
    line starts with ``what``, capitalised: it is shown as it is)."""
    what = what[:1].upper() + what[1:]
    beta = tuple(float(b) for b in beta)
    if not _finite(beta):
        raise RelativityError(f"{what} is not a finite vector")
    speed = math.sqrt(sum(b * b for b in beta))
    if speed >= 1.0:
        raise RelativityError(f"{what}: speed |beta| = {speed:.6g} must be below 1 (the speed of light)")
    return beta


def check_speed_of_light(c: float) -> float:
    c = float(c)
    if not (math.isfinite(c) and c > 0.0):
        raise RelativityError("Speed of light must be a positive finite number")
    return c


def active_camera(scene: Scene) -> Object:
    camera = scene.camera
    if camera is None or camera.type != "CAMERA":
        raise RelativityError(f"Scene {scene.name!r} has no active camera")
    return camera


def camera_matrix(
    scene: Scene, camera: Object, frame: float, depsgraph: Depsgraph | None = None
) -> npt.NDArray[np.float64]:
    """The camera's world matrix at ``frame`` as float64 ``(4, 4)``.

    Blender's animation render does not re-evaluate the original camera object, so its
    ``matrix_world`` is that of the frame the file was saved at; a farm worker would render a
    turning camera wrongly. Keyframed transforms (with object parents) are evaluated from the
    F-curves at the frame itself; only a camera moved by constraints, drivers or NLA uses
    Blender's evaluation (the depsgraph's, when given).
    """
    if animation.keyframe_motion_problem(camera, scene) is None:
        return animation.world_matrices(camera, [frame])[0]
    evaluated = camera.evaluated_get(depsgraph) if depsgraph is not None else camera
    return np.array(evaluated.matrix_world, dtype=np.float64)


# Half-width of the central difference, in frames. Small enough to be the instantaneous velocity
# of smooth keyframe curves, large enough for float32 key values.
STEP_FRAMES = 1.0 / 64.0
# Sub-frame samples per frame checked by ``check_animation_speed``.
CHECK_SAMPLES_PER_FRAME = 4


def camera_beta_at(scene: Scene, frame: float, camera: Object | None = None) -> tuple[float, ...]:
    """The camera's velocity (world axes, fraction of c) at ``frame`` (float allowed), from its
    keyframes: the time derivative of its world position in scene time ``t = frame / fps``, over c
    (docs/physics.md, units), by a central difference of half-width STEP_FRAMES. A camera that its
    keyframes do not move alone (constraints, drivers, NLA) is refused."""
    camera = active_camera(scene) if camera is None else camera
    animation.check_supported(camera, scene)
    c = check_speed_of_light(scene.relativity.speed_of_light)
    before, after = animation.world_matrices(camera, [frame - STEP_FRAMES, frame + STEP_FRAMES])[:, :3, 3]
    dt = 2.0 * STEP_FRAMES / animation.frames_per_second(scene)
    return tuple(float(x) for x in (after - before) / dt / c)


def observer_speeds(scene: Scene, frames: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """The observer's speed ``|beta|`` at each of ``frames`` (array, sub-frames allowed): the
    setting, or the camera's keyframes (central differences, as :func:`camera_beta_at`, for all
    frames at once). RelativityError at or above the speed of light."""
    frames = np.asarray(frames, dtype=np.float64)
    settings = scene.relativity
    if settings.velocity_source != "CAMERA_ANIMATION":
        speed = math.sqrt(sum(b * b for b in check_velocity(settings.beta, "observer velocity beta")))
        return np.full(len(frames), speed)
    camera = active_camera(scene)
    animation.check_supported(camera, scene)
    c = check_speed_of_light(settings.speed_of_light)
    before = animation.world_matrices(camera, frames - STEP_FRAMES)[:, :3, 3]
    after = animation.world_matrices(camera, frames + STEP_FRAMES)[:, :3, 3]
    speeds = np.linalg.norm(after - before, axis=1) * animation.frames_per_second(scene) / (2.0 * STEP_FRAMES * c)
    if np.any(speeds >= 1.0):
        raise RelativityError(
            f"Camera {camera.name!r} reaches the speed of light at frame {float(frames[np.argmax(speeds >= 1.0)]):g}"
        )
    return speeds


def _checked_camera_speed(camera, beta, frame):
    speed = math.sqrt(sum(b * b for b in beta))
    if not math.isfinite(speed) or speed >= 1.0:
        whole = math.floor(frame)
        where = f"frame {whole}" if frame == whole else f"frame {whole} (sub-frame {frame:g})"
        raise RelativityError(
            f"Camera {camera.name!r} moves at {speed:.4g} c at {where}: "
            "its animation must stay below the speed of light (slow it down or raise c)"
        )
    return speed


def check_animation_speed(scene: Scene, frame_start: int | None = None, frame_end: int | None = None) -> float:
    """Raise RelativityError naming the first frame where the camera moves at or above c.

    Samples every frame of [frame_start, frame_end] (default: the scene's frame range) and
    CHECK_SAMPLES_PER_FRAME - 1 sub-frames between frames. Returns the highest speed found.
    """
    camera = active_camera(scene)
    frame_start = scene.frame_start if frame_start is None else frame_start
    frame_end = scene.frame_end if frame_end is None else frame_end
    steps = max(int(round((frame_end - frame_start) * CHECK_SAMPLES_PER_FRAME)), 0)
    frames = (frame_start + step / CHECK_SAMPLES_PER_FRAME for step in range(steps + 1))
    return max((_checked_camera_speed(camera, camera_beta_at(scene, f, camera), f) for f in frames), default=0.0)


def observer_velocity(scene: Scene, camera: Object | None, frame: float) -> tuple[float, ...]:
    """The observer velocity at ``frame``: the setting, or the camera's keyframed motion."""
    if scene.relativity.velocity_source == "CAMERA_ANIMATION":
        beta = camera_beta_at(scene, frame, camera)
        _checked_camera_speed(camera, beta, frame)
        return beta
    return check_velocity(scene.relativity.beta, "observer velocity beta")


def light_render_hidden(obj: Object) -> bool:
    """Whether the user hid the light from renders (the moving-light stage hides it too, keeping
    the user's value under ``names.LIGHT_SAVED_KEY``)."""
    saved = obj.get(names.LIGHT_SAVED_KEY)
    return bool(saved["hide_render"]) if saved is not None else obj.hide_render


def _keyframe_beta(scene, obj, frame, step=0.01):
    """An animated object's velocity over c at ``frame`` from its keyframes (central difference)."""
    problem = animation.keyframe_motion_problem(obj, scene)
    if problem is not None:
        raise RelativityError(f"Light {obj.name!r} moves by its keyframes, but {problem}: set its motion to Constant")
    positions = animation.world_matrices(obj, [frame - step, frame + step])[:, :3, 3]
    c = check_speed_of_light(scene.relativity.speed_of_light)
    per_frame = (positions[1] - positions[0]) / (2.0 * step)
    return tuple(float(v) for v in per_frame * animation.frames_per_second(scene) / c)


def moving_lights(
    scene: Scene, frame: float, depsgraph: Depsgraph | None = None, observer: Sequence[float] = (0.0, 0.0, 0.0)
) -> tuple[MovingLight, ...]:
    """Every light of ``scene`` with constant velocity or keyframed motion that renders, at ``frame``; RelativityError
    for a light at or above the speed of light. A light moving with the camera moves uniformly with the observer's
    velocity ``observer`` at the frame."""
    found = []
    for entry in census.entries(scene):
        if entry.type != "LIGHT" and not entry.emitter_light:
            continue  # (only lights and emitting meshes are moving lights)
        obj, motion = entry.obj, entry.motion
        if entry.emitter_light and not obj.hide_render:
            found += _emitter_light(scene, obj, frame, depsgraph)
            continue
        if obj.type == "LIGHT" and cockpit.moves_with_camera(obj) and not light_render_hidden(obj):
            # with the camera: its keyframed path when the velocity comes from the camera's keyframes
            # (an accelerating camera's lamp), else uniform at the camera's velocity
            animated = scene.relativity.velocity_source == "CAMERA_ANIMATION"
            motion = "ANIMATION" if animated else "CONSTANT"
            if not any(observer):
                continue  # at rest with the camera at rest: Blender's own light
        elif obj.type != "LIGHT" or motion not in ("CONSTANT", "ANIMATION"):
            continue
        if any(curve.data_path == "hide_render" for curve in compat.action_fcurves(obj.animation_data)):
            # its F-curve would write the lamp's visibility back over the stage's hiding at each frame
            raise RelativityError(
                f"Light {obj.name!r} moves and its Hide in Render is keyframed: remove those keyframes "
                "(animate its Power to switch it off)"
            )
        if light_render_hidden(obj):
            continue
        if cockpit.moves_with_camera(obj) and motion == "CONSTANT":
            beta = tuple(observer)
        else:
            beta = obj.relativity.beta if motion == "CONSTANT" else _keyframe_beta(scene, obj, frame)
        beta = check_velocity(beta, f"light {obj.name!r} velocity beta")
        matrix = camera_matrix(scene, obj, frame, depsgraph)
        axis = -matrix[:3, 2] / max(np.linalg.norm(matrix[:3, 2]), 1e-30)
        light = obj.data
        power = float(light.energy) / (4.0 * math.pi)
        spot = light.type == "SPOT"
        # its Color times its tree's constant (the stand-ins do not render its tree) and its temperature's
        colour = np.array(light.color, dtype=np.float64) * np.array(sources.light_tree_factor(light))
        if light.use_temperature:
            colour = colour * np.array(light.temperature_color, dtype=np.float64)
        found.append(
            MovingLight(
                name=obj.name,
                kind=light.type,
                position=tuple(float(v) for v in matrix[:3, 3]),
                beta=beta,
                intensity=tuple(power * float(v) for v in colour),
                axis=tuple(float(v) for v in axis),
                spot_size=float(light.spot_size) if spot else math.pi,
                spot_blend=float(light.spot_blend) if spot else 0.0,
                motion=motion,
                temperature=float(sources.light_blackbody(light) or 0.0),
            )
        )
    return tuple(found)


def _emitter_light(scene, obj, frame, depsgraph):
    """A moving emissive mesh as a moving point light at its origin (``emitter_lights``), or none."""
    beta = check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity beta")
    matrix = camera_matrix(scene, obj, frame, depsgraph)
    intensity = emitting_meshes.intensity(obj, matrix)
    if intensity is None:
        return []
    return [
        MovingLight(
            name=obj.name,
            kind="POINT",
            position=tuple(float(v) for v in matrix[:3, 3]),
            beta=beta,
            intensity=intensity,
            axis=(0.0, 0.0, -1.0),
            spot_size=math.pi,
            spot_blend=0.0,
            temperature=float(obj.relativity.temperature),
        )
    ]


# Object types the Apparent Geometry path cannot move (their own velocity is refused, naming them)
# and those that draw nothing in a render (a velocity there would move nothing, children included).
# Scenes whose Apparent Geometry final render is running with the exact camera.
_final_renders = set()


def begin_final_render(scene: Scene) -> None:
    """From now on ``scene`` renders its Apparent Geometry through the exact camera: the observer's
    motion by the OSL camera (aberration, searchlight, colour, exact for lamps, shadows and the
    world, which stay in the scene frame), the moving objects at their retarded positions in the
    scene frame. Set by ``effect.begin_final_render`` for the time of a render."""
    _final_renders.add(scene.name)


def end_final_render(scene: Scene) -> None:
    _final_renders.discard(scene.name)


def in_final_render(scene: Scene) -> bool:
    return scene.name in _final_renders


@functools.lru_cache(maxsize=8)
def _world_to_camera_of(camera_matrix: tuple) -> npt.NDArray[np.float64]:
    return world_to_camera(np.array(camera_matrix, dtype=np.float64))


def world_to_camera(camera_matrix: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Rotation ``(3, 3)`` taking world vectors to the axes of a camera with world matrix
    ``camera_matrix`` (4x4): the nearest rotation (polar decomposition), scale and shear removed."""
    u, _, vt = np.linalg.svd(np.asarray(camera_matrix, dtype=np.float64)[:3, :3])
    return (u @ vt).T


def frame_exposure(
    scene: Scene, camera: Object, settings: PropertyGroup, beta: Sequence[float], camera_matrix: npt.ArrayLike
) -> float:
    """The exposure factor of the frame (``physics.exposure.compensation``; 1 when FIXED)."""
    if settings.exposure_mode != "COMPENSATED" or not any(beta):
        return 1.0
    beta_camera = world_to_camera(camera_matrix) @ np.array(beta)
    aberration = settings.use_geometry and not settings.use_lorentz_window
    power = 1.0 if settings.use_chang_searchlight else 4.0
    return exposure.compensation(beta_camera, lens.view_window(scene, camera), aberration, power)


def check_time_of_flight(settings: PropertyGroup, lights: Sequence[MovingLight]) -> None:
    """RelativityError (one line) for what time-of-flight mode (Gray Fig. 1c) cannot render: it is
    the exact camera's, for a scene at rest, and has no Lorentz transformation to window or to
    take spatial fixed points from."""
    if settings.method != "CAMERA":
        raise RelativityError("Time of Flight Only is for the exact camera (Method: Exact Camera)")
    if settings.use_lorentz_window:
        raise RelativityError("Time of Flight Only has no Lorentz transformation for the Lorentz window to undo")
    if settings.shutter_model == "FIXED_POINT_SURFACE":
        raise RelativityError("Time of Flight Only has no spatial fixed points: choose another shutter")
    if lights:
        raise RelativityError(f"Time of Flight Only renders a scene at rest: light {lights[0].name!r} moves")


def read(scene: Scene, depsgraph: Depsgraph | None = None, objects_for: str | None = None) -> Snapshot:
    """The snapshot of ``scene`` at its current frame; RelativityError (one line) if the scene
    cannot be rendered with correct physics. ``objects_for`` checks the objects' own velocities for
    that method instead of the scene's (the Apparent Geometry bakes read ``"GEOMETRY"``: they are
    that path's tools, used before the method is chosen)."""
    with census.taken():  # (the objects' settings read once for every check below)
        return _read(scene, depsgraph, objects_for)


def _read(scene, depsgraph, objects_for):
    settings = scene.relativity
    c = check_speed_of_light(settings.speed_of_light)
    camera = active_camera(scene)
    frame = current_frame(scene)
    beta = observer_velocity(scene, camera, frame)
    if not math.isfinite(settings.shutter_time):
        raise RelativityError("Shutter time must be finite")
    normal = tuple(settings.shutter_plane_normal)
    if settings.shutter_model == "ARBITRARY_PLANE" and (not _finite(normal) or sum(n * n for n in normal) == 0.0):
        raise RelativityError("Arbitrary shutter plane needs a non-zero normal")
    if not _finite(settings.shutter_plane_point):
        raise RelativityError("The shutter plane point must be finite")
    if not math.isfinite(settings.lorentz_window_time):
        raise RelativityError("The Lorentz window time must be finite")
    temperatures.check_temperatures(scene)
    matrix = camera_matrix(scene, camera, frame, depsgraph)
    lights = moving_lights(scene, frame, depsgraph, beta)
    time_of_flight = bool(settings.use_time_of_flight)
    if time_of_flight:
        check_time_of_flight(settings, lights)
    if settings.method == "CAMERA" and osl.unavailable_reason() is not None:  # first: nothing else helps
        raise RelativityError(f"{osl.unavailable_reason()}: Method Exact Camera needs it (use Apparent Geometry)")
    moving_objects.check_object_velocities(scene, objects_for or settings.method)
    if settings.method == "CAMERA" and scene.render.engine != "CYCLES":
        engine = compat.engine_label(scene.render.engine)
        raise RelativityError(f"Render Engine is {engine}: the exact camera renders with Cycles only")
    exact_camera = settings.method == "CAMERA" or (settings.method == "GEOMETRY" and in_final_render(scene))
    fast_colour = exact_camera and settings.use_doppler and not time_of_flight  # the compositor's colour
    if exact_camera and settings.shutter_model == "DETECTOR_PLANE":
        lens.check_detector_image(scene, camera, matrix)
    return Snapshot(
        scene=scene.name,
        frame=frame,
        fps=animation.frames_per_second(scene),
        speed_of_light=c,
        beta=beta,
        velocity_source=settings.velocity_source,
        method=settings.method,
        exact_camera=exact_camera,
        geometry_final_render=settings.geometry_final_render,
        engine=scene.render.engine,
        camera=camera.name,
        camera_matrix=tuple(map(tuple, matrix.tolist())),
        shutter_model=settings.shutter_model,
        shutter_time=float(settings.shutter_time),
        shutter_plane_point=tuple(float(v) for v in settings.shutter_plane_point),
        shutter_plane_normal=tuple(float(v) for v in normal),
        use_lorentz_window=bool(settings.use_lorentz_window),
        use_geometry=bool(settings.use_geometry),
        use_doppler=bool(settings.use_doppler) and not time_of_flight,
        use_searchlight=bool(settings.use_searchlight) and not time_of_flight,
        use_chang_searchlight=bool(settings.use_chang_searchlight),
        exposure_mode=settings.exposure_mode,
        exposure=frame_exposure(scene, camera, settings, beta, matrix)
        if settings.use_searchlight and not time_of_flight
        else 1.0,
        moving_lights=lights,
        doppler_only_brightness=settings.doppler_only_brightness,
        imaging_element=settings.imaging_element,
        lorentz_window_shutter=settings.lorentz_window_shutter,
        lorentz_window_time=float(settings.lorentz_window_time),
        use_time_of_flight=time_of_flight,
        lit_groups=temperatures.checked_lit_groups(illuminants.lit_groups(scene, {light.name for light in lights}))
        if fast_colour
        else (),
        observed_lights=tuple(light.name for light in lights if light.temperature > 0.0 and light.kind != "SUN")
        if fast_colour and illuminants.reads_observed(scene)
        else (),
        projection=lens.projection(scene, camera),
        stereo=lens.stereo_eyes(scene),
        cockpit=cockpit.object_names(scene),
        moving_light_shadows=settings.moving_light_shadows,
        fastest_object=moving_objects.fastest_speed(scene),
    )
