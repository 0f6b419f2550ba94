"""Proper time beyond constant velocity, read off Cycles renders: a keyframed clock (its location keys
are its world line, its rotation keys its own animation), the same clock's face as a child of a
keyframed body, and a shape key (the hand's tip slides) on a clock at constant velocity and on a
keyframed one.

The keyframed world line is constant proper acceleration ``a`` from rest at t = 0 (keys at every
frame): ``x(t) = (c^2 / a)(sqrt(1 + (a t / c)^2) - 1)`` and ``tau(t) = (c / a) asinh(a t / c)``
(docs/physics.md); at constant velocity ``tau = t / gamma``. The expected picture is computed here:
the clock's centre and the hand's tip move on their world lines (the face Lorentz-contracted along
the velocity of that moment), each is seen at its own retarded time (bisection on the light cone),
and projected through the camera. The angle of the tip about the centre in the image (centroids
of the markers' colours) is compared with the render's, within 1 degree; without time dilation
(the hand at scene time) the expected angle is more than 10 degrees away.
"""

import math

import numpy as np
import pytest

import geometry_helpers as gh
from geometry_helpers import ch

RESOLUTION = (320, 160)
FPS = 24
C = 10.0  # scene units per second
ACCELERATION = 10.0  # scene units per s^2: 0.77 c at t = 1.2 s, 0.95 c at 3 s
OMEGA = 2.0  # rad/s of the clock's hand (rotation keys)
SLIDE = 1.0  # units per second of the shape key's tip (value 1 per second, key offset (0, 1, 0))
RADIUS = 1.0
START = 1.0  # the tip's y at shape-key value 0
FRAME = 48  # t_o = 2 s
DISTANCE = 8.0
KEYED_FRAMES = 96


def _hyperbolic(t):
    at = ACCELERATION * np.asarray(t, float) / C
    return C * C / ACCELERATION * (np.sqrt(1.0 + at * at) - 1.0)


def _linear(obj):
    for fcurve in ch.compat.action_fcurves(obj.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"


def _face(bpy, scene):
    """A red dot at the origin (the centre) and a green dot at (RADIUS, 0, 0) (the tip), tessellation 0."""
    clock = gh.clock_face(bpy, scene, RADIUS)
    clock.relativity.tessellation = 0
    return clock


def _key_path(obj, offset):
    """Location keys at every frame: the hyperbolic world line, shifted by ``offset`` along x."""
    for frame in range(KEYED_FRAMES + 1):
        obj.location = (float(_hyperbolic(frame / FPS)) + offset, 0.0, -DISTANCE)
        obj.keyframe_insert("location", frame=frame)
    _linear(obj)


def _key_spin(obj):
    for frame in (0, 240):
        obj.rotation_euler = (0.0, 0.0, OMEGA * frame / FPS)
        obj.keyframe_insert("rotation_euler", index=2, frame=frame)
    _linear(obj)


def _key_slide(bpy, clock):
    """Shape key "Slide": the tip starts at (RADIUS, -START, 0) and its vertices move by (0, 1, 0) at
    value 1; the value is t (seconds)."""
    for vertex in clock.data.vertices:
        if vertex.co.x > 0.5 * RADIUS:
            vertex.co.y -= START
    clock.shape_key_add(name="Basis")
    slide = clock.shape_key_add(name="Slide")
    slide.slider_max = 10.0
    for point in slide.data:
        if point.co.x > 0.5 * RADIUS:
            point.co.y += 1.0
    for frame in (0, 240):
        slide.value = SLIDE * frame / FPS
        slide.keyframe_insert("value", frame=frame)
    for fcurve in ch.compat.action_fcurves(clock.data.shape_keys.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"


def _retarded(position, t_o, camera_position):
    low, high = t_o - 100.0, t_o
    for _ in range(200):
        middle = 0.5 * (low + high)
        ahead = np.linalg.norm(position(middle) - camera_position) - C * (t_o - middle)
        low, high = (low, middle) if ahead > 0.0 else (middle, high)
    return 0.5 * (low + high)


def _render_angle(bpy, scene, tmp_path):
    image = ch.render_exr(bpy, scene, tmp_path / "clock.exr")

    def centroid(channel, others):
        weight = np.where((image[..., channel] > 0.2) & (image[..., others].max(-1) < 0.1), image[..., channel], 0.0)
        assert weight.sum() > 3.0, "the marker is in the picture"
        rows, columns = np.indices(weight.shape)
        return np.array([(weight * (columns + 0.5)).sum(), (weight * (rows + 0.5)).sum()]) / weight.sum()

    return _angle(centroid(0, [1, 2]), centroid(1, [0, 2]))


def _angle(centre, tip):
    return math.degrees(math.atan2(-(tip[1] - centre[1]), tip[0] - centre[0]))  # image y points down


def _scene(bpy):
    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=8)
    scene.render.fps = FPS
    scene.relativity.speed_of_light = C
    return scene, camera


def _render(bpy, scene, tmp_path):
    scene.frame_set(FRAME)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = False
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    return _render_angle(bpy, scene, tmp_path)


def _expected(bpy, scene, camera, centre, velocity, tip_offset, clock):
    """Image angle of the tip about the centre: ``centre(t)`` the world line, ``velocity(t)`` its
    velocity (the face's contraction), ``tip_offset(tau)`` the tip in the face's rest frame at its
    proper time ``tau = clock(t)``. Also returns the tip's retarded time and proper time."""

    def tip(t):
        beta = velocity(t) / C
        speed2 = beta @ beta
        gamma = 1.0 / math.sqrt(1.0 - speed2)
        contraction = np.eye(3) - (1.0 - 1.0 / gamma) * np.outer(beta, beta) / max(speed2, 1e-30)
        return centre(t) + contraction @ tip_offset(clock(t))

    model = ch.pinhole_model(bpy, scene, camera)
    pixels = [
        model.project_direction(f(_retarded(f, FRAME / FPS, model.location)) - model.location) for f in (centre, tip)
    ]
    t_tip = _retarded(tip, FRAME / FPS, model.location)
    return _angle(*pixels), t_tip, clock(t_tip)


def _hyperbolic_world_line():
    """(centre, velocity, proper time) of the keyed clock, shifted so that its light from x = 0 arrives at t_o."""
    shift = -float(_hyperbolic(FRAME / FPS - DISTANCE / C))

    def centre(t):
        return np.array([float(_hyperbolic(t)) + shift, 0.0, -DISTANCE])

    def velocity(t):
        at = ACCELERATION * t / C
        return np.array([C * at / math.sqrt(1.0 + at * at), 0.0, 0.0])

    def clock(t):
        return C / ACCELERATION * math.asinh(ACCELERATION * t / C)

    return shift, centre, velocity, clock


def _spin(tau):
    return np.array([RADIUS * math.cos(OMEGA * tau), RADIUS * math.sin(OMEGA * tau), 0.0])


def _compare(measured, expected, undilated, label, t_e, tau):
    print(
        f"{label}: tip at {measured:.2f} deg in the render, {expected:.2f} deg expected (proper time {tau:.4f} s "
        f"at the retarded time {t_e:.4f} s); at scene time {undilated:.2f} deg"
    )
    assert abs(measured - expected) < 1.0
    assert abs(undilated - expected) > 10.0, "time dilation must be visible in this set-up"


@pytest.mark.parametrize("parented", [False, True])
def test_keyframed_clock_runs_on_proper_time(relativity_addon, tmp_path, parented):
    """Rotation keys play at tau = integral dt / gamma along the location keys' path; a child's
    (the face under a keyed body) along the path its parent carries it on."""
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    shift, centre, velocity, clock = _hyperbolic_world_line()
    face = _face(bpy, scene)
    face.relativity.motion = "ANIMATION"
    _key_spin(face)
    if parented:
        body = bpy.data.objects.new("Body", None)
        scene.collection.objects.link(body)
        _key_path(body, shift)
        face.parent = body  # identity parent inverse: the face sits at the body's origin
    else:
        _key_path(face, shift)
    measured = _render(bpy, scene, tmp_path)
    expected, t_e, tau = _expected(bpy, scene, camera, centre, velocity, _spin, clock)
    undilated, _, _ = _expected(bpy, scene, camera, centre, velocity, _spin, lambda t: t)
    _compare(measured, expected, undilated, "child of a keyed body" if parented else "keyed clock", t_e, tau)


@pytest.mark.parametrize("motion", ["CONSTANT", "ANIMATION"])
def test_shape_keys_run_on_proper_time(relativity_addon, tmp_path, motion):
    """A keyframed shape key (the tip slides along y at 1 unit per second of its clock) is read at
    the proper time of each vertex's retarded time."""
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    face = _face(bpy, scene)
    _key_slide(bpy, face)
    face.relativity.motion = motion
    if motion == "CONSTANT":
        speed = 0.9
        p0 = np.array([speed * DISTANCE, 0.0, -DISTANCE])
        face.location = p0
        face.relativity.beta = (speed, 0.0, 0.0)
        gamma = 1.0 / math.sqrt(1.0 - speed * speed)

        def centre(t):
            return p0 + np.array([speed * C * (t - FRAME / FPS), 0.0, 0.0])

        def velocity(t):
            return np.array([speed * C, 0.0, 0.0])

        def clock(t):
            return t / gamma
    else:
        shift, centre, velocity, clock = _hyperbolic_world_line()
        _key_path(face, shift)

    def slid(tau):
        return np.array([RADIUS, SLIDE * tau - START, 0.0])

    measured = _render(bpy, scene, tmp_path)
    expected, t_e, tau = _expected(bpy, scene, camera, centre, velocity, slid, clock)
    undilated, _, _ = _expected(bpy, scene, camera, centre, velocity, slid, lambda t: t)
    _compare(measured, expected, undilated, f"shape key, {motion.lower()}", t_e, tau)


def test_shape_keys_need_the_mesh_own_vertices(relativity_addon):
    """Tessellated rest points are not the shape keys' vertices: the keys play at the scene's time
    (the shape Blender evaluated, as with Proper Time off), and the object's warning says so and
    names the fix; at Tessellation 0 the warning goes."""
    bpy = __import__("bpy")
    scene, _ = _scene(bpy)
    face = _face(bpy, scene)
    _key_slide(bpy, face)
    face.relativity.motion = "CONSTANT"
    face.relativity.beta = (0.5, 0.0, 0.0)
    face.relativity.tessellation = 1
    scene.frame_set(FRAME)
    mesh_notes = gh.addon_module("pipeline.mesh_notes")
    gh.apply_geometry(scene)
    assert gh.geometry_module().scene_errors(scene) == []
    dilated = gh.evaluated_points(bpy, face)[0]
    (warning,) = [w for w in mesh_notes.object_warnings(scene, face) if "shape keys" in w]
    assert "scene's time" in warning and "Tessellation is above 0" in warning
    face.relativity.use_proper_time = False
    scene.frame_set(FRAME)
    assert np.allclose(gh.evaluated_points(bpy, face)[0], dilated, atol=1e-6), "the scene's time, as without it"
    assert not [w for w in mesh_notes.object_warnings(scene, face) if "shape keys" in w]
    face.relativity.use_proper_time = True
    face.relativity.tessellation = 0
    assert not [w for w in mesh_notes.object_warnings(scene, face) if "shape keys" in w]


def test_armature_hand_runs_on_proper_time(relativity_addon, tmp_path):
    """An armature carries the face along the keyed world line and turns the hand with a keyed bone
    (Armature modifier, vertex group): with the deformation bake, everything about the origin's path
    plays at the proper time of each vertex's retarded time."""
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    shift, centre, velocity, clock = _hyperbolic_world_line()
    armature = bpy.data.objects.new("Rig", bpy.data.armatures.new("Rig"))
    scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    bone = armature.data.edit_bones.new("Hand")
    bone.head, bone.tail = (0.0, 0.0, 0.0), (0.0, 0.0, 0.5)  # its Y axis is the face's normal
    bpy.ops.object.mode_set(mode="OBJECT")
    pose_bone = armature.pose.bones["Hand"]
    pose_bone.rotation_mode = "XYZ"
    for frame in (0, 240):
        pose_bone.rotation_euler = (0.0, OMEGA * frame / FPS, 0.0)
        pose_bone.keyframe_insert("rotation_euler", index=1, frame=frame)
    _key_path(armature, shift)
    face = _face(bpy, scene)
    face.parent = armature
    group = face.vertex_groups.new(name="Hand")
    group.add([v.index for v in face.data.vertices if v.co.x > 0.5 * RADIUS], 1.0, "REPLACE")
    face.modifiers.new("Armature", "ARMATURE").object = armature
    # Which way the bone turns the hand: Blender's own evaluation at one frame (object space).
    scene.frame_set(6)
    bpy.context.view_layer.update()
    evaluated = face.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    tip_now = np.mean([v.co for v in evaluated.vertices if v.co.length > 0.5 * RADIUS], axis=0)
    face.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
    turn = math.atan2(tip_now[1], tip_now[0])
    assert abs(abs(turn) - OMEGA * 6 / FPS) < 1e-3
    sense = math.copysign(1.0, turn)
    face.relativity.motion = "ANIMATION"
    face.relativity.use_deformation = True
    face.relativity.samples_per_frame = 4
    scene.frame_set(FRAME)
    scene.relativity.method = "GEOMETRY"
    gh.addon_module("geometry.bakes").bake_deformation(scene, face, 0, FRAME)
    measured = _render(bpy, scene, tmp_path)

    def spin(tau):
        return _spin(sense * tau)

    expected, t_e, tau = _expected(bpy, scene, camera, centre, velocity, spin, clock)
    undilated, _, _ = _expected(bpy, scene, camera, centre, velocity, spin, lambda t: t)
    _compare(measured, expected, undilated, "armature (deformation bake)", t_e, tau)


def test_clock_table_follows_the_keyframes(relativity_addon):
    """The keyed clock's table (kept between updates) reads (c / a) asinh(a t / c) on the hyperbolic
    keys, is extended when a later time is asked, and is recomputed when the keys change."""
    bpy = __import__("bpy")
    scene, _ = _scene(bpy)
    face = _face(bpy, scene)
    _key_path(face, 0.0)
    world_lines = gh.addon_module("geometry.motion")
    step = 1.0 / (8 * FPS)

    def reading(t):
        return float(world_lines._path_clock(face, FPS, step, C)(np.array([t]))[0])

    for t in (1.0, 3.5, 0.5):  # 3.5 s extends the table
        assert reading(t) == pytest.approx(C / ACCELERATION * math.asinh(ACCELERATION * t / C), abs=2e-4)
    for point in ch.compat.action_fcurves(face.animation_data)[0].keyframe_points:
        point.co.y *= 0.5  # half the path: a slower clock
    changed = reading(3.5)
    world_lines._clock_tables.clear()
    assert changed == reading(3.5)
    assert changed - C / ACCELERATION * math.asinh(ACCELERATION * 3.5 / C) > 0.1


def test_child_of_a_constant_velocity_body(relativity_addon, tmp_path):
    """Hands (the face, with rotation keys) parented to a body at constant velocity 0.9c: a Static
    child is refused in one line; with the body's motion and velocity it rides on the body's world
    line and its keys play at t / gamma."""
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    speed = 0.9
    p0 = np.array([speed * DISTANCE, 0.0, -DISTANCE])
    body_mesh = bpy.data.meshes.new("Body")
    body_mesh.from_pydata([(0.0, 0.0, 0.0), (0.0, 0.0, 0.01), (0.0, 0.01, 0.0)], [], [])  # renders nothing
    body = bpy.data.objects.new("Body", body_mesh)
    scene.collection.objects.link(body)
    body.location = p0
    body.relativity.motion = "CONSTANT"
    body.relativity.beta = (speed, 0.0, 0.0)
    face = _face(bpy, scene)
    _key_spin(face)
    face.parent = body
    scene.frame_set(FRAME)
    with pytest.raises(gh.geometry_module().RelativityError, match="rides on its moving parent 'Body'"):
        gh.apply_geometry(scene)
    face.relativity.motion = "CONSTANT"
    face.relativity.beta = (speed, 0.0, 0.0)
    measured = _render(bpy, scene, tmp_path)
    gamma = 1.0 / math.sqrt(1.0 - speed * speed)

    def centre(t):
        return p0 + np.array([speed * C * (t - FRAME / FPS), 0.0, 0.0])

    def velocity(t):
        return np.array([speed * C, 0.0, 0.0])

    expected, t_e, tau = _expected(bpy, scene, camera, centre, velocity, _spin, lambda t: t / gamma)
    undilated, _, _ = _expected(bpy, scene, camera, centre, velocity, _spin, lambda t: t)
    _compare(measured, expected, undilated, "child of a constant-velocity body", t_e, tau)
