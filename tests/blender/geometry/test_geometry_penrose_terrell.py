"""Penrose-Terrell through the mesh path: objects moving at 0.9c past a camera at rest.

A sphere keeps a circular outline in angle space, centred where aberration of its rest-frame
view puts it; a cube shows its trailing face, rotated rather than contracted (the widths of
trailing and front faces are in the ratio beta gamma). Expected values are docs/physics.md relations
written out here (Lorentz boost of the observer event into the sphere's rest frame, aberration).
"""

import math

import numpy as np

import geometry_helpers as gh
from geometry_helpers import ch

C = 5.0  # slow light, scene units per second


def _moving_setup(bpy, resolution=(320, 240), lens=None):
    scene, camera_object = ch.new_scene(bpy, resolution=resolution, samples=4)
    if lens is not None:
        camera_object.data.lens = lens
    scene.relativity.speed_of_light = C
    scene.frame_current = 24
    return scene, camera_object, ch.pinhole_model(bpy, scene, camera_object)


# Outlines and face areas are geometry: searchlight and Doppler colour (tested in
# tests/blender/colour/) would only dim the receding side.
GEOMETRY_ONLY = ("--no-doppler", "--no-searchlight")


def test_moving_sphere_outline_is_circular_at_0_9c(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, _, camera = _moving_setup(bpy)
    u = np.array([0.9, 0.0, 0.0])
    gamma = ch.gamma_of(u)
    # Retarded centre up and to the right in the image, 6 units away; its position at t_o is
    # further along the motion by the distance travelled during the light-travel time.
    retarded = camera.location + 6.0 * camera.local_to_world(camera.pixel_direction(210.0, 90.0))
    now = retarded + u * np.linalg.norm(retarded - camera.location)
    radius = 0.5
    sphere = ch.add_sphere(bpy, scene, now, radius, ch.emission_material(bpy), name="Ball", segments=64, rings=32)
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = tuple(u)
    blend = ch.save_blend(bpy, tmp_path / "ball.blend")
    image = ch.render_image(bpy, blend, tmp_path / "ball.exr", "--method=geometry", "--beta=0,0,0", *GEOMETRY_ONLY)
    ch.run_render_script(blend, tmp_path / "ball.png", "--method=geometry", "--beta=0,0,0", *GEOMETRY_ONLY)
    coverage = np.clip(ch.luminance(image), 0.0, 1.0)
    assert coverage.max() > 0.99, "sphere not resolved"
    ratio, axis = gh.tangent_plane_axis_ratio(camera, coverage)

    # Expected: in the sphere's rest frame R the observer event (S-simultaneous with the centre at
    # `now`) is at x' = dx + (gamma - 1)(uhat.dx) uhat; the sphere subtends a circular cone there;
    # its boundary photons aberrated into S (S moves with -u relative to R).
    dx = camera.location - now
    uhat = u / np.linalg.norm(u)
    offset = dx + (gamma - 1.0) * (uhat @ dx) * uhat
    k_axis = ch.normalized(offset)
    half_angle = math.asin(radius / np.linalg.norm(offset))
    e1 = ch.normalized(np.cross(k_axis, [0.0, 0.0, 1.0]))
    e2 = np.cross(k_axis, e1)
    boundary = []
    for phi in np.linspace(0.0, 2.0 * math.pi, 360, endpoint=False):
        k = math.cos(half_angle) * k_axis + math.sin(half_angle) * (math.cos(phi) * e1 + math.sin(phi) * e2)
        boundary.append(-ch.normalized(ch.aberrate(k, -u)))  # viewing direction in S
    # Aberration maps circles on the sky to circles, but not uniformly in azimuth: the image's
    # axis is the normal of the plane through the mapped boundary, not their mean direction.
    boundary = np.array(boundary)
    normal = np.linalg.svd(boundary - boundary.mean(axis=0))[2][-1]
    normal *= np.sign(normal @ boundary.mean(axis=0))
    expected_axis = ch.normalized(camera.world_to_local(normal))
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])
    offset_px = math.acos(min(1.0, axis @ expected_axis)) * focal_px
    print(f"axis ratio {ratio:.4f} (contracted ellipse: {1 / gamma:.3f}), centre off by {offset_px:.2f} px")
    assert abs(ratio - 1.0) < 0.02
    assert offset_px < 0.5


def _coloured_cube(bpy, scene, location, size, colours):
    """A cube whose faces emit the colours given per outward normal axis ('+X', '-X', ...)."""
    import bmesh

    mesh = bpy.data.meshes.new("Cube")
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=size)
    names = {}
    for key, colour in colours.items():
        material = ch.emission_material(bpy, name=f"Face{key}")
        material.node_tree.nodes["Emission"].inputs["Color"].default_value = (*colour, 1.0)
        names[key] = len(mesh.materials)
        mesh.materials.append(material)
    for face in bm.faces:
        n = face.normal
        axis = max(range(3), key=lambda i: abs(n[i]))
        face.material_index = names[("+" if n[axis] > 0 else "-") + "XYZ"[axis]]
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new("Cube", mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def test_moving_cube_shows_its_trailing_face(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object, camera = _moving_setup(bpy, lens=200.0)
    u = np.array([0.9, 0.0, 0.0])
    distance, size = 12.0, 1.0
    # Camera looks down -Z: retarded centre straight ahead (view perpendicular to the motion).
    retarded = camera.location + np.array([0.0, 0.0, -distance])
    now = retarded + u * distance
    colours = {"+Z": (1, 0, 0), "-X": (0, 1, 0), "+X": (0, 0, 1), "-Z": (1, 1, 0), "+Y": (0, 1, 1), "-Y": (1, 0, 1)}
    cube = _coloured_cube(bpy, scene, now, size, colours)
    cube.relativity.motion = "CONSTANT"
    cube.relativity.beta = tuple(u)
    cube.relativity.tessellation = 2
    blend = ch.save_blend(bpy, tmp_path / "cube.blend")
    image = ch.render_image(bpy, blend, tmp_path / "cube.exr", "--method=geometry", "--beta=0,0,0", *GEOMETRY_ONLY)
    ch.run_render_script(blend, tmp_path / "cube.png", "--method=geometry", "--beta=0,0,0", *GEOMETRY_ONLY)
    rgb = np.clip(image, 0.0, 1.0)
    lit = rgb.sum(-1) > 0.5
    counts = {}
    for key, colour in colours.items():
        match = np.all(np.abs(rgb - np.array(colour, float)) < 0.3, axis=-1) & lit
        counts[key] = int(match.sum())
    print(counts)
    gamma = ch.gamma_of(u)
    # Front (+Z, facing the camera) and trailing (-X) faces are visible; the leading face is not.
    assert counts["+Z"] > 200
    assert counts["+X"] == 0
    # Terrell rotation: trailing face width beta L, front face width L / gamma at the same height.
    ratio = counts["-X"] / counts["+Z"]
    print(f"trailing/front area ratio {ratio:.3f}, beta gamma = {0.9 * gamma:.3f}")
    assert abs(ratio / (0.9 * gamma) - 1.0) < 0.1
