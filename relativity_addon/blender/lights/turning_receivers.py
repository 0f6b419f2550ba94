"""Moving objects that turn, lit by lamps at rest: eq. 18 takes the centre's velocity.

The stand-ins (``lamp_stand_ins.py``) and a sun's copy give each receiving point eq. 18's ``D`` and
aberrated direction ``k'`` for the velocity of the object's centre; a point of an object that turns
moves with the spin's velocity besides. Measured (docs/lamp-doppler.md, "A moving object that
turns": a sphere at 0.5c and a point lamp 3 radii away, renders against a model with each point's
own velocity) the total is off by up to about the rim's speed (31 % at 0.31c, 2.9 % at 0.031c in the
worst of 15 set-ups) and the points' own ``k'`` lie off the stand-ins' line, so the stand-ins cannot
carry them. This module finds the lit objects whose rim is fast enough for that to pass issue 27's
bar (5 % in total) and says so, one panel line each.
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ...physics import lorentz
from ..common import names
from ..geometry import modifier
from ..geometry import motion as world_lines
from ..scene import animation

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ..scene.snapshot import Snapshot

# Rim speed (fraction of c, in the object's frame) from which the panel names a turning object: the
# worst set-up measured was 4.8 % off in total at 0.05c (the error about the rim speed in every set-up).
MIN_RIM_BETA = 0.05

# The bounding box's face centres and edge midpoints (unit box): points whose speeds about the
# centre give the rotation rate (whatever the axis, one is within 13 degrees of square to it: the
# rate is at most 2.4 % under; numpy over 200,000 random axes).
_DIRECTIONS = np.array([step for step in np.ndindex(3, 3, 3) if 1 <= sum(abs(s - 1) for s in step) <= 2]) - 1.0


def rim_beta(scene: Scene, obj: Object, snap: Snapshot) -> float:
    """The largest speed of a vertex about the object's centre, in the centre's frame (fraction of
    c): the rotation rate (the fastest of the box points' speeds there over their distances from
    the centre, at their retarded times) times the farthest vertex's distance."""
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.attributes["position"].data.foreach_get("vector", co)
    if not len(co):
        return 0.0
    co = co.reshape(-1, 3).astype(np.float64)
    low, high = co.min(axis=0), co.max(axis=0)
    points = np.vstack([(low + high) / 2.0, (low + high) / 2.0 + _DIRECTIONS * (high - low) / 2.0])
    at_rest = snap if snap.exact_camera else dataclasses.replace(snap, beta=(0.0, 0.0, 0.0))
    _, beta = world_lines.apparent_world_positions(scene, obj, obj, points, at_rest, shape_keys_too=False)
    beta = np.broadcast_to(beta, points.shape)
    about_centre = lorentz.compose_velocities(-beta[0], beta[1:])  # in the centre's frame
    linear = world_lines.matrix_array(obj.matrix_world)[:3, :3]
    distances = np.linalg.norm((points[1:] - points[0]) @ linear.T, axis=-1)
    usable = distances > 1e-9
    if not usable.any():
        return 0.0
    rate = float(np.max(np.linalg.norm(about_centre[usable], axis=-1) / distances[usable]))
    return rate * float(np.max(np.linalg.norm((co - points[0]) @ linear.T, axis=-1)))


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """One line per turning object lit by lamp copies whose rim passes :data:`MIN_RIM_BETA`."""
    if snap.method != "GEOMETRY":
        return []
    lit = {obj[names.LAMP_DOPPLER_COPY_KEY][1] for obj in scene.objects if names.LAMP_DOPPLER_COPY_KEY in obj}
    found = []
    for obj in modifier.applied_objects(scene):
        if obj.name not in lit or not world_lines.turns(obj, scene):
            continue
        try:
            rim = rim_beta(scene, obj, snap)
        except (RelativityError, ValueError):  # its world line's problem: said by the sync that failed
            continue
        if rim >= MIN_RIM_BETA:
            found.append(
                f"Lamps light {obj.name!r} with its centre's velocity, but it turns (its rim at {rim:.2f}c): "
                f"up to about {rim:.0%} off in total (docs/lamp-doppler.md)"
            )
    return found


# The turn (radians at the rim: beta times the rim's beta) by which the relativity of simultaneity,
# which an object's own animation leaves out (docs/proper-time.md, "Not covered"), may put a moving,
# spinning object's rim off before its panel says so: the proper-time tests' bar, one degree.
MIN_SPIN_LAG = math.radians(1.0)


def spin_warning(obj: Object, scene: Scene, c: float) -> str | None:
    """One line when the object moves and its own Euler rotation keys turn it so fast that the
    simultaneity left out puts its rim :data:`MIN_SPIN_LAG` or more off (``beta beta_rim`` radians,
    both bounded from the keys: ``animation.fastest_key_rates``; the rim its farthest vertex from the
    origin, read only where its box's farthest corner passes), else None. Where the keys give no
    bound (quaternion or axis-angle rotation, other easing, F-curve modifiers) and its own rotation
    keys vary, the line without the angle. No evaluation, no solve."""
    settings = obj.relativity
    if settings.motion not in ("CONSTANT", "ANIMATION") or not world_lines.turns(obj, scene):
        return None
    rates = animation.fastest_key_rates(obj)
    if rates is None:  # quaternion or axis-angle keys, other easing, F-curve modifiers: not bounded
        moves = (
            any(settings.beta) if settings.motion == "CONSTANT" else animation.keys_vary(obj, animation.LOCATION_PATHS)
        )
        if not moves or not animation.keys_vary(obj, animation.ROTATION_PREFIXES):
            return None
        return (
            f"{obj.name!r} spins while it moves: its spin is drawn in the scene's time, not its own (the "
            "relativity of simultaneity is left out); how far off its rim is cannot be read off these "
            "keys (quaternion, axis-angle, eased other than Bezier, or modifiers) (docs/proper-time.md)"
        )
    fps = animation.frames_per_second(scene)
    speed = math.hypot(*settings.beta) if settings.motion == "CONSTANT" else rates[0] * fps / c
    linear = world_lines.matrix_array(obj.matrix_world)[:3, :3]
    per_radius = speed * rates[1] * fps / c
    corners = np.array([tuple(corner) for corner in obj.bound_box], dtype=np.float64)
    if per_radius * float(np.max(np.linalg.norm(corners @ linear.T, axis=-1))) < MIN_SPIN_LAG:
        return None  # not even the box's farthest corner: no vertex read
    co = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.attributes["position"].data.foreach_get("vector", co)
    lag = per_radius * float(np.max(np.linalg.norm(co.reshape(-1, 3) @ linear.T, axis=-1), initial=0.0))
    if lag < MIN_SPIN_LAG:
        return None
    return (
        f"{obj.name!r} spins while it moves: its spin is drawn in the scene's time, not its own (the "
        f"relativity of simultaneity is left out): its rim up to about {math.degrees(lag):.0f} degrees off "
        "(docs/proper-time.md)"
    )
