"""Panoramic relativistic cameras: Blender's equirectangular, fisheye and mirror-ball panoramas
through the exact camera.

At beta = 0 each panorama renders like Blender's own panoramic camera; at 0.9c markers over the
whole sphere land where the aberration formula puts them (the panorama's projection written out
below in numpy from Blender's documented lens models, independently of the shader); the searchlight
ratio of two emitters is their D^4 ratio.
"""

import math

import numpy as np
import pytest

import camera_helpers as ch

CAMERA_LOCATION = (0.3, -0.2, 0.5)
CAMERA_ROTATION = (math.radians(80.0), math.radians(10.0), math.radians(30.0))
DISTANCE = 10.0


# --- the panoramas' projections (camera-local axes: +X right, +Y up, -Z forward) ------------


def equirectangular_pixel(direction_local, size, longitude=(-math.pi, math.pi), latitude=(-math.pi / 2, math.pi / 2)):
    x, y, z = ch.normalized(direction_local)
    lon = math.atan2(x, -z)
    lat = math.asin(max(-1.0, min(1.0, y)))
    width, height = size
    return np.array(
        [
            (lon - longitude[0]) / (longitude[1] - longitude[0]) * width,
            (latitude[1] - lat) / (latitude[1] - latitude[0]) * height,
        ]
    )


def equirectangular_direction(px, py, size):
    width, height = size
    lon = -math.pi + px / width * 2.0 * math.pi
    lat = math.pi / 2 - py / height * math.pi
    return np.array([math.cos(lat) * math.sin(lon), math.sin(lat), -math.cos(lat) * math.cos(lon)])


def equidistant_pixel(direction_local, size, fov):
    """Fisheye equidistant: image radius proportional to the angle from the axis, the circle
    filling the frame."""
    x, y, z = ch.normalized(direction_local)
    theta = math.acos(max(-1.0, min(1.0, -z)))
    r = theta / (fov / 2.0)
    phi = math.atan2(y, x)
    width, height = size
    return np.array([(0.5 + 0.5 * r * math.cos(phi)) * width, (0.5 - 0.5 * r * math.sin(phi)) * height])


def equidistant_direction(px, py, size, fov):
    width, height = size
    u, v = 2.0 * px / width - 1.0, 1.0 - 2.0 * py / height
    r = math.hypot(u, v)
    theta = r * fov / 2.0
    s = math.sin(theta) / r if r > 0 else 0.0
    return np.array([u * s, v * s, -math.cos(theta)])


def expected_centroid(project, camera_rotation, center, radius, camera_location, beta, samples=360):
    """Area centroid (pixels) of a sphere's image: its cone of rays, aberrated, projected."""
    return ch.aberrated_outline_centroid(
        lambda view: project(camera_rotation.T @ view), camera_location, center, radius, beta, samples
    )


def _panorama_scene(bpy, panorama_type, resolution, samples=2, fov=math.pi):
    scene, camera_object = ch.new_scene(
        bpy, resolution=resolution, samples=samples, rotation_euler=CAMERA_ROTATION, location=CAMERA_LOCATION
    )
    data = camera_object.data
    data.type = "PANO"
    data.panorama_type = panorama_type
    data.fisheye_fov = fov
    data.fisheye_lens = 8.0
    bpy.context.view_layer.update()
    rotation = np.array(camera_object.matrix_world.to_quaternion().to_matrix())
    return scene, camera_object, rotation


def _markers(bpy, scene, rotation, beta, apparent_directions, pixel_angle, apparent_radius_px=3.0):
    """Markers placed so that the moving camera sees them along the given camera-local directions."""
    material = ch.emission_material(bpy)
    location = np.array(CAMERA_LOCATION, float)
    markers = []
    for index, local in enumerate(apparent_directions):
        view_scene = ch.scene_direction_for_apparent(rotation @ ch.normalized(local), beta)
        doppler = ch.doppler_factor(-view_scene, beta)  # apparent angular size shrinks by 1/D
        radius = DISTANCE * math.sin(apparent_radius_px * pixel_angle * doppler)
        center = location + DISTANCE * view_scene
        ch.add_sphere(bpy, scene, center, radius, material, name=f"Marker{index}", segments=32, rings=16)
        markers.append((center, radius))
    return markers


def _measure(intensity, markers, project, rotation, beta, half_window):
    errors = []
    for center, radius in markers:
        expected = expected_centroid(project, rotation, center, radius, np.array(CAMERA_LOCATION, float), beta)
        measured, _ = ch.centroid(intensity, expected, half_window=half_window)
        assert measured is not None, f"marker expected at {expected} not found"
        errors.append(float(np.linalg.norm(measured - expected)))
    return np.array(errors)


BETA_DIRECTION = (0.3, 1.0, 0.2)  # world: oblique to the camera's axes


@pytest.fixture
def addon(factory_blender):
    """The add-on registered from this source tree (in-process)."""
    import relativity_addon
    from relativity_addon.blender.pipeline import effect

    relativity_addon.register()
    yield effect
    relativity_addon.unregister()


def _render_in_process(bpy, scene, path, seed):
    scene.cycles.seed = seed
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return ch.read_exr(bpy, path)


# --- tests -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "panorama_type,resolution",
    [
        ("EQUIRECTANGULAR", (128, 64)),
        ("FISHEYE_EQUIDISTANT", (96, 72)),
        ("FISHEYE_EQUISOLID", (96, 72)),
        ("MIRRORBALL", (96, 72)),
    ],
)
def test_rest_equals_blender_panorama(addon, factory_blender, tmp_path, panorama_type, resolution):
    """At beta = 0 the exact camera is Blender's own panoramic camera (non-square frames check the
    fisheye's aspect and sensor fit). Rendered in the test process (the batch script's path is
    the other tests')."""
    bpy = factory_blender
    scene, _camera, _rotation = _panorama_scene(bpy, panorama_type, resolution, fov=math.radians(220.0))
    material = ch.emission_material(bpy)
    rng = np.random.default_rng(7)
    for index in range(30):
        direction = ch.normalized(rng.normal(size=3))
        ch.add_sphere(
            bpy,
            scene,
            np.array(CAMERA_LOCATION) + DISTANCE * direction,
            0.9,
            material,
            name=f"S{index}",
            segments=16,
            rings=8,
        )
    reference = _render_in_process(bpy, scene, tmp_path / "ref0.exr", seed=0)
    other_seed = _render_in_process(bpy, scene, tmp_path / "ref1.exr", seed=1)
    addon.apply(scene)  # beta = 0, pinhole shutter (the settings' defaults)
    assert scene.camera.data.type == "CUSTOM"
    relativistic = _render_in_process(bpy, scene, tmp_path / "rel.exr", seed=0)
    addon.remove(scene)
    assert scene.camera.data.type == "PANO" and scene.camera.data.panorama_type == panorama_type
    noise = np.abs(other_seed - reference).mean()
    difference = np.abs(relativistic - reference).mean()
    print(f"{panorama_type}: mean |rel - Blender| = {difference:.3g}, seed noise = {noise:.3g}")
    assert reference.mean() > 0.005, "reference render is black"
    assert noise > 0.0
    assert difference < 0.25 * noise


def test_equirectangular_markers_over_the_sphere_follow_aberration(factory_blender, tmp_path):
    """0.9c: markers all round the sphere (front, sides, behind, up and down) within 1 px at 720x360."""
    bpy = factory_blender
    size = (720, 360)
    scene, _camera, rotation = _panorama_scene(bpy, "EQUIRECTANGULAR", size, samples=2)
    beta = 0.9 * ch.normalized(BETA_DIRECTION)
    pixels = [(x, y) for y in (70.0, 180.0, 290.0) for x in (40.0, 160.0, 290.0, 400.0, 530.0, 660.0)]
    apparent = [equirectangular_direction(px, py, size) for px, py in pixels]
    markers = _markers(bpy, scene, rotation, beta, apparent, pixel_angle=2.0 * math.pi / size[0])
    blend = ch.save_blend(bpy, tmp_path / "equirect.blend")
    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy, blend, tmp_path / "equirect.exr", f"--beta={beta_option}", "--shutter=pinhole", "--no-searchlight"
    )
    errors = _measure(ch.luminance(image), markers, lambda d: equirectangular_pixel(d, size), rotation, beta, 14)
    print(f"equirectangular 0.9c: max error {errors.max():.3f} px, mean {errors.mean():.3f} px")
    assert errors.max() < 1.0, f"position errors (px): {np.round(errors, 3)}"


def test_fisheye_markers_follow_aberration(factory_blender, tmp_path):
    """0.9c, fisheye equidistant with a 240 degree field of view: markers across it within 1 px."""
    bpy = factory_blender
    size, fov = (240, 240), math.radians(240.0)
    scene, _camera, rotation = _panorama_scene(bpy, "FISHEYE_EQUIDISTANT", size, samples=2, fov=fov)
    beta = 0.9 * ch.normalized(BETA_DIRECTION)
    pixels = [(120.0, 120.0)] + [
        (120.0 + r * math.cos(a), 120.0 - r * math.sin(a))
        for r in (45.0, 95.0)
        for a in np.linspace(0.3, 0.3 + 2 * math.pi, 5, endpoint=False)
    ]
    apparent = [equidistant_direction(px, py, size, fov) for px, py in pixels]
    markers = _markers(bpy, scene, rotation, beta, apparent, pixel_angle=fov / size[0])
    blend = ch.save_blend(bpy, tmp_path / "fisheye.blend")
    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy, blend, tmp_path / "fisheye.exr", f"--beta={beta_option}", "--shutter=pinhole", "--no-searchlight"
    )
    errors = _measure(ch.luminance(image), markers, lambda d: equidistant_pixel(d, size, fov), rotation, beta, 12)
    print(f"fisheye equidistant 0.9c: max error {errors.max():.3f} px, mean {errors.mean():.3f} px")
    assert errors.max() < 1.0, f"position errors (px): {np.round(errors, 3)}"


def test_panorama_searchlight_ratio_is_doppler_fourth_power(factory_blender, tmp_path):
    """Two emitters, one ahead and one behind the moving equirectangular camera: radiance ratio =
    D^4 ratio within 2 %."""
    bpy = factory_blender
    size = (240, 120)
    scene, _camera, rotation = _panorama_scene(bpy, "EQUIRECTANGULAR", size, samples=4)
    beta = 0.5 * ch.normalized(BETA_DIRECTION)
    pixels = [(60.0, 50.0), (200.0, 70.0)]
    apparent = [equirectangular_direction(px, py, size) for px, py in pixels]
    _markers(bpy, scene, rotation, beta, apparent, pixel_angle=2.0 * math.pi / size[0], apparent_radius_px=9.0)
    dopplers = [ch.doppler_factor(-ch.scene_direction_for_apparent(rotation @ a, beta), beta) for a in apparent]
    blend = ch.save_blend(bpy, tmp_path / "emitters.blend")
    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy,
        blend,
        tmp_path / "emitters.exr",
        f"--beta={beta_option}",
        "--shutter=pinhole",
        "--no-doppler",
        "--samples=4",
    )
    intensity = ch.luminance(image)
    ys, xs = np.mgrid[0 : intensity.shape[0], 0 : intensity.shape[1]]
    radiances = [intensity[np.hypot(xs + 0.5 - px, ys + 0.5 - py) < 4.0].mean() for px, py in pixels]
    measured = radiances[0] / radiances[1]
    expected = (dopplers[0] / dopplers[1]) ** 4
    print(f"D = {dopplers[0]:.4f}, {dopplers[1]:.4f}; ratio measured {measured:.4f}, expected {expected:.4f}")
    for radiance, doppler in zip(radiances, dopplers, strict=True):
        assert radiance == pytest.approx(doppler**4, rel=0.02)
    assert measured == pytest.approx(expected, rel=0.02)
    assert abs(math.log(expected)) > 0.5, "test emitters must differ clearly in D"


def test_panorama_camera_restored_and_lens_models_refused(addon, factory_blender):
    """A panoramic camera comes back panoramic with its settings; what needs a thin lens says so."""
    bpy = factory_blender
    scene, camera_object, _rotation = _panorama_scene(bpy, "FISHEYE_EQUISOLID", (64, 48), fov=math.radians(190.0))
    data = camera_object.data
    data.latitude_min, data.longitude_max = -0.7, 2.5
    settings = {
        name: getattr(data, name)
        for name in (
            "panorama_type",
            "fisheye_fov",
            "fisheye_lens",
            "latitude_min",
            "latitude_max",
            "longitude_min",
            "longitude_max",
        )
    }
    scene.relativity.beta = (0.0, 0.6, 0.0)
    addon.apply(scene)
    custom = data.cycles_custom
    assert data.type == "CUSTOM" and custom["projection"] == 3
    assert custom["fisheye_lens"] == pytest.approx(8.0) and custom["fisheye_fov"] == pytest.approx(math.radians(190.0))
    # 64x48 with AUTO fit: the 36 mm sensor width across, the height by the aspect.
    assert (custom["sensor_width"], custom["sensor_height"]) == pytest.approx((36.0, 27.0))
    assert not addon.scene_warnings(scene)

    data.dof.use_dof = True
    addon.sync(scene)
    assert any("depth of field is not rendered" in w for w in addon.scene_warnings(scene))
    data.dof.use_dof = False

    # Shutter models that need the lens's geometry: the camera renders black, the panel says why.
    scene.relativity.shutter_model = "DETECTOR_PLANE"
    assert not custom["settings_valid"]
    assert any("needs a perspective camera's lens" in w for w in addon.scene_warnings(scene))
    scene.relativity.shutter_model = "ARBITRARY_PLANE"
    assert custom["settings_valid"]

    assert addon.remove(scene)
    assert data.type == "PANO"
    assert {name: getattr(data, name) for name in settings} == settings
    assert len(data.cycles_custom.keys()) == 0

    # Applied with a lens-dependent shutter: refused, the camera untouched.
    scene.relativity.shutter_model = "FOCUS_SURFACE"
    with pytest.raises(addon.RelativityError, match="panorama"):
        addon.apply(scene)
    assert data.type == "PANO"
    scene.relativity.shutter_model = "PINHOLE"
    data.panorama_type = "EQUIANGULAR_CUBEMAP_FACE"
    with pytest.raises(addon.RelativityError, match="panorama type Equiangular Cubemap Face"):
        addon.apply(scene)
    assert data.type == "PANO"
