"""Spectral mode of the exact camera: a few Cycles passes at rest-frame wavelengths, one picture.
(Also for Apparent Geometry scenes whose meshes are all at rest: their final renders are exact-camera
renders, ``effect.begin_final_render``.)

``physics/spectral_render.py`` has the model. Here, for the scene's current frame:

1. every pixel's ``D`` from its viewing direction through the camera's frame, as the OSL camera
   computes it (``1 / (gamma (1 - beta.d))``, or ``gamma (1 + beta.d)`` without aberration and
   behind the Lorentz window), which also holds for surfaces without a material (no AOV) and
   costs no render; depth of field spreads ``d`` over the lens, which the pixel centre's ``d``
   approximates;
2. ``passes`` colour passes: materials (``spectral_nodes``), the world and the lights get their
   spectral values at three wavelengths of the band ``[380 D_min, 780 D_max]`` nm, and the
   compositor stage passes the render through;
3. per pixel, the CIE integral of ``D^5 L(lambda D)``.

Everything the passes change (render settings, lights' colours, the stage's mode) is restored
afterwards, also when a pass fails. Works from the operator (F12's sibling in the panel) and the
batch script (``--spectral N``).
"""

from __future__ import annotations

import os
import tempfile
import time
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np

from ...errors import RelativityError
from ...physics import spectral_render
from ..colour import compositing, materials, volumes, world_doppler
from ..common import compat, names
from ..geometry import modifier
from ..scene import snapshot
from . import effect

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy.typing as npt
    from bpy.types import Image, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

IMAGE_NAME = names.SPECTRAL_IMAGE


def ready(scene: Scene) -> None:
    """RelativityError unless the effect is set up with the physical colour settings: the cheap
    part of :func:`check`, for the button's poll (which runs on every redraw of the panel)."""
    if effect.applied_method(scene) is None:
        raise RelativityError("Spectral colour needs the effect: set it up first (Set Up Relativistic Render)")
    settings = scene.relativity
    if not (settings.use_doppler and settings.use_searchlight) or settings.use_chang_searchlight:
        raise RelativityError(
            "Spectral colour renders the physical picture: switch Doppler Colour and "
            "Searchlight on (and Chang's searchlight off)"
        )


def check(scene: Scene) -> None:
    """RelativityError unless the scene is set up for a spectral render (walks the scene's
    objects and materials: :func:`render` runs it, the button's poll only :func:`ready`)."""
    ready(scene)
    if effect.applied_method(scene) == "GEOMETRY":
        # Its passes are exact-camera renders (effect.begin_final_render); each pixel's D is the
        # observer's, so every mesh must be at rest in the scene.
        problem = effect.final_render_problem(scene, snapshot.read(scene))
        if problem is not None and problem != "the observer is at rest":
            raise RelativityError(f"Spectral colour with Apparent Geometry needs the exact final render: {problem}")
        moving = [obj.name for obj in modifier.applied_objects(scene) if obj.relativity.motion != "STATIC"]
        if moving:
            raise RelativityError(
                f"Spectral colour with Apparent Geometry: object {moving[0]!r} moves; each "
                "pixel's D is the observer's (use the fast colour for moving objects)"
            )
    problem = volumes.spectral_problem(scene)
    if problem is not None:
        raise RelativityError(problem)


def _light_spectrum(light, wavelengths):
    """Spectral values of a lamp's colour (its temperature, if used, as a blackbody), >= 0."""
    colour = np.array(light.color, dtype=np.float64)
    if light.use_temperature:
        tint = spectral_render.reflectance_matrix(wavelengths) @ colour
        luminance = spectral_render.luminance(np.array(light.temperature_color, dtype=np.float64))
        values = tint * spectral_render.blackbody_samples(wavelengths, light.temperature, luminance)
    else:
        values = spectral_render.emission_matrix(wavelengths) @ colour
    return np.maximum(values, 0.0)


class _Saved:
    """Everything the passes change, restored by :meth:`restore`."""

    def __init__(self, scene):
        render = scene.render
        settings = render.image_settings
        self.scene = scene
        self.render = {key: getattr(render, key) for key in ("filepath", "use_file_extension", "use_persistent_data")}
        self.image = {key: getattr(settings, key) for key in ("file_format", "color_depth", "color_mode")}
        self.lights = {light.name: (tuple(light.color), light.use_temperature) for light in _scene_lights(scene)}
        self.ray_marching = compat.volume_ray_marching(scene)

    def restore(self) -> None:
        scene = self.scene
        for key, value in self.render.items():
            setattr(scene.render, key, value)
        for key, value in self.image.items():
            setattr(scene.render.image_settings, key, value)
        compat.set_volume_ray_marching(scene, self.ray_marching)
        for name, (colour, use_temperature) in self.lights.items():
            light = bpy.data.lights.get(name)
            if light is not None:
                light.color, light.use_temperature = colour, use_temperature


def pixel_log_doppler(scene: Scene, snap: Snapshot) -> FloatArray:
    """``ln D`` at every pixel centre (rows bottom first, as Blender stores images), for the
    snapshot's projection: a perspective view window or one of the exact camera's panoramas."""
    aberration = bool(snap.use_geometry and not snap.use_lorentz_window)
    size = world_doppler.render_size(scene)
    return world_doppler.pixel_log_doppler(snap.projection, size, snap.beta_camera, aberration)


def _scene_lights(scene):
    """The lamps whose colours the passes set. Not the moving lights' stand-in lamps (white: their
    shaders carry the user's light), nor the moving lights themselves (but suns: a moving sun's
    stand-in, ``D^2`` its strength, gets ``D S(mu D)``, its spectrum shifted by its one ``D``),
    whose stand-ins compute the shifted spectrum at the pass's wavelengths themselves (blackbodies:
    ``moving_lights.blackbody_parameters``, RGB lights: ``moving_lights.rgb_spectral_parameters``)."""
    snap = effect.last_snapshot(scene)
    lights = snap.moving_lights if snap is not None else ()
    shifted = {light.name for light in lights if light.kind != "SUN"}
    return list(
        {
            obj.data
            for obj in scene.objects
            if obj.type == "LIGHT"
            and obj.name not in shifted
            and not (obj.name.startswith(names.MOVING_LAMP_PREFIX) and obj.data.type != "SUN")
        }
    )


def _render_exr(scene, path):
    scene.render.filepath = path
    scene.render.use_file_extension = False
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.color_mode = "RGBA"
    effect.sync(scene)  # the settings group and the compositor stage for this pass
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path, check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)  # bottom row first, as Blender stores images


def render(
    scene: Scene, passes: int, progress: Callable[[int, int], object] | None = None
) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
    """Render the scene's current frame in spectral mode: ``(pixels, info)``, pixels RGBA float32
    (bottom row first, scene linear), info the Doppler range, wavelengths and time taken.
    ``progress(done, total)`` is called after each pass. RelativityError (one line) on failure."""
    check(scene)
    if passes < 1:
        raise RelativityError(f"Spectral passes must be at least 1, got {passes}")
    started = time.monotonic()
    saved = _Saved(scene)
    total = passes
    snap = effect.last_snapshot(scene)
    if snap is None:
        raise RelativityError(
            effect.scene_warnings(scene)[0] if effect.scene_warnings(scene) else "the relativistic camera is not valid"
        )
    log_doppler = pixel_log_doppler(scene, snap)
    try:
        with tempfile.TemporaryDirectory(prefix="relativity_spectral_") as folder:
            d_min, d_max = float(np.exp(log_doppler.min())), float(np.exp(log_doppler.max()))
            wavelengths = spectral_render.sample_wavelengths(d_min, d_max, passes)
            compositing.set_stage_mode("PASS_THROUGH")
            scene.render.use_persistent_data = True  # the passes differ in colours only: keep the scene's BVH
            if volumes.blackbody_materials(scene):
                # 5.x's null scattering renders heterogeneous blackbody gas wrongly in the passes (a
                # grid: the 1127-1357 nm pass black; a node field: 3.4 % dim); ray marching, 4.5's only
                # method, matches 4.5 (docs/spectral-model.md, "Temperature grids in the spectral mode")
                compat.set_volume_ray_marching(scene, True)
            samples = []
            for index in range(passes):
                trio = spectral_render.pass_wavelengths(wavelengths, index)
                materials.set_spectral_pass(trio)
                for name, (colour, use_temperature) in saved.lights.items():  # from the user's lamp each time
                    light = bpy.data.lights[name]
                    light.color, light.use_temperature = colour, use_temperature
                    spectrum = _light_spectrum(light, trio)
                    if names.SUN_DOPPLER_KEY in light:  # a moving sun's stand-in (energy D^2): D S(mu D), eq. 18
                        doppler = float(light[names.SUN_DOPPLER_KEY])
                        rest = light[names.SUN_REST_KEY]  # of the user's sun (the stand-in has the fast mode's)
                        light.color, light.use_temperature = tuple(rest["color"]), bool(rest["use_temperature"])
                        light.temperature = float(rest["temperature"])
                        spectrum = doppler * _light_spectrum(light, tuple(doppler * w for w in trio))
                    light.use_temperature, light.color = False, tuple(spectrum)
                rendered = _render_exr(scene, os.path.join(folder, f"pass{index}.exr"))
                samples.append(rendered[..., :3])
                alpha = rendered[..., 3]
                if progress:
                    progress(index + 1, total)
    except RuntimeError as error:
        message = str(error).strip().splitlines()
        raise RelativityError(f"Spectral render failed: {message[-1] if message else type(error).__name__}") from None
    finally:
        saved.restore()
        materials.set_spectral_pass(None)
        compositing.set_stage_mode("COLOUR")
        effect.sync(scene)
    stacked = np.concatenate(samples, axis=-1).astype(np.float64)  # (H, W, 3 passes)
    rgb = spectral_render.reconstruct_rgb(stacked, log_doppler, wavelengths)
    pixels = np.concatenate([rgb, alpha[..., None]], axis=-1).astype(np.float32)
    info = {"doppler_range": (d_min, d_max), "wavelengths_nm": wavelengths, "seconds": time.monotonic() - started}
    return pixels, info


def store_image(pixels: npt.ArrayLike, name: str = IMAGE_NAME) -> Image:
    """Put the pixels into the float image ``name`` (made or resized as needed) and return it."""
    height, width = pixels.shape[:2]
    image = bpy.data.images.get(name)
    if image is not None and (tuple(image.size) != (width, height) or not image.is_float):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    image.pixels.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())
    image.update()
    return image
