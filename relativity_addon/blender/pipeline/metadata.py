"""The physics of each frame in the output's metadata: the observer's velocity and the exposure.

A compensated exposure multiplies the frame by one factor (``physics/exposure.py``); the factor,
with the velocity and the speed of light, goes into Blender's *Note* metadata field
(``render.stamp_note_text``, written into PNG, EXR and the other formats that keep metadata, not
burnt into the image unless the user asks for it), so that the physical brightness is
recoverable from any output file: divide by ``exposure``. ``render=`` says what made the image: the
exact camera, or Apparent Geometry's boosted-mesh preview. A set-up file keeps the preview's note,
so a render of it without the add-on (no handler swaps the exact camera in for the final render)
says that it is the preview. The user's own note comes back when the effect is removed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..common import names

if TYPE_CHECKING:
    from bpy.types import Scene

    from ..scene.snapshot import Snapshot

SAVED_KEY = names.STAMP_SAVED_KEY
PREFIX = "relativity:"


def note(snap: Snapshot) -> str:
    beta = ",".join(f"{b:.9g}" for b in snap.beta)
    return (
        f"{PREFIX} exposure={snap.exposure:.9g} ({snap.exposure_mode.lower()}) beta={beta} "
        f"speed={snap.speed:.9g} c={snap.speed_of_light:.9g} frame={snap.frame:g} method={snap.method.lower()}"
        f" render={'exact-camera' if snap.exact_camera else 'boosted-mesh-preview'}"
        + (" kinematics=galilean (time of flight only, not relativity)" if snap.use_time_of_flight else "")
    )


def write(scene: Scene, snap: Snapshot) -> None:
    """Write the frame's note (only when it changed: a write triggers a depsgraph update)."""
    render = scene.render
    if SAVED_KEY not in scene:
        scene[SAVED_KEY] = {"use_stamp_note": render.use_stamp_note, "stamp_note_text": render.stamp_note_text}
    text = note(snap)
    if not render.use_stamp_note:
        render.use_stamp_note = True
    if render.stamp_note_text != text:
        render.stamp_note_text = text


def remove(scene: Scene) -> bool:
    """Give the user's note back."""
    if SAVED_KEY not in scene:
        return False
    saved = scene[SAVED_KEY].to_dict()
    scene.render.use_stamp_note = bool(saved["use_stamp_note"])
    scene.render.stamp_note_text = saved["stamp_note_text"]
    del scene[SAVED_KEY]
    return True
