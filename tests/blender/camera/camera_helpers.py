"""Helpers for the relativistic-camera tests: scene builders, the batch render, pixel measures.

The expected values are computed here from docs/physics.md written out in numpy (aberration,
Doppler factor, pinhole projection), independently of the shader and of the add-on.

Pixel convention: image arrays are indexed [row, column] with row 0 at the top; a pixel
(column i, row j) covers [i, i+1] x [j, j+1], so its centre is at (i + 0.5, j + 0.5).
"""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from relativity_addon.blender.common import compat

REPO_ROOT = Path(__file__).resolve().parents[3]
RENDER_SCRIPT = REPO_ROOT / "examples" / "render.py"


# --- physics written out from docs/physics.md -------------------------------------------------


def gamma_of(beta):
    beta = np.asarray(beta, float)
    return 1.0 / math.sqrt(1.0 - beta @ beta)


def aberrate(k, beta):
    """Photon propagation direction k (scene frame; or an array of them, (..., 3)) -> k' in the
    frame moving with beta."""
    k = np.asarray(k, float)
    beta = np.asarray(beta, float)
    b2 = beta @ beta
    if b2 == 0.0:
        return k.copy()
    g = gamma_of(beta)
    bhat = beta / math.sqrt(b2)
    bk = np.asarray(k @ bhat)[..., None]
    return (k + (g - 1.0) * bk * bhat - g * beta) / (g * (1.0 - np.asarray(k @ beta)[..., None]))


def doppler_factor(k, beta):
    """D = gamma (1 - beta.k): observer moving with beta, source at rest, k scene frame."""
    return gamma_of(beta) * (1.0 - np.asarray(beta, float) @ np.asarray(k, float))


def normalized(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


# --- pinhole camera model ------------------------------------------------------------------


class PinholeCamera:
    """Blender camera at `location` with world rotation matrix `rotation` (columns = local axes).

    The camera looks down local -Z; `window` = (left, right, bottom, top) of the image on the
    plane at unit distance, `size` = (width, height) in pixels.
    """

    def __init__(self, location, rotation, window, size):
        self.location = np.asarray(location, float)
        self.rotation = np.asarray(rotation, float)
        self.window = window
        self.size = size

    def world_to_local(self, v):
        return self.rotation.T @ np.asarray(v, float)

    def local_to_world(self, v):
        return self.rotation @ np.asarray(v, float)

    def project_direction(self, direction_world):
        """Viewing direction (world) -> pixel (x right, y down from top), or None if behind."""
        x, y, z = self.world_to_local(direction_world)
        if z >= 0.0:
            return None
        u, v = x / -z, y / -z
        left, right, bottom, top = self.window
        width, height = self.size
        return np.array([(u - left) / (right - left) * width, (top - v) / (top - bottom) * height])

    def pixel_direction(self, px, py):
        """Pixel coordinates (arrays allowed) -> unit viewing directions in camera-local axes."""
        left, right, bottom, top = self.window
        width, height = self.size
        u = left + np.asarray(px, float) / width * (right - left)
        v = top - np.asarray(py, float) / height * (top - bottom)
        d = np.stack([u, v, -np.ones_like(u)], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)


def apparent_view_direction(marker_position, camera_position, beta):
    """Where a moving pinhole camera at (t=0, camera_position) sees a static point (world)."""
    k = normalized(camera_position - np.asarray(marker_position, float))  # photon propagation
    return -normalized(aberrate(k, beta))


def scene_direction_for_apparent(view_direction, beta):
    """Inverse of apparent_view_direction: the scene-frame viewing direction to place a marker."""
    k_camera = -normalized(view_direction)
    return -normalized(aberrate(k_camera, -np.asarray(beta, float)))


def expected_sphere_centroid(camera, center, radius, beta, samples=720):
    """Area centroid (pixels) of the image of a sphere: the aberrated image of its cone of rays.

    The silhouette seen from the camera position is the cone of directions at half-angle
    asin(radius / distance) around the centre direction; aberration maps that cone's boundary
    to a closed curve; the centroid of the enclosed polygon is what an emission-only sphere's
    intensity-weighted centroid measures (without searchlight).
    """
    return aberrated_outline_centroid(camera.project_direction, camera.location, center, radius, beta, samples)


def aberrated_outline_centroid(project, location, center, radius, beta, samples=720):
    """Area centroid (pixels) of the sphere's cone of rays from ``location``, aberrated by ``beta``
    and mapped to pixels by ``project`` (a world-axes viewing direction -> pixel)."""
    to_center = np.asarray(center, float) - location
    distance = np.linalg.norm(to_center)
    axis = to_center / distance
    half_angle = math.asin(radius / distance)
    e1 = normalized(np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0]))
    e2 = np.cross(axis, e1)
    points = []
    for phi in np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False):
        view = math.cos(half_angle) * axis + math.sin(half_angle) * (math.cos(phi) * e1 + math.sin(phi) * e2)
        view_camera = -normalized(aberrate(-view, beta))
        points.append(project(view_camera))
    polygon = np.array(points)
    x, y = polygon[:, 0], polygon[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    return np.array([((x + xn) * cross).sum() / (6.0 * area), ((y + yn) * cross).sum() / (6.0 * area)])


# --- scene building (in the test process, with bpy) ---------------------------------------


def emission_material(bpy, name="Emitter", strength=1.0):
    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = strength
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material


def reset_cycles_scene(bpy, resolution, samples):
    """The current scene emptied of objects: Cycles on the CPU, black world, no denoising or
    adaptive sampling, Standard view transform (pixels are linear radiance up to clipping)."""
    scene = bpy.context.scene
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("Black")
    world.color = (0.0, 0.0, 0.0)
    compat.world_node_tree(world).nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def new_scene(bpy, resolution=(320, 240), samples=4, rotation_euler=(0.0, 0.0, 0.0), location=(0.0, 0.0, 0.0)):
    """Empty Cycles scene: black world, one perspective camera, no denoising."""
    scene = reset_cycles_scene(bpy, resolution, samples)
    camera_data = bpy.data.cameras.new("Camera")
    camera_data.clip_start = 0.001
    camera_data.clip_end = 1000.0
    camera = bpy.data.objects.new("Camera", camera_data)
    camera.location = location
    camera.rotation_euler = rotation_euler
    scene.collection.objects.link(camera)
    scene.camera = camera
    bpy.context.view_layer.update()
    return scene, camera


def add_sphere(bpy, scene, location, radius, material, name="Marker", segments=48, rings=24):
    import bmesh

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def pinhole_model(bpy, scene, camera):
    bpy.context.view_layer.update()
    corners = camera.data.view_frame(scene=scene)
    xs = [c.x / -c.z for c in corners]
    ys = [c.y / -c.z for c in corners]
    rotation = np.array(camera.matrix_world.to_quaternion().to_matrix())
    return PinholeCamera(
        np.array(camera.matrix_world.translation),
        rotation,
        (min(xs), max(xs), min(ys), max(ys)),
        (scene.render.resolution_x, scene.render.resolution_y),
    )


def save_blend(bpy, path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    return Path(path)


# --- rendering through the user-facing batch script ---------------------------------------


def run_render_script(blend, out, *options, check=True, timeout=300):
    """Run `python examples/render.py blend --out=out options...` as the user would."""
    command = [sys.executable, str(RENDER_SCRIPT), str(blend), f"--out={out}", *options]
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env)
    if check and result.returncode != 0:
        raise AssertionError(f"render.py failed ({result.returncode}): {result.stderr.strip()[-2000:]}")
    return result


def read_image(bpy, path):
    """RGBA float32 pixels [row (top first), column, channel] of a PNG or EXR file."""
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1]


def read_exr(bpy, path):
    """Linear float RGB of an image file as an array [row (top first), column, channel]."""
    return read_image(bpy, path)[:, :, :3].astype(float)


def render_exr(bpy, scene, path):
    """F12 in this process into a 32-bit EXR at ``path``; its linear RGB, top row first."""
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.ops.render.render(write_still=True)
    return read_exr(bpy, path)


def diffuse_material(bpy, name, colour):
    """A Diffuse BSDF material of linear RGB ``colour``."""
    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*colour, 1.0)
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(diffuse.outputs[0], output.inputs["Surface"])
    return material


def render_image(bpy, blend, out, *options):
    run_render_script(blend, out, *options)
    return read_exr(bpy, out)


# --- measurements -------------------------------------------------------------------------


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def _window(intensity, center, half_window):
    """The square patch of ``intensity`` around ``center`` (clipped to the image), its pixel-centre
    coordinates ``xs, ys`` and its total."""
    height, width = intensity.shape
    cx, cy = int(round(center[0])), int(round(center[1]))
    x0, x1 = max(cx - half_window, 0), min(cx + half_window + 1, width)
    y0, y1 = max(cy - half_window, 0), min(cy + half_window + 1, height)
    patch = intensity[y0:y1, x0:x1]
    ys, xs = np.mgrid[y0:y1, x0:x1]
    return patch, xs + 0.5, ys + 0.5, patch.sum()


def centroid(intensity, center, half_window):
    """Intensity-weighted centroid in pixel coordinates within a square window."""
    patch, xs, ys, total = _window(intensity, center, half_window)
    if total <= 0.0:
        return None, 0.0
    return np.array([(xs * patch).sum() / total, (ys * patch).sum() / total]), total


def rms_radius(intensity, center, half_window):
    """RMS distance (pixels) of the intensity from ``center``, within a square window around it:
    the square root of the intensity-weighted second moment, a size measure of a spot."""
    patch, xs, ys, total = _window(intensity, center, half_window)
    if total <= 0.0:
        return float("nan")
    squared = (xs - center[0]) ** 2 + (ys - center[1]) ** 2
    return math.sqrt((squared * patch).sum() / total)


def tangent_plane_axis_ratio(camera, coverage):
    """Axis ratio of a silhouette measured in angle space (on the tangent plane of the sky at its
    centre, so perspective projection does not stretch it) and the silhouette's axis."""
    ys, xs = np.nonzero(coverage > 0.0)
    weights = coverage[ys, xs]
    directions = camera.pixel_direction(xs + 0.5, ys + 0.5)  # camera-local unit vectors
    # Pixel solid angle is proportional to |u_z|^3 per image-plane area.
    solid_angle = weights * np.abs(directions[:, 2]) ** 3
    axis = normalized((directions * solid_angle[:, None]).sum(axis=0))
    for _ in range(5):
        e1 = normalized(np.cross(axis, [0.0, 1.0, 0.0]))
        e2 = np.cross(axis, e1)
        cos_axis = directions @ axis
        plane = directions / cos_axis[:, None]
        coords = np.stack([plane @ e1, plane @ e2], axis=1)
        # Area on the tangent plane = solid angle / cos^3 of the angle to its normal.
        area = solid_angle / cos_axis**3
        mean = (coords * area[:, None]).sum(axis=0) / area.sum()
        axis = normalized(axis + mean[0] * e1 + mean[1] * e2)
    centred = coords - mean
    covariance = (centred.T * area) @ centred / area.sum()
    eigenvalues = np.linalg.eigvalsh(covariance)
    return math.sqrt(eigenvalues[0] / eigenvalues[1]), axis


def pixel_rays(resolution, sensor, lens):
    """Unit scene directions of the pixel centres' rays of a pinhole camera looking along +Y, image
    up +Z (horizontal sensor fit; ``sensor`` and ``lens`` in mm), ``(height, width, 3)``."""
    width, height = resolution
    scale = sensor / lens / width
    columns = (np.arange(width) + 0.5 - width / 2.0) * scale
    rows = (height / 2.0 - np.arange(height) - 0.5) * scale
    x, z = np.meshgrid(columns, rows)
    rays = np.stack([x, np.ones_like(x), z], axis=-1)
    return rays / np.linalg.norm(rays, axis=-1, keepdims=True)
