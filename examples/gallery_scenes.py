"""The gallery's scenes (``examples/gallery.py``), built with the data API.

Each builder fills an empty Cycles scene and sets ``scene.relativity`` for one figure of
Weiskopf et al. (1999) or Gray et al. (2020). It returns a dict of what the measurements need
(the camera object and, for Gray's sphere arrays, the grid points the spheres were placed for).
Parameters follow the papers and ``presets/relativity/paper_setups/``; Gray's sphere arrays are
those of ``tests/blender/camera/test_camera_gray_sphere_array.py``.
"""

import math

import bpy
import numpy as np
from mathutils import Vector

from relativity_addon.blender.common import compat
from relativity_addon.physics.lorentz import camera_to_scene_event
from relativity_addon.physics.shutter import ShutterModel, lens_time
from scenes import _link, _mesh_from_bmesh, add_box, add_camera, add_sphere, aim, principled_material

SUN_TEMPERATURE = 5762.0
STREET_SPEED = 0.8
SUN_SPEED = 0.5
# Gray's beta = (0.1, 0, 0.99) in Dr TIM's axes (x right, y up, z into the page); the gallery's
# Gray cameras sit at the origin with no rotation, so camera-local axes are world axes: z flips.
GRAY_BETA = (0.1, 0.0, -0.99)
GRAY_LENS_MM = 100.0  # 20.4 degrees horizontal, as Gray's Fig. 3(b)
GRAY_FOCUS = 10.0
GRAY_GRID = np.linspace(-1.0, 1.0, 9)
GRAY_SPHERE_RADIUS = 0.05


# --- materials --------------------------------------------------------------------------------


def emission(name, colour=(1.0, 1.0, 1.0), strength=1.0, temperature=None):
    """Emission-only material; ``temperature`` feeds its colour from a Blackbody node."""
    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    node = tree.nodes.new("ShaderNodeEmission")
    node.inputs["Color"].default_value = (*colour, 1.0)
    node.inputs["Strength"].default_value = strength
    if temperature is not None:
        blackbody = tree.nodes.new("ShaderNodeBlackbody")
        blackbody.inputs["Temperature"].default_value = temperature
        tree.links.new(blackbody.outputs[0], node.inputs["Color"])
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def emission_checker(name, colour1, colour2, scale, strength=1.0):
    material = emission(name, colour1, strength)
    tree = material.node_tree
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Color1"].default_value = (*colour1, 1.0)
    checker.inputs["Color2"].default_value = (*colour2, 1.0)
    checker.inputs["Scale"].default_value = scale
    tree.links.new(checker.outputs["Color"], tree.nodes["Emission"].inputs["Color"])
    return material


def diffuse_checker(name, colour1, colour2, scale):
    material = principled_material(name, colour1, roughness=0.9)
    tree = material.node_tree
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Color1"].default_value = (*colour1, 1.0)
    checker.inputs["Color2"].default_value = (*colour2, 1.0)
    checker.inputs["Scale"].default_value = scale
    tree.links.new(checker.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return material


def plane(scene, name, corners, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(c) for c in corners], [], [(0, 1, 2, 3)])
    return _link(scene, name, mesh, material, (0.0, 0.0, 0.0))


def cylinder(scene, name, location, radius, depth, material, rotation=(0.0, 0.0, 0.0)):
    import bmesh

    mesh = _mesh_from_bmesh(
        name,
        lambda bm: bmesh.ops.create_cone(bm, cap_ends=True, segments=32, radius1=radius, radius2=radius, depth=depth),
    )
    obj = _link(scene, name, mesh, material, location)
    obj.rotation_euler = rotation
    return obj


def world(scene, colour, strength=1.0):
    w = bpy.data.worlds.new("World")
    scene.world = w
    compat.world_node_tree(w)
    background = w.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*colour, 1.0)
    background.inputs["Strength"].default_value = strength


def set_relativity(scene, beta_local=(0.0, 0.0, 0.0), **settings):
    """Velocity in the active camera's local axes (as the paper presets), then the settings."""
    bpy.context.view_layer.update()
    rotation = scene.camera.matrix_world.to_quaternion()
    scene.relativity.velocity_source = "MANUAL"
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(rotation @ Vector(beta_local))
    for key, value in settings.items():
        setattr(scene.relativity, key, value)


# --- Weiskopf et al. (1999): the street (Figs. 4-7) ---------------------------------------------


def street(scene, effect):
    """A street of boxes lit by the sun and a row of street lamps, all at rest; the viewer
    rushes into it at 0.8c (``effect``: REST, GEOMETRY, CHANG, SEARCHLIGHT)."""
    world(scene, (0.30, 0.42, 0.62), 0.8)
    floor = diffuse_checker("Street floor", (0.35, 0.35, 0.35), (0.12, 0.12, 0.12), 60.0)
    plane(scene, "Floor", [(-120, -10, 0), (120, -10, 0), (120, 230, 0), (-120, 230, 0)], floor)
    palette = [(0.75, 0.55, 0.40), (0.55, 0.60, 0.70), (0.80, 0.78, 0.70), (0.50, 0.42, 0.38)]
    heights = [9.0, 14.0, 7.0, 18.0, 11.0, 8.0, 15.0, 10.0, 12.0, 6.0, 16.0, 9.0]
    materials = [principled_material(f"Facade {i}", colour, 0.7) for i, colour in enumerate(palette)]
    lamp = emission("Street lamp", (1.0, 0.85, 0.6), 40.0)
    for side in (-1, 1):
        for i, height in enumerate(heights):
            y = 6.0 + 9.0 * i
            box = add_box(
                scene,
                f"House {side} {i}",
                (side * 9.0, y, height / 2),
                1.0,
                materials[(i + (side > 0)) % len(materials)],
            )
            box.scale = (6.0, 7.5, height)
            if i % 2 == 0:
                add_sphere(scene, f"Lamp {side} {i}", (side * 5.2, y + 4.5, 4.5), 0.25, lamp)
    sun = bpy.data.lights.new("Sun", type="SUN")
    sun.energy = 3.0
    sun.angle = math.radians(2.0)
    sun_object = bpy.data.objects.new("Sun", sun)
    sun_object.location = (30.0, -20.0, 40.0)
    aim(sun_object, Vector((0.0, 40.0, 0.0)))
    scene.collection.objects.link(sun_object)
    camera = add_camera(scene, (0.0, -3.0, 1.7), (0.0, 100.0, 3.0), lens_mm=16.0)
    moving = effect != "REST"
    set_relativity(
        scene,
        (0.0, 0.0, -STREET_SPEED) if moving else (0.0, 0.0, 0.0),
        use_geometry=True,
        use_doppler=False,
        use_searchlight=effect in ("CHANG", "SEARCHLIGHT"),
        use_chang_searchlight=effect == "CHANG",
    )
    return {"camera": camera, "beta_local": (0.0, 0.0, -STREET_SPEED if moving else 0.0)}


COCKPIT_SPEED = 0.9


def _cockpit_frame(scene, camera, material, depth=0.3, outer=(0.6, 0.45), window=(0.24, 0.15)):
    """A flat frame ``depth`` in front of the camera, wider than the 16 mm view there, with an open
    window (half-sizes ``outer`` and ``window``, the window raised a little), parented to the camera."""
    (ox, oy), (ix, iy) = outer, window
    lift = 0.03
    verts = [(-ox, -oy, 0), (ox, -oy, 0), (ox, oy, 0), (-ox, oy, 0)]
    verts += [(-ix, lift - iy, 0), (ix, lift - iy, 0), (ix, lift + iy, 0), (-ix, lift + iy, 0)]
    mesh = bpy.data.meshes.new("Cockpit frame")
    mesh.from_pydata(verts, [], [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)])
    mesh.materials.append(material)
    frame = bpy.data.objects.new("Cockpit frame", mesh)
    scene.collection.objects.link(frame)
    frame.parent = camera
    frame.location = (0.0, 0.0, -depth)
    return frame


def street_cockpit(scene):
    """A fly-through frame: the street (Figs. 4-7) entered at 0.9c from a cockpit that moves with
    the camera (issue 28; docs/cockpit.md): an opaque frame with an open window and a glowing
    instrument strip, lit by a lamp that moves with the camera and by the sky as the moving camera
    sees it. The street is seen through the window with aberration, Doppler colour and searchlight;
    the cockpit as at rest."""
    context = street(scene, "SEARCHLIGHT")
    camera = context["camera"]
    hull = principled_material("Cockpit hull", (0.35, 0.36, 0.4), 0.6)
    frame = _cockpit_frame(scene, camera, hull)
    strip = emission("Instrument strip", (0.1, 1.0, 0.35), 3.0)
    mesh = bpy.data.meshes.new("Instruments")
    mesh.from_pydata(
        [(-0.16, -0.15, 0.0), (0.16, -0.15, 0.0), (0.16, -0.13, 0.0), (-0.16, -0.13, 0.0)], [], [(0, 1, 2, 3)]
    )
    mesh.materials.append(strip)
    instruments = bpy.data.objects.new("Instruments", mesh)
    scene.collection.objects.link(instruments)
    instruments.parent = camera
    instruments.location = (0.0, 0.0, -0.299)  # on the frame, just in front of it
    light = bpy.data.lights.new("Cockpit lamp", "POINT")
    light.energy = 2.0
    light.shadow_soft_size = 0.02
    lamp = bpy.data.objects.new("Cockpit lamp", light)
    scene.collection.objects.link(lamp)
    lamp.parent = camera
    lamp.location = (0.0, 0.2, -0.12)
    for obj in (frame, instruments, lamp):
        obj.relativity.moves_with_camera = True
    rotation = camera.matrix_world.to_quaternion()
    scene.relativity.beta = tuple(rotation @ Vector((0.0, 0.0, -COCKPIT_SPEED)))
    scene.relativity.use_doppler = True
    return {**context, "beta_local": (0.0, 0.0, -COCKPIT_SPEED)}


# --- Weiskopf et al. (1999): the Sun (Figs. 8, 9) ------------------------------------------------

SUN_APPARENT_DEG = (-36.0, -18.0, 0.0, 18.0, 36.0)  # where the moving observer sees the five Suns
SUN_DISTANCE = 14.0


def _scene_angle(apparent_deg, speed):
    """Scene-frame angle from -Z (toward +X) of a direction the observer moving along +X at
    ``speed`` sees at ``apparent_deg``: aberration, cos(theta) = (cos(theta') - b) / (1 - b cos(theta'))
    with theta measured from the direction of motion (docs/physics.md)."""
    cos_seen = math.sin(math.radians(apparent_deg))
    cos_scene = (cos_seen - speed) / (1.0 - speed * cos_seen)
    return 90.0 - math.degrees(math.acos(cos_scene))


def suns(scene, effect):
    """Five Suns (5762 K blackbody spheres) on a dark sky; the observer passes them at 0.5c along
    its +X (the Suns pass by to the left). ``effect``: REST, DOPPLER (Fig. 8), SEARCHLIGHT (Fig. 9)."""
    world(scene, (0.0, 0.0, 0.0), 0.0)
    material = emission("Sun surface", strength=1.0, temperature=SUN_TEMPERATURE)
    for i, apparent in enumerate(SUN_APPARENT_DEG):
        angle = math.radians(_scene_angle(apparent, SUN_SPEED))
        add_sphere(
            scene, f"Sun {i}", (SUN_DISTANCE * math.sin(angle), 0.0, -SUN_DISTANCE * math.cos(angle)), 1.3, material
        )
    camera = add_camera(scene, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), lens_mm=20.0)
    moving = effect != "REST"
    set_relativity(
        scene,
        (SUN_SPEED, 0.0, 0.0) if moving else (0.0, 0.0, 0.0),
        use_geometry=True,
        use_doppler=True,
        use_searchlight=effect == "SEARCHLIGHT",
        doppler_only_brightness="SPECTRUM",
    )
    return {"camera": camera, "beta_local": (SUN_SPEED if moving else 0.0, 0.0, 0.0)}


# --- Gray et al. (2020) ----------------------------------------------------------------------


def gray_camera(scene, lens_mm, focus=None, aperture_radius=None):
    camera = add_camera(scene, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), lens_mm=lens_mm)
    camera.rotation_euler = (0.0, 0.0, 0.0)
    camera.data.clip_start = 0.001
    if aperture_radius:
        camera.data.dof.use_dof = True
        camera.data.dof.focus_distance = focus
        camera.data.dof.aperture_fstop = lens_mm * 1e-3 / (2.0 * aperture_radius)
    return camera


def gray_settings(scene, moving=True, **settings):
    set_relativity(
        scene,
        GRAY_BETA if moving else (0.0, 0.0, 0.0),
        speed_of_light=1.0,
        use_geometry=True,
        use_doppler=False,
        use_searchlight=False,
        **settings,
    )


def sphere_array_centres(model, shutter_time):
    """Grid points P = (x, y, -10) and the scene-frame centres: the events of the chief rays
    passing P (Gray eq. 1), from the physics core's shutter and Lorentz transformation."""
    points = np.array([(x, y, -GRAY_FOCUS) for y in GRAY_GRID[::-1] for x in GRAY_GRID])
    image_distance = 1.0 / (1.0 / (GRAY_LENS_MM * 1e-3) - 1.0 / GRAY_FOCUS)
    detector = -points * (image_distance / GRAY_FOCUS)
    t_lens = lens_time(model, np.zeros_like(points), points, c=1.0, shutter_time=shutter_time, detector_point=detector)
    _, centres = camera_to_scene_event(t_lens - np.linalg.norm(points, axis=-1), points, np.array(GRAY_BETA), 1.0)
    return points, centres


def _share(scene, name, mesh, location):
    obj = bpy.data.objects.new(name, mesh)
    obj.location = tuple(location)
    scene.collection.objects.link(obj)
    return obj


def detector_shutter_time():
    """Gray's Fig. 5: the axial chief ray passes the lens at t = 0."""
    return 1.0 / (1.0 / (GRAY_LENS_MM * 1e-3) - 1.0 / GRAY_FOCUS)


def sphere_array(scene, model, aperture_radius, imaging_element="IDEAL_LENS"):
    """Gray's 9 x 9 array of small white spheres on the scene-frame surface the moving camera
    (shutter ``model``) focuses on the camera-frame plane at distance 10. The phase hologram
    (Fig. 6b) gives the chief rays the ideal lens's times, so the spheres stay where they are."""
    world(scene, (0.0, 0.0, 0.0), 0.0)
    # Shutter times as Gray's: the axial chief ray passes the lens at t = 0 (Figs. 5-7)
    shutter_time = {"DETECTOR_PLANE": detector_shutter_time(), "FOCUS_SURFACE": -GRAY_FOCUS}.get(model, 0.0)
    points, centres = sphere_array_centres(ShutterModel[model], shutter_time)
    material = emission("White", strength=1.0)
    import bmesh

    mesh = _mesh_from_bmesh(
        "Sphere", lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=24, v_segments=12, radius=GRAY_SPHERE_RADIUS)
    )
    for index, centre in enumerate(centres):  # 81 objects sharing one small mesh
        if index == 0:
            _link(scene, f"S{index}", mesh, material, tuple(centre))
        else:
            _share(scene, f"S{index}", mesh, centre)
    camera = gray_camera(scene, GRAY_LENS_MM, GRAY_FOCUS, aperture_radius)
    gray_settings(scene, shutter_model=model, shutter_time=shutter_time, imaging_element=imaging_element)
    return {"camera": camera, "points": points}


def tiles(scene, shutter, moving, time_of_flight=False, zoom_lens_mm=None):
    """Gray's Fig. 1: a tiled floor, a back wall and coloured spheres; pinhole or wide aperture;
    ``time_of_flight``: Fig. 1(c), light-travel time without the Lorentz transformation;
    ``zoom_lens_mm``: a long lens, shifted to centre the direction of motion."""
    world(scene, (0.0, 0.0, 0.0), 0.0)
    floor = emission_checker("Tiles", (0.8, 0.8, 0.8), (0.15, 0.15, 0.15), 40.0, 0.6)
    plane(scene, "Floor", [(-20, -1.5, 0), (20, -1.5, 0), (20, -1.5, -40), (-20, -1.5, -40)], floor)
    wall = emission_checker("Wall", (0.5, 0.5, 0.5), (0.25, 0.25, 0.25), 20.0, 0.6)
    plane(scene, "Wall", [(-20, -1.5, -40), (20, -1.5, -40), (20, 18.5, -40), (-20, 18.5, -40)], wall)
    add_sphere(scene, "Red", (-1.2, -0.7, -8.0), 0.8, emission("Red", (1.0, 0.05, 0.03)))
    add_sphere(scene, "Green", (1.6, -0.2, -13.0), 1.3, emission("Green", (0.05, 0.8, 0.1)))
    add_sphere(scene, "Blue", (-2.5, 0.5, -20.0), 2.0, emission("Blue", (0.1, 0.2, 1.0)))
    wide = shutter == "APERTURE_PLANE"
    # at rest a wide view (12 mm, 113 degrees); moving, aberration shrinks the scene about
    # 20-fold ahead, so 100 mm (20 degrees), as Gray's Fig. 3 (a) and (b)
    camera = gray_camera(scene, 100.0 if moving else 12.0, GRAY_FOCUS if wide else None, 0.2 if wide else None)
    if zoom_lens_mm:
        camera.data.lens = zoom_lens_mm
        camera.data.shift_x = GRAY_BETA[0] / -GRAY_BETA[2] * zoom_lens_mm / camera.data.sensor_width
    gray_settings(scene, moving, shutter_model=shutter, shutter_time=0.0, use_time_of_flight=time_of_flight)
    return {
        "camera": camera,
        "red": ((-1.2, -0.7, -8.0), 0.8),
        "beta_local": GRAY_BETA if moving else (0, 0, 0),
        "time_of_flight": time_of_flight,
    }


FIXED_PLANE = 8.0
MARKERS = [(-0.75, 0.4), (0.75, 0.4), (-0.75, -0.4), (0.75, -0.4)]


def cylinders(scene, moving):
    """Gray's Fig. 8: cylinders whose axes lie in the focus plane z = -8 (camera frame), and four
    red discs in that plane; fixed-point-surface shutter."""
    world(scene, (0.0, 0.0, 0.0), 0.0)
    grey = emission("Grey", (0.6, 0.6, 0.6))
    for i, x in enumerate((-1.5, 0.0, 1.5)):
        cylinder(scene, f"Vertical {i}", (x, 0.0, -FIXED_PLANE), 0.08, 4.0, grey, (math.radians(90.0), 0.0, 0.0))
    for i, y in enumerate((-0.9, 0.9)):
        cylinder(scene, f"Horizontal {i}", (0.0, y, -FIXED_PLANE), 0.08, 5.0, grey, (0.0, math.radians(90.0), 0.0))
    floor = emission_checker("Tiles", (0.35, 0.35, 0.35), (0.1, 0.1, 0.1), 30.0, 1.0)
    plane(scene, "Floor", [(-15, -2.0, 0), (15, -2.0, 0), (15, -2.0, -30), (-15, -2.0, -30)], floor)
    red = emission("Marker", (1.0, 0.0, 0.0), 2.0)
    for i, (x, y) in enumerate(MARKERS):
        mesh = _mesh_from_bmesh(
            f"Disc {i}", lambda bm: __import__("bmesh").ops.create_circle(bm, cap_ends=True, segments=32, radius=0.06)
        )
        _link(scene, f"Disc {i}", mesh, red, (x, y, -FIXED_PLANE))
    camera = gray_camera(scene, 50.0, FIXED_PLANE, 0.02)
    gray_settings(scene, moving, shutter_model="FIXED_POINT_SURFACE", shutter_time=0.0)
    return {"camera": camera}


PORTRAIT_LENS_MM = 50.0
PORTRAIT_FOCUS = 4.4
BACKDROP_DEPTH = 10.0
FIG9_PLANE_POINT = (0.111, 0.0, -1.1)
PUPILS = ((-0.24, 0.45, -4.31), (0.24, 0.45, -4.31))


def fig10_shutter_time(window_time=-1.0):
    """Gray's Fig. 10 caption: the detector-plane shutter opens when the chief ray along the axis,
    which crosses Fig. 9's shutter plane at ``window_time`` (c = 1), reaches the detector: a
    distance ``a`` to the lens centre, then the image distance (the preset's formula)."""
    normal = np.array(GRAY_BETA) / np.linalg.norm(GRAY_BETA)
    a = float(np.array(FIG9_PLANE_POINT) @ normal) / float(np.array([0.0, 0.0, -1.0]) @ normal)
    focal_length = PORTRAIT_LENS_MM * 1e-3
    return window_time + a + 1.0 / (1.0 / focal_length - 1.0 / PORTRAIT_FOCUS)


def portrait(scene, variant):
    """Gray's Fig. 9: a portrait-like scene (head, eyes, body, a tiled backdrop); ``variant`` REST,
    MOVING (shutter in the plane of spatial fixed points for t_S = -1) or WINDOW (plus the
    Lorentz window in that plane). Fig. 10: WINDOW_DETECTOR, the window in that plane with the
    detector-plane shutter (``lorentz_window_shutter = 'SHUTTER_MODEL'``)."""
    world(scene, (0.0, 0.0, 0.0), 0.0)
    backdrop = emission_checker("Backdrop", (0.45, 0.5, 0.55), (0.2, 0.22, 0.25), 16.0, 1.0)
    plane(
        scene,
        "Backdrop",
        [(-6, -5, -BACKDROP_DEPTH), (6, -5, -BACKDROP_DEPTH), (6, 5, -BACKDROP_DEPTH), (-6, 5, -BACKDROP_DEPTH)],
        backdrop,
    )
    add_sphere(scene, "Head", (0.0, 0.35, -5.0), 0.7, emission("Skin", (0.85, 0.6, 0.48)))
    add_sphere(scene, "Hair", (0.0, 0.65, -5.15), 0.68, emission("Hair", (0.25, 0.15, 0.08)))
    white, pupil = emission("Eye", (0.95, 0.95, 0.95)), emission("Pupil", (0.02, 0.05, 0.12))
    for side in (-1, 1):
        add_sphere(scene, f"Eye {side}", (side * 0.24, 0.45, -4.42), 0.12, white)
        add_sphere(scene, f"Pupil {side}", PUPILS[(side + 1) // 2], 0.045, pupil)
    add_sphere(scene, "Nose", (0.0, 0.25, -4.32), 0.09, emission("Nose", (0.8, 0.5, 0.4)))
    body = add_box(scene, "Body", (0.0, -1.55, -5.3), 1.0, emission("Shirt", (0.15, 0.3, 0.7)))
    body.scale = (1.9, 1.7, 0.7)
    camera = gray_camera(scene, PORTRAIT_LENS_MM, PORTRAIT_FOCUS, 0.05)
    shutter = {"shutter_model": "ARBITRARY_PLANE", "shutter_time": -1.0}
    if variant == "WINDOW_DETECTOR":
        shutter = {
            "shutter_model": "DETECTOR_PLANE",
            "shutter_time": fig10_shutter_time(),
            "lorentz_window_shutter": "SHUTTER_MODEL",
            "lorentz_window_time": -1.0,
        }
    gray_settings(
        scene,
        variant != "REST",
        shutter_plane_point=FIG9_PLANE_POINT,
        shutter_plane_normal=GRAY_BETA,
        use_lorentz_window=variant in ("WINDOW", "WINDOW_DETECTOR"),
        **shutter,
    )
    return {"camera": camera, "shutter_time": shutter["shutter_time"], "window_time": -1.0}


def stereo_portrait(scene, variant):
    """Gray's Fig. 11: the Fig. 9 portrait and shutter through Blender's stereo camera, eyes 0.4 apart
    (off-axis, converging at distance 5, as the paper's), written as a red-cyan anaglyph. Both eyes
    share the shutter plane and time (docs/camera.md, Stereo)."""
    context = portrait(scene, variant)
    stereo = scene.camera.data.stereo
    stereo.convergence_mode = "OFFAXIS"
    stereo.interocular_distance = 0.4
    stereo.convergence_distance = 5.0
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    context.update(stereo=True, pivot=stereo.pivot)  # Blender's default pivot: the left eye at the camera
    return context
