"""Objects with their own velocity: which the render path of each Method can move, and the one-line
refusal naming the others (read by ``snapshot.read``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ..common import once
from . import animation, census, emitting_meshes

if TYPE_CHECKING:
    from contextlib import AbstractContextManager

    from bpy.types import Object, Scene


TYPE_LABELS = {
    "MESH": "Mesh",
    "CURVE": "Curve",
    "SURFACE": "Surface",
    "FONT": "Text",
    "META": "Metaball",
    "POINTCLOUD": "Point cloud",
    "VOLUME": "Volume",
    "GPENCIL": "Grease pencil",
    "GREASEPENCIL": "Grease pencil",
    "CURVES": "Hair curves",
    "EMPTY": "Empty",
    "CAMERA": "Camera",
    "SPEAKER": "Speaker",
    "LIGHT_PROBE": "Light probe",
    "LIGHTPROBE": "Light probe",
    "ARMATURE": "Armature",
    "LATTICE": "Lattice",
}
DRAWS_NOTHING = ("EMPTY", "CAMERA", "SPEAKER", "LIGHT_PROBE", "LIGHTPROBE", "ARMATURE", "LATTICE")


_checked = once.Once()  # object pointer -> has_own_velocity, inside checked_once()


def checked_once() -> AbstractContextManager[None]:
    """Inside: :func:`has_own_velocity` reads each object's settings once (a sync changes none;
    the instancing checks ask about the applied objects and what instancers draw; the snapshot's
    checks read ``census.entries``)."""
    return _checked.kept()


def has_own_velocity(obj: Object) -> bool:
    """Whether the object's settings give it its own motion: ``relativity.enabled`` with Constant
    Velocity of nonzero ``beta``, or with Animation (its keyframes or motion bake are its world
    line). What the Apparent Geometry path moves (for meshes) and the exact camera cannot."""
    found = _checked.values()
    if found is None:
        return _own_velocity(obj)
    key = obj.as_pointer()
    known = found.get(key)
    if known is None:
        known = found[key] = _own_velocity(obj)
    return known


def _own_velocity(obj):
    return census.own_velocity(obj.relativity)


def object_label(obj: Object) -> str:
    """``Text 'Name'``: the object's kind (a collection instance named so) and name."""
    if obj.type == "EMPTY" and obj.instance_type == "COLLECTION" and obj.instance_collection is not None:
        return f"Collection instance {obj.name!r}"
    return f"{TYPE_LABELS.get(obj.type, obj.type.title())} {obj.name!r}"


def draws_nothing(obj: Object) -> bool:
    """Whether the object draws nothing in a render itself (an empty instancing a collection does)."""
    return obj.type in DRAWS_NOTHING and not (
        obj.type == "EMPTY" and obj.instance_type == "COLLECTION" and obj.instance_collection is not None
    )


def _named(labels, limit=4):
    shown = ", ".join(labels[:limit])
    return shown + (f" and {len(labels) - limit} more" if len(labels) > limit else "")


def mesh_instancer(obj: Object) -> str | None:
    """How a mesh draws other objects that the apparent-geometry modifier does not move (one
    phrase), or None: rendered particle systems (hair, object or collection instances) and
    vertex or face instancing. Geometry-nodes instances are found on the evaluated scene
    (``apparent_meshes.apply``)."""
    for modifier in obj.modifiers:
        if (
            modifier.type == "PARTICLE_SYSTEM"
            and modifier.show_render
            and modifier.particle_system.settings.render_type != "NONE"
        ):
            return f"particle system {modifier.particle_system.name!r}"
    if obj.instance_type in ("VERTS", "FACES") and len(obj.children):
        return f"{obj.instance_type.lower()[:-1]} instancing"
    return None


def check_object_velocities(scene: Scene, method: str) -> None:
    """RelativityError (one line) naming the objects whose own velocity ``method`` cannot render:
    with the exact camera every object but lights (the moving-light stage takes those); with
    Apparent Geometry every moving object that is not a mesh, and meshes drawing particles or
    instances, which the modifier leaves where they are."""
    moving = [entry.obj for entry in census.entries(scene) if entry.own_velocity and entry.type != "LIGHT"]
    if not moving:
        return
    if method == "CAMERA":
        # emissive meshes with Lights the Scene are drawn by the moving-light stage, like lights
        labels = [f"{obj.name!r}" for obj in moving if not emitting_meshes.is_emitter_light(obj)]
        if not labels:
            return
        subject = (
            f"Object {labels[0]} has its own velocity"
            if len(labels) == 1
            else f"Objects {_named(labels)} have their own velocities"
        )
        raise RelativityError(
            f"{subject}: the Exact Camera method photographs a static scene; choose Apparent "
            "Geometry (its final render uses the exact camera)"
        )
    drawn, problems = [], []  # (one read of a mover's type: a mesh draws itself)
    for obj in moving:
        if obj.type != "MESH":
            if not draws_nothing(obj):
                drawn.append(object_label(obj))
            else:
                problems.append(
                    f"{object_label(obj)} has its own velocity but draws nothing (children and deformed "
                    "meshes do not inherit it): set its Motion to Static, give moving meshes their own"
                )
        elif (instancer := mesh_instancer(obj)) is not None:
            problems.append(
                f"Mesh {obj.name!r} draws objects by its {instancer}, which cannot move on the "
                "Apparent Geometry path yet: make them real (Make Instances Real / Convert to Mesh)"
            )
    if drawn:
        problems.insert(
            0,
            f"{_named(drawn)} cannot move on the Apparent Geometry path yet (only meshes do): "
            f"convert {'it to a mesh' if len(drawn) == 1 else 'them to meshes'}",
        )
    if problems:
        raise RelativityError("; ".join(problems))


# Quarter frames: the keyframed speeds that bound the sample clamps (``fastest_speed``).
_SPEED_STEP_FRAMES = 0.25
_SPEED_SAMPLES = 4096
_keyframed_speeds: dict[str, tuple[tuple, float]] = {}


def fastest_speed(scene: Scene) -> float:
    """The largest speed ``|beta|`` among the scene's objects with their own velocity (meshes and
    lights): Constant Velocity's setting; with Animation the fastest its keyframes move it over
    the scene's frame range (every quarter frame; kept while its keyframes are the same). Below 1:
    what reaches the speed of light is refused elsewhere."""
    keyed = None  # (frame range, fps, c): read once for every keyframed object
    speeds = _speeds[scene.name] = {}
    for entry in census.entries(scene):
        if not entry.own_velocity:
            continue
        if entry.motion == "CONSTANT":
            speed = math.hypot(*entry.beta)  # (a numpy norm per object: 5 us, a tenth of a 1,000-mesh sync)
        else:
            if keyed is None:
                c = float(scene.relativity.speed_of_light)
                keyed = (scene.frame_start, scene.frame_end, animation.frames_per_second(scene), c)
            speed = _keyframed_speed(entry.obj, keyed)
        speeds[entry.obj.session_uid] = speed
    return _fastest(speeds)


# Scene name -> {object session_uid: speed} of its movers as :func:`fastest_speed` last read them.
_speeds: dict[str, dict[int, float]] = {}


def fastest_speed_with(scene: Scene, obj: Object, speed: float) -> float:
    """:func:`fastest_speed` with ``obj``'s speed now ``speed`` and every other mover's as the last
    :func:`fastest_speed` of ``scene`` read it (a velocity dragged on one mesh, the others unchanged
    since: ``settled.velocity_holds``); read again where there was none."""
    speeds = _speeds.get(scene.name)
    if speeds is None:
        return fastest_speed(scene)
    speeds[obj.session_uid] = speed
    return _fastest(speeds)


def _fastest(speeds: dict[int, float]) -> float:
    # (a speed that is not a number counts for none: it is refused where it is drawn)
    return min(max((speed for speed in speeds.values() if speed == speed), default=0.0), 1.0 - 1e-9)


def _keyframed_speed(obj, keyed):
    start, end, fps, c = keyed
    key = (animation.keyframes_hash(obj), *keyed)
    known = _keyframed_speeds.get(obj.name)
    if known is not None and known[0] == key:
        return known[1]
    count = min(int((end - start) / _SPEED_STEP_FRAMES) + 2, _SPEED_SAMPLES)
    frames = np.linspace(start - _SPEED_STEP_FRAMES, end, count)
    try:
        positions = animation.world_matrices(obj, frames)[:, :3, 3]
    except RelativityError:  # a motion its keyframes do not give: refused where it is drawn
        return 0.0
    if c <= 0.0 or len(frames) < 2:
        return 0.0
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1) / (np.diff(frames) / fps)
    speed = float(np.max(steps)) / c
    _keyframed_speeds[obj.name] = (key, speed)
    return speed


# Frames of the scene's range (fractions of it) at which a Static mesh's keyframed place is compared.
_RANGE_SAMPLES = (0.0, 0.25, 0.5, 0.75, 1.0)


def static_but_keyframed(obj: Object, scene: Scene) -> str | None:
    """A hint (one line) when a mesh on the Apparent Geometry path with Motion left at Static is
    moved by keyframes, its own or an object parent's, over the scene's frame range: it is drawn at
    rest where it is at each frame, with no light delay. None otherwise (also when constraints or
    drivers move it: keyframes alone do not tell then)."""
    if obj.type != "MESH" or not obj.relativity.enabled or obj.relativity.motion != "STATIC":
        return None
    chain = []
    link: Object | None = obj
    while link is not None:
        chain.append(link)
        link = link.parent
    keyed = [link for link in chain if animation.has_transform_keys(link)]
    if not keyed or animation.keyframe_motion_problem(obj, scene) is not None:
        return None
    start, end = scene.frame_start, max(scene.frame_end, scene.frame_start + 1)
    frames = [start + fraction * (end - start) for fraction in _RANGE_SAMPLES] + [scene.frame_current]
    try:
        origins = animation.world_matrices(obj, frames)[:, :3, 3]
    except RelativityError:
        return None
    if np.ptp(origins, axis=0).max() <= 1e-6 * (1.0 + np.abs(origins).max()):
        return None
    mover = "its keyframes" if keyed[0] is obj else f"the keyframes of its parent {keyed[0].name!r}"
    return (
        f"Mesh {obj.name!r} is moved by {mover} but its Motion is Static: it is drawn where it is, "
        "without light delay; set its Motion to Animation"
    )
