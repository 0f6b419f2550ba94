"""The world's ``ln D`` from each pixel's direction, instead of a Doppler AOV written per sample.

A camera ray that meets the world has a Doppler factor that depends on its direction alone, so
the compositor stage (``compositing``) takes the world pixels' ``ln D`` from an image instead of
an AOV that Cycles would write at every sample (0.09 us a sample, measured on a world-only
panorama): the image ``Relativity World Doppler`` holds ``ln D`` of every pixel centre's
camera-frame direction (``physics.exposure``: the perspective view window, or Blender's panorama
projections, as the exact camera's shader maps them), and the compositor forms

    ln D = AOV + (1 - coverage) ln D_pixel,

``coverage`` being the share of the pixel's samples that wrote the AOV (the materials). Samples
scattered in a volume write no AOV either: with the scene at rest their ray has the pixel's
direction, so they get the right ``D`` too. Depth of field and the shutter models spread the
directions within a pixel (over the lens); the pixel centre stands for them (docs/camera.md).

Where the image cannot stand for the world's rays, the world keeps its AOV writer and the
compositor divides the AOV by the coverage as before (``problem``): time-of-flight mode (its rays
leave along ``d - beta``), Blender's stereo pair (each eye's view is shifted or turned), a render
cropped to its border, a panorama with a lens shift. The image is written at every sync whose
inputs changed before a render (``render_pre``, every frame of an animation render), sized to
the render (its percentage included), from the frame's snapshot alone, and packed into the file
(0.3 s for 1920 x 1080), so that a saved file renders the same without the add-on; it goes with
the effect.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ...physics import exposure
from ..common import names
from . import compositing

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt
    from bpy.types import Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

IMAGE = names.WORLD_DOPPLER_IMAGE
AOV_NODE = f"{names.MATERIAL_NODE_PREFIX} AOV"  # materials._insert_aov_writer's node in the world
_written = {}  # image session_uid -> the inputs its pixels were computed from


def render_size(scene: Scene) -> tuple[int, int]:
    render = scene.render
    return (
        max(1, int(render.resolution_x * render.resolution_percentage / 100)),
        max(1, int(render.resolution_y * render.resolution_percentage / 100)),
    )


def problem(scene: Scene, snap: Snapshot) -> str | None:
    """Why the world must write its own ``ln D`` AOV in this render (one line), or None."""
    render = scene.render
    if snap.use_time_of_flight:
        return "time-of-flight rays leave along d - beta"
    if snap.stereo:
        return "a stereo pair's eyes look along shifted directions"
    if render.use_border and render.use_crop_to_border:
        return "the render is cropped to its border"
    kind = snap.projection[0]
    if kind in exposure.PANORAMAS:
        values = dict(snap.projection[1:])
        return "a panorama with a lens shift" if values["shift_x"] or values["shift_y"] else None
    if kind != "PERSP":
        return f"a {kind} camera"
    return None


def _inputs(scene, snap):
    """What the image depends on: camera type and projection, size, velocity, aberration."""
    aberration = bool(snap.use_geometry and not snap.use_lorentz_window)
    return snap.projection, render_size(scene), tuple(float(b) for b in snap.beta_camera), aberration


def pixel_log_doppler(
    projection: Sequence[Any], size: tuple[int, int], beta_camera: npt.ArrayLike, aberration: bool
) -> FloatArray:
    """``ln D`` at every pixel centre (rows bottom first) for :func:`_inputs`' values; 0 outside a
    fisheye's or mirror ball's image circle (the camera renders black there)."""
    kind = projection[0]
    if kind == "PERSP":
        return exposure.log_doppler(exposure.pixel_directions(projection[1:], size), beta_camera, aberration)
    values = dict(projection[1:])
    directions, inside = exposure.panorama_directions(
        kind,
        size,
        (values["longitude_min"], values["longitude_max"]),
        (values["latitude_min"], values["latitude_max"]),
        values["fisheye_fov"],
        values["fisheye_lens"],
        (values["sensor_width"], values["sensor_height"]),
    )
    return np.where(inside, exposure.log_doppler(directions, beta_camera, aberration), 0.0)


def _mute_world_writer(world, mute):
    node = world.node_tree.nodes.get(AOV_NODE) if world is not None and world.node_tree is not None else None
    if node is not None and node.mute != mute:
        node.mute = mute


def write(scene: Scene, snap: Snapshot, pixels: bool = True) -> bool:
    """Bring the world's AOV writer, the compositor's switch and (with ``pixels``: before a render)
    the image up to date for ``snap`` (exact camera, compositor stage applied). Only what changed
    is written: the image costs a few tenths of a second at full HD, too much for every edit."""
    if not compositing.is_applied(scene):
        return False
    use_image = problem(scene, snap) is None
    # an older file's compositor group has no World Directions input: its world keeps the writer
    use_image = compositing.write_world_directions(scene, 1.0 if use_image else 0.0) and use_image
    _mute_world_writer(scene.world, use_image)  # a muted writer is left out of the shader
    if not use_image or not pixels:
        return use_image
    inputs = _inputs(scene, snap)
    image = compositing.ensure_world_image(inputs[1])
    if _written.get(image.session_uid) == inputs:
        return True
    log_doppler = pixel_log_doppler(*inputs)
    pixels = np.zeros((*log_doppler.shape, 4), dtype=np.float32)
    pixels[..., 0] = log_doppler
    pixels[..., 3] = 1.0
    image.pixels.foreach_set(pixels.ravel())
    image.update()
    image.pack()  # into the .blend (as OpenEXR): the saved file renders the same without the add-on
    _written[image.session_uid] = inputs
    return True
