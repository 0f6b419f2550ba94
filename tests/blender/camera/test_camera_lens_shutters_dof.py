"""Issue 25: the lens shutter models with and without depth of field.

- Detector plane, depth of field off (how Blender creates every camera): Blender's camera is then a
  pinhole with its sensor at the focal length, so the ray reaches the detector at t_S having
  passed the lens |D|/c earlier (``shutter.image_distance`` and ``lens_time``); its scene-frame
  origin is gamma beta c |D| behind the lens, and the photo is the pinhole photo from there. It
  rendered black: Cycles reports a focal distance of 1e-5 with depth of field off, which the
  shader took for a focus inside the focal length and put the detector 1e6 units away.
- Detector plane with the focus inside the focal length: no real image, refused in one line.
- Pinhole shutter with depth of field on: a panel warning (the pinhole ignores the aperture).
- Focus surface with depth of field on: the rays pass the lens |P|/c after t_S, when the camera
  has moved gamma beta |P| on; at 0.9c focused at 5 that is 10.3 units, past a sphere 5 away, so
  the frame is black (the physics) and the panel says why; t_S = -|P|/c photographs it again.

The expected pixels are computed from docs/physics.md written out in numpy (camera_helpers),
not from the shader or the add-on.
"""

import math

import numpy as np
import pytest

import camera_helpers as ch

RESOLUTION = (64, 48)
CENTER = np.array([0.3, 0.2, -5.0])
RADIUS = 0.5
FOCAL_LENGTH = 0.05  # Blender's default 50 mm lens
COMMON = ("--no-doppler", "--no-searchlight", "--samples=4", "--seed=1")


@pytest.fixture
def addon(factory_blender):
    import relativity_addon
    from relativity_addon.blender.pipeline import effect

    relativity_addon.register()
    yield effect
    relativity_addon.unregister()


def _scene(bpy, use_dof, focus=5.0):
    scene, camera_object = ch.new_scene(bpy, resolution=RESOLUTION, samples=4)
    camera_object.data.dof.use_dof = use_dof
    camera_object.data.dof.focus_distance = focus
    camera_object.data.dof.aperture_fstop = 128.0
    ch.add_sphere(bpy, scene, CENTER, RADIUS, ch.emission_material(bpy), segments=32, rings=16)
    return scene, camera_object


def _measure(image):
    centre, total = ch.centroid(ch.luminance(image), (RESOLUTION[0] / 2, RESOLUTION[1] / 2), 40)
    return centre, total


def test_detector_plane_without_depth_of_field_is_the_pinhole_photo_from_the_detector_time(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = _scene(bpy, use_dof=False)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    blend = ch.save_blend(bpy, tmp_path / "nodof.blend")
    beta = np.array([0.0, 0.0, -0.5])  # toward the sphere
    moving = ("--beta=0,0,-0.5", *COMMON)
    pinhole = ch.render_image(bpy, blend, tmp_path / "pinhole.exr", *moving, "--shutter=pinhole")
    detector = ch.render_image(bpy, blend, tmp_path / "detector.exr", *moving, "--shutter=detector_plane")
    pinhole_centre, pinhole_total = _measure(pinhole)
    detector_centre, detector_total = _measure(detector)
    # The chief ray of the image centre passes the lens |D|/c = f/c before t_S = 0: eq. (1) puts
    # its origin gamma beta c t_L from the lens, 0.029 behind it (the tilt of off-axis rays moves
    # it by less than 1e-3 of a pixel here).
    origin = ch.gamma_of(beta) * beta * -FOCAL_LENGTH
    expected = ch.aberrated_outline_centroid(camera.project_direction, camera.location + origin, CENTER, RADIUS, beta)
    expected_pinhole = ch.expected_sphere_centroid(camera, CENTER, RADIUS, beta)
    print(
        f"0.5c, depth of field off: pinhole total {pinhole_total:.2f} centroid {pinhole_centre}, detector plane "
        f"total {detector_total:.2f} centroid {detector_centre}; expected {expected} (pinhole {expected_pinhole})"
    )
    assert detector_total > 0.9 * pinhole_total > 0.0
    assert np.linalg.norm(detector_centre - expected) < 0.3
    assert np.linalg.norm(detector_centre - pinhole_centre) < 0.2


def test_detector_plane_preset_without_depth_of_field_is_not_blank(addon, factory_blender, tmp_path):
    """Set Up in-process with the shipped preset, as the panel does, and F12."""
    bpy = factory_blender
    scene, _ = _scene(bpy, use_dof=False)
    import runpy

    preset = ch.REPO_ROOT / "presets" / "relativity" / "shutter" / "Detector_plane_ideal_lens.py"
    bpy.context.scene.relativity.beta = (0.0, 0.0, -0.9)
    runpy.run_path(str(preset), init_globals={"bpy": bpy})
    assert scene.relativity.shutter_model == "DETECTOR_PLANE"
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = False
    addon.apply(scene)
    image = ch.render_exr(bpy, scene, tmp_path / "preset.exr")
    centre, total = _measure(image)
    print(f"0.9c preset, depth of field off: total {total:.2f}, centroid {centre}")
    assert total > 5.0


def test_detector_plane_focus_inside_the_focal_length_is_refused(addon, factory_blender):
    from relativity_addon.blender.scene import snapshot
    from relativity_addon.errors import RelativityError

    bpy = factory_blender
    scene, _ = _scene(bpy, use_dof=True, focus=0.03)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    scene.relativity.shutter_model = "DETECTOR_PLANE"
    message = (
        "Camera 'Camera': focus distance 0.03 m is inside the focal length 0.05 m: no image forms "
        "(Detector Plane shutter)"
    )
    with pytest.raises(RelativityError) as error:
        snapshot.read(scene)
    assert str(error.value) == message
    with pytest.raises(RelativityError):
        addon.apply(scene)
    assert message in addon.scene_warnings(scene)
    scene.relativity.shutter_model = "APERTURE_PLANE"  # the other shutters do not need the image
    addon.apply(scene)
    assert message not in addon.scene_warnings(scene)


def test_pinhole_shutter_with_depth_of_field_warns(addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy, use_dof=True)
    warning = "Camera 'Camera': Pinhole shutter ignores depth of field: choose Aperture Plane for a blurred image"
    addon.apply(scene)  # at rest: the shutter model still drops the blur
    assert warning in addon.scene_warnings(scene)
    scene.relativity.shutter_model = "APERTURE_PLANE"
    assert warning not in addon.scene_warnings(scene)
    scene.relativity.shutter_model = "PINHOLE"
    camera_object.data.dof.use_dof = False
    addon.sync(scene)
    assert warning not in addon.scene_warnings(scene)


def test_focus_surface_shutter_past_the_scene_is_black_and_says_why(addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, _ = _scene(bpy, use_dof=True, focus=5.0)
    settings = scene.relativity
    settings.beta = (0.0, 0.0, -0.9)
    settings.shutter_model = "FOCUS_SURFACE"
    settings.use_doppler = False
    settings.use_searchlight = False
    addon.apply(scene)
    late = ch.render_exr(bpy, scene, tmp_path / "late.exr")
    warnings = [w for w in addon.scene_warnings(scene) if "Focus Surface" in w]
    c = settings.speed_of_light
    settings.shutter_time = -5.0 / c  # the axial ray passes the lens at t = 0
    on_time = ch.render_exr(bpy, scene, tmp_path / "on_time.exr")
    late_total, on_time_total = _measure(late)[1], _measure(on_time)[1]
    gamma_beta = 0.9 / math.sqrt(1.0 - 0.81)
    print(
        f"focus surface 0.9c, focus 5: t_S = 0 total {late_total:.3f} (lens event {gamma_beta * 5:.2f} on, "
        f"past the sphere at 5), t_S = -5/c total {on_time_total:.2f}; warnings {warnings}"
    )
    assert late_total == 0.0
    assert on_time_total > 5.0
    assert len(warnings) == 1 and "10.3 m further on" in warnings[0]
    assert not [w for w in addon.scene_warnings(scene) if "Focus Surface" in w]
