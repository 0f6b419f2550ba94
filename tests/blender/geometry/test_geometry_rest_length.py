"""CONSTANT and ANIMATION motion agree on an object's length: the modelled mesh is the rest shape,
contracted along the motion in the scene frame whichever way the motion is given.

A rod (thin box, 1 m rest length) passes a camera at rest at 0.9c, once with a CONSTANT velocity
and once keyframed (LINEAR keys, the same velocity). Both renders must show it with the same
length, within 1 px, and with the length that docs/physics.md gives, written out here in numpy:
the rest shape contracted by 1/gamma along x, each corner seen at its retarded position (closed
form of uniform motion), projected by the pinhole camera. Keyframes taken as the world shape (as
before) would draw it 136 px long instead of 58 (it then runs off the image's left edge).
"""

import math

import numpy as np

import geometry_helpers as gh
from geometry_helpers import ch

C = 10.0  # slow light, scene units per second
FPS = 24
FRAME = 24
BETA = np.array([0.9, 0.0, 0.0])
SIZE = np.array([1.0, 0.05, 0.01])  # rest length along the motion, height, depth (thin: end faces ~0 px)
GEOMETRY_ONLY = ("--no-doppler", "--no-searchlight")  # uniform brightness: only the outline counts


def _rod_scene(bpy, motion):
    scene, camera_object = ch.new_scene(bpy, resolution=(160, 48), samples=16)
    scene.relativity.speed_of_light = C
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    scene.frame_start, scene.frame_end = 0, 48
    scene.frame_set(FRAME)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    # The rod's centre is seen 2 m away, left of the image centre; light left it tau = 2 m / c
    # ago, so at t_o it is further along by u tau.
    retarded = camera.location + 2.0 * ch.normalized([-0.3, 0.0, -2.0])
    now = retarded + BETA * np.linalg.norm(retarded - camera.location)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=tuple(now))
    rod = bpy.context.object
    rod.name = "Rod"
    rod.scale = tuple(SIZE)
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)  # the mesh is 1 m long
    rod.data.materials.append(ch.emission_material(bpy))
    rod.relativity.motion = motion
    if motion == "CONSTANT":
        rod.relativity.beta = tuple(BETA)
    else:
        speed = BETA[0] * C / FPS  # units per frame
        gh.keyframe_linear(rod, "location", 0, [(0, now[0] - FRAME * speed), (48, now[0] + (48 - FRAME) * speed)])
    scene.frame_set(FRAME)
    return scene, camera, now


def _expected_corners_px(camera, origin_now, contracted=True):
    """Pixel positions of the rod's corners: docs/physics.md written out (rest shape contracted
    along beta about the origin; retarded time of uniform motion in closed form; pinhole)."""
    gamma = 1.0 / math.sqrt(1.0 - BETA @ BETA)
    corners = np.array([[sx, sy, sz] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5) for sz in (-0.5, 0.5)]) * SIZE
    if contracted:
        corners[:, 0] /= gamma  # the contraction along the motion (x)
    positions_now = origin_now + corners
    u = BETA * C
    delta = camera.location - positions_now
    a = delta @ u
    b = C * C - u @ u
    tau = (a + np.sqrt(a * a + b * np.sum(delta * delta, axis=1))) / b
    seen = positions_now - np.outer(tau, u)
    return np.array([camera.project_direction(point - camera.location) for point in seen])


def _length_px(image):
    """Apparent length along x (pixels) of a bright bar on black: its column profile (lit height
    per column) summed, over the plateau height; the ends' partial pixels count by coverage.
    Also the number of columns lit above half the plateau."""
    profile = ch.luminance(image).sum(axis=0)
    plateau = float(np.median(profile[profile > 0.5 * profile.max()]))
    return float(profile.sum() / plateau), int(np.count_nonzero(profile > 0.5 * plateau)), plateau


def test_constant_and_keyframed_rod_have_the_same_contracted_length(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    lengths = {}
    for motion in ("CONSTANT", "ANIMATION"):
        scene, camera, now = _rod_scene(bpy, motion)
        blend = ch.save_blend(bpy, tmp_path / f"rod_{motion}.blend")
        options = ("--method=geometry", "--beta=0,0,0", f"--frame={FRAME}", *GEOMETRY_ONLY)
        image = ch.render_image(bpy, blend, tmp_path / f"rod_{motion}.exr", *options)
        assert np.isfinite(image).all() and image.min() >= 0.0
        lengths[motion] = _length_px(image)
        expected_px = _expected_corners_px(camera, now)
    expected = float(np.ptp(expected_px[:, 0]))
    # For reference: far-field L0 / gamma / (1 - beta cos theta), theta between the velocity and
    # the line of sight from the rod to the camera; viewed side-on the rod is 0.436 m.
    cos_theta = 0.3 / math.hypot(0.3, 2.0)
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])
    far_field = SIZE[0] * math.sqrt(1.0 - 0.81) / (1.0 - 0.9 * cos_theta) * focal_px / abs(now[2])
    uncontracted = float(np.ptp(_expected_corners_px(camera, now, contracted=False)[:, 0]))
    print(
        f"rod length: CONSTANT {lengths['CONSTANT'][0]:.2f} px ({lengths['CONSTANT'][1]} columns lit), "
        f"ANIMATION {lengths['ANIMATION'][0]:.2f} px ({lengths['ANIMATION'][1]} columns lit), "
        f"expected {expected:.2f} px (far-field estimate {far_field:.2f}, uncontracted {uncontracted:.2f}); "
        f"plateau heights {lengths['CONSTANT'][2]:.2f} / {lengths['ANIMATION'][2]:.2f} px"
    )
    assert abs(lengths["CONSTANT"][0] - lengths["ANIMATION"][0]) < 1.0
    assert abs(lengths["CONSTANT"][0] - expected) < 1.0
    assert abs(lengths["ANIMATION"][0] - expected) < 1.0
    assert abs(lengths["CONSTANT"][1] - lengths["ANIMATION"][1]) <= 1
    assert abs(lengths["ANIMATION"][1] - expected) < 1.5


def test_moving_deforming_mesh_is_contracted_about_its_origin(relativity_addon, factory_blender):
    """A deforming cube (shape keys) carried at 0.6c by LINEAR location keys, through its
    deformation bake: each vertex is where Blender's own evaluation at its retarded sub-frame puts
    the deformed shape, contracted about the object's origin along the origin's velocity (the
    documented convention for deformation bakes). A bake without the origin's path (made by an
    earlier version) is refused with a one-line error naming the fix."""
    bpy = factory_blender
    scene, camera_object = gh.slow_light_scene(bpy, C, FPS)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.2, -3.0))
    blob = bpy.context.object
    blob.shape_key_add(name="Basis")
    stretched = blob.shape_key_add(name="Stretch")
    for i, point in enumerate(stretched.data):
        point.co = point.co * 1.8
        point.co.x += 0.3 * (i % 2)
    stretched.value = 0.0
    stretched.keyframe_insert("value", frame=0)
    stretched.value = 1.0
    stretched.keyframe_insert("value", frame=36)
    speed = 0.6 * C / FPS  # units per frame
    gh.keyframe_linear(blob, "location", 0, [(0, -2.0), (36, -2.0 + 36 * speed)])
    blob.relativity.motion = "ANIMATION"
    blob.relativity.use_deformation = True
    blob.relativity.use_proper_time = False  # Blender's own shape at t_e (the clock: test_geometry_proper_time_*)
    blob.relativity.tessellation = 0
    blob.relativity.samples_per_frame = 8
    frame = 24
    scene.frame_set(frame)
    gh.addon_module("geometry.bakes").bake_deformation(scene, blob, 0, 36)
    gh.apply_geometry(scene)
    x_a, _ = gh.evaluated_points(bpy, blob)
    x_o = np.array(camera_object.matrix_world.translation)
    tau = np.linalg.norm(x_a - x_o, axis=1) / C
    t_e = frame / FPS - tau
    x_e = np.empty_like(x_a)
    uncontracted = np.empty_like(x_a)
    dt = 0.01
    for i, t in enumerate(t_e):
        origins = []
        for offset in (dt, -dt, 0.0):
            whole = math.floor((t + offset) * FPS)
            scene.frame_set(whole, subframe=(t + offset) * FPS - whole)
            origins.append(np.array(blob.matrix_world.translation))
        deformed = gh.evaluated_attribute(bpy, blob, "relativity_rest")[i]  # object space, this sub-frame
        beta = (origins[0] - origins[1]) / (2 * dt * C)
        matrix = np.array(blob.matrix_world)
        x_e[i] = gh.contract((matrix[:3, :3] @ deformed)[None], beta)[0] + origins[2]
        uncontracted[i] = matrix[:3, :3] @ deformed + origins[2]
    scene.frame_set(frame)
    mismatch = np.linalg.norm(x_a - x_e, axis=1) / (C * tau)
    print(
        f"moving deforming cube: max position mismatch {mismatch.max():.2e}, retarded frames "
        f"{t_e.min() * FPS:.2f}..{t_e.max() * FPS:.2f}"
    )
    assert mismatch.max() < 1e-6
    # The contraction is not negligible here: (1 - 1/gamma) of each vertex's ~0.9 m from the origin.
    assert np.max(np.linalg.norm(x_e - uncontracted, axis=1)) > 0.1

    record = gh.addon_module("geometry.modifier").cache_data(blob)[gh.addon_module("common.names").BAKE_KEY]
    del record[gh.addon_module("common.names").BAKE_ORIGINS_KEY]
    scene.frame_set(frame - 1)
    errors = gh.geometry_module().scene_errors(scene)
    assert len(errors) == 1 and "no origin path" in errors[0] and "bake again" in errors[0]
