"""The world seen by a moving exact camera: its colour Doppler-shifted at every pixel.

Nothing but a world of constant colour: every pixel's expected colour is the world's colour through
the Doppler matrix at that pixel's ``D = 1 / (gamma (1 - beta . d'))``, ``d'`` its camera-frame
viewing direction (docs/physics.md), for the perspective camera and the equirectangular panorama
(Blender's projection: longitude -pi to pi left to right, latitude -pi/2 to pi/2 bottom to top),
up to D about 4; in a spectral render, the XYZ of ``D^5 S(lambda D)`` of the colour's spectrum
(docs/spectral-model.md). The world's Doppler colour group feeds its Background only where it
changes the colour (spectral passes, blackbodies: ``world_colour``), and removing the effect gives
the world back exactly.
"""

import math

import numpy as np
import pytest

import colour_helpers as dh

COLOUR = (0.3, 0.6, 0.2)
RESOLUTION = (48, 32)


def _world_scene(bpy, colour=COLOUR, resolution=RESOLUTION):
    """No objects; the camera at the origin looks down -Z (world axes = camera axes)."""
    scene, camera = dh.emitter_scene(bpy, samples=4, resolution=resolution)
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*colour, 1.0)
    background.inputs["Strength"].default_value = 1.0
    return scene, camera, background


def _set_up(bpy, scene, beta):
    scene.relativity.beta = beta
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}


def _equirectangular_directions(width, height):
    """Camera-local viewing directions (+X right, +Y up, -Z forward) of the pixel centres, top row first."""
    longitude = -math.pi + (np.arange(width) + 0.5) / width * 2.0 * math.pi
    latitude = math.pi / 2 - (np.arange(height) + 0.5) / height * math.pi
    lon, lat = np.meshgrid(longitude, latitude)
    return np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], axis=-1)


def _equidistant_directions(width, height, fov):
    """The same for the fisheye equidistant lens (angle from the axis = radius * fov / 2, the image
    circle filling the frame), and each pixel centre's radius (1 on the circle)."""
    u = 2.0 * (np.arange(width) + 0.5) / width - 1.0
    v = 1.0 - 2.0 * (np.arange(height) + 0.5) / height
    x, y = np.meshgrid(u, v)
    r = np.hypot(x, y)
    theta = r * fov / 2.0
    s = np.sin(theta) / r
    return np.stack([x * s, y * s, -np.cos(theta)], axis=-1), r


def _doppler(view, beta):
    beta = np.asarray(beta, float)
    return math.sqrt(1.0 - beta @ beta) / (1.0 - view @ beta)  # 1 / (gamma (1 - beta . d))


def _assert_shifted(image, d, colour=COLOUR, tolerance=0.01):
    from relativity_addon.physics import spectral

    expected = spectral.doppler_shift_rgb(colour, d)
    error = np.abs(image - expected) / expected.sum(-1, keepdims=True)
    print(f"D {d.min():.3f}-{d.max():.3f}: max relative error {error.max():.4f}, mean {error.mean():.5f}")
    assert np.all(np.isfinite(image))
    assert error.mean() < 0.005
    assert error.max() < tolerance


def _signature(tree):
    links = sorted(
        (link.from_node.name, link.from_socket.identifier, link.to_node.name, link.to_socket.identifier)
        for link in tree.links
    )
    return sorted(node.name for node in tree.nodes), links


@pytest.mark.parametrize("beta", [(0.3, 0.0, -0.5), (0.2, -0.1, -0.9)], ids=["oblique", "fast_forward"])
def test_world_is_shifted_at_every_pixel(relativity_addon, tmp_path, beta):
    bpy = __import__("bpy")
    scene, camera, _background = _world_scene(bpy)
    _set_up(bpy, scene, beta)
    _assert_world_writes_no_aov(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "world.exr")
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    d = _doppler(view, beta)
    assert d.max() > (3.0 if beta[2] < -0.8 else 1.5)
    # the pixel's samples spread D by up to 2% at D = 5 (the corners): its mean of D^4 is not D^4
    # at the centre, which the compositor divides by
    _assert_shifted(image, d, tolerance=0.02)


def _assert_world_writes_no_aov(addon, scene):
    """The world's ln D comes from the compositor's direction image, not from an AOV writer."""
    world_doppler = dh.addon_module(addon, "colour.world_doppler")
    assert scene.world.node_tree.nodes[world_doppler.AOV_NODE].mute
    stage = next(
        node
        for node in dh.addon_module(addon, "common.compat").compositor_tree(scene).nodes
        if node.bl_idname == "CompositorNodeGroup"
    )
    assert stage.inputs["World Directions"].default_value == 1.0


@pytest.mark.parametrize("panorama", ["EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT"])
def test_panorama_world_is_shifted_at_every_pixel(relativity_addon, tmp_path, panorama):
    bpy = __import__("bpy")
    width, height = (128, 64) if panorama == "EQUIRECTANGULAR" else (64, 64)
    scene, camera, _background = _world_scene(bpy, resolution=(width, height))
    camera.data.type = "PANO"
    camera.data.panorama_type = panorama
    camera.data.fisheye_fov = math.radians(240.0)
    beta = (0.2, 0.3, -0.6)
    _set_up(bpy, scene, beta)
    _assert_world_writes_no_aov(relativity_addon, scene)
    image = dh.render(bpy, scene, tmp_path / "panorama.exr")
    if panorama == "EQUIRECTANGULAR":
        d = _doppler(_equirectangular_directions(width, height), beta)
        # A pixel holds 2.8 degrees of directions, over which D varies by up to 10% here: the
        # pixel's mean of D^4 (the rendered brightness) is not exp(4 <ln D>) (the compositor's division)
        _assert_shifted(image[2:-2], d[2:-2], tolerance=0.08)
    else:
        view, radius = _equidistant_directions(width, height, math.radians(240.0))
        d = _doppler(view, beta)
        inner, outer = radius < 1.0 - 3.0 / width, radius > 1.0 + 3.0 / width  # away from the circle's edge
        assert np.abs(image[outer]).max() < 1e-6  # outside the image circle: black
        _assert_shifted(image[inner], d[inner], tolerance=0.08)


def test_world_colour_group_feeds_the_background_only_where_needed(relativity_addon):
    """Fast mode: the Background keeps its own colour (the compositor shifts the pixel); a spectral
    pass and a blackbody background need the group; removal restores the tree exactly."""
    bpy = __import__("bpy")
    effect = dh.addon_module(relativity_addon, "pipeline.effect")
    materials = dh.addon_module(relativity_addon, "colour.materials")
    world_colour = dh.addon_module(relativity_addon, "colour.world_colour")
    scene, _camera, background = _world_scene(bpy)
    tree = scene.world.node_tree
    rgb = tree.nodes.new("ShaderNodeRGB")  # a linked colour and ...
    second = tree.nodes.new("ShaderNodeBackground")  # ... an unlinked one (not in the output)
    second.inputs["Color"].default_value = (0.1, 0.2, 0.7, 1.0)
    tree.links.new(rgb.outputs[0], background.inputs["Color"])
    before = _signature(tree)
    _set_up(bpy, scene, (0.0, 0.0, -0.5))
    assert len(tree.nodes) > len(before[0])  # the groups are in the tree ...
    assert world_colour.linked_groups(scene.world) == []  # ... and feed nothing
    assert background.inputs["Color"].links[0].from_node == rgb
    assert not second.inputs["Color"].is_linked

    second.inputs["Color"].default_value = (0.4, 0.1, 0.1, 1.0)  # edited while the group is out
    materials.set_spectral_pass((450.0, 550.0, 650.0))
    try:
        effect.sync(scene)
        assert len(world_colour.linked_groups(scene.world)) == 2
        for socket in (background.inputs["Color"], second.inputs["Color"]):
            assert socket.links[0].from_node.node_tree.name == materials.DOPPLER_EMISSION
        group = second.inputs["Color"].links[0].from_node
        assert tuple(group.inputs["Color"].default_value) == pytest.approx((0.4, 0.1, 0.1, 1.0))
    finally:
        materials.set_spectral_pass(None)
    effect.sync(scene)
    assert world_colour.linked_groups(scene.world) == []
    assert background.inputs["Color"].links[0].from_node == rgb

    assert "Relativity World Doppler" in bpy.data.images  # the compositor's world ln D
    effect.remove(scene)
    assert _signature(tree) == before
    assert "Relativity World Doppler" not in bpy.data.images
    assert tuple(second.inputs["Color"].default_value) == pytest.approx((0.4, 0.1, 0.1, 1.0))

    blackbody = tree.nodes.new("ShaderNodeBlackbody")  # a blackbody background keeps its group
    tree.links.new(blackbody.outputs[0], background.inputs["Color"])
    _set_up(bpy, scene, (0.0, 0.0, -0.5))
    linked = world_colour.linked_groups(scene.world)
    assert len(linked) == 1 and background.inputs["Color"].links[0].from_node == linked[0]
    effect.remove(scene)
    assert background.inputs["Color"].links[0].from_node == blackbody


def test_spectral_render_of_a_coloured_world(relativity_addon):
    """Spectral passes see the world through its colour group: ``D^5 S(lambda D)`` per pixel."""
    bpy = __import__("bpy")
    scene, camera, _background = _world_scene(bpy, resolution=(32, 24))
    beta = (0.3, 0.0, -0.6)
    _set_up(bpy, scene, beta)
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 3)
    image = pixels[::-1, :, :3].astype(float)  # top row first
    d = _doppler(-dh.pixel_photon_directions(bpy, scene, camera), beta)
    spectrum = dh.emitted_spectrum(COLOUR)
    for rows, cols in ((slice(2, 6), slice(2, 6)), (slice(10, 14), slice(14, 18)), (slice(18, 22), slice(26, 30))):
        expected = np.mean([dh.observed_xyz(spectrum, value) for value in d[rows, cols].ravel()], axis=0)
        measured = dh.linear_rec709_to_xyz(image[rows, cols].reshape(-1, 3).mean(0))
        delta_e = dh.delta_e_2000_normalised(measured, expected)
        print(f"D {d[rows, cols].mean():.3f}: Delta E {delta_e:.2f}, Y/expected {measured[1] / expected[1]:.3f}")
        assert delta_e < 2.0
        assert measured[1] / expected[1] == pytest.approx(1.0, abs=0.05)
    assert d.max() / d.min() > 1.3


@pytest.mark.parametrize("panorama", ["EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT"])
def test_spectral_render_of_a_world_through_a_panorama(relativity_addon, panorama):
    """A panoramic camera's spectral passes weigh each pixel with its own direction's ``D`` (the
    panorama's, not a perspective view window's): ``D^5 S(lambda D)`` per pixel, equirectangular and
    fisheye (outside the fisheye's image circle: black)."""
    bpy = __import__("bpy")
    width, height = (64, 32) if panorama == "EQUIRECTANGULAR" else (32, 32)
    scene, camera, _background = _world_scene(bpy, resolution=(width, height))
    camera.data.type = "PANO"
    camera.data.panorama_type = panorama
    camera.data.fisheye_fov = math.radians(240.0)
    beta = (0.3, 0.0, -0.6)
    _set_up(bpy, scene, beta)
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 3)
    image = pixels[::-1, :, :3].astype(float)  # top row first
    spectrum = dh.emitted_spectrum(COLOUR)
    if panorama == "EQUIRECTANGULAR":
        d = _doppler(_equirectangular_directions(width, height), beta)
        # ahead (the view axis is the image centre), to the side, behind (the left edge), up and down
        patches = [(slice(14, 18), slice(30, 34)), (slice(14, 18), slice(46, 50)), (slice(14, 18), slice(1, 4))]
        patches += [(slice(5, 8), slice(20, 24)), (slice(24, 27), slice(40, 44))]
    else:
        view, radius = _equidistant_directions(width, height, math.radians(240.0))
        d = _doppler(view, beta)
        assert np.abs(image[radius > 1.0 + 3.0 / width]).max() < 1e-6  # outside the image circle
        # the centre (ahead), halfway out right and left, and near the rim (behind the side) above and below
        patches = [(slice(14, 18), slice(14, 18)), (slice(14, 18), slice(22, 25)), (slice(14, 18), slice(7, 10))]
        patches += [(slice(3, 5), slice(14, 18)), (slice(27, 29), slice(14, 18))]
    for rows, cols in patches:
        expected = np.mean([dh.observed_xyz(spectrum, value) for value in d[rows, cols].ravel()], axis=0)
        measured = dh.linear_rec709_to_xyz(image[rows, cols].reshape(-1, 3).mean(0))
        delta_e = dh.delta_e_2000_normalised(measured, expected)
        print(f"D {d[rows, cols].mean():.3f}: Delta E {delta_e:.2f}, Y/expected {measured[1] / expected[1]:.3f}")
        assert delta_e < 2.0
        assert measured[1] / expected[1] == pytest.approx(1.0, abs=0.08)
    assert d.max() / d.min() > 3.0


def test_stereo_pair_keeps_the_world_aov_writer(relativity_addon):
    """Each eye of Blender's stereo pair looks along its own shifted directions: the world writes its
    ln D AOV there, and the compositor divides the AOV by the coverage."""
    bpy = __import__("bpy")
    scene, _camera, _background = _world_scene(bpy)
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    _set_up(bpy, scene, (0.0, 0.0, -0.5))
    world_doppler = dh.addon_module(relativity_addon, "colour.world_doppler")
    assert not scene.world.node_tree.nodes[world_doppler.AOV_NODE].mute
    scene.render.use_multiview = False
    dh.addon_module(relativity_addon, "pipeline.effect").sync(scene)
    _assert_world_writes_no_aov(relativity_addon, scene)


def test_animation_render_shifts_the_world_for_each_frame(relativity_addon, tmp_path):
    """Blender's own animation render of a camera that speeds up from 0.3 c to 0.8 c: each frame's
    world pixels are shifted by that frame's D (the direction image is written per frame, before
    the frame's render; the compositor must not see the previous frame's)."""
    bpy = __import__("bpy")
    compat = dh.addon_module(relativity_addon, "common.compat")
    scene, camera, _background = _world_scene(bpy)
    scene.relativity.speed_of_light = 10.0
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    speeds = {1: 0.3, 2: 0.8}  # frame -> speed along the view (-Z), keys half a frame either side
    step = {frame: speed * 10.0 / scene.render.fps for frame, speed in speeds.items()}
    for frame, z in ((0.5, 0.0), (1.5, -step[1]), (2.5, -step[1] - step[2])):
        camera.location = (0.0, 0.0, z)
        camera.keyframe_insert("location", frame=frame)
    for fcurve in compat.action_fcurves(camera.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    scene.frame_start, scene.frame_end = 1, 2
    scene.frame_set(1)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    scene.render.filepath = str(tmp_path / "f_####")
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.ops.render.render(animation=True)
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    for frame, speed in speeds.items():
        image = dh.ch.read_exr(bpy, tmp_path / f"f_{frame:04d}.exr")
        _assert_shifted(image, _doppler(view, (0.0, 0.0, -speed)), tolerance=0.02)


def test_saved_file_renders_the_world_without_the_addon(relativity_addon, tmp_path):
    """The world's ln D image is packed into the file: opened and rendered where the add-on is not
    installed, the shifted world is the same."""
    bpy = __import__("bpy")
    scene, _camera, _background = _world_scene(bpy)
    _set_up(bpy, scene, (0.3, 0.0, -0.6))
    reference = dh.render(bpy, scene, tmp_path / "with_addon.exr")
    blend = dh.ch.save_blend(bpy, tmp_path / "world.blend")
    plain = dh.render_without_addon(bpy, blend, tmp_path / "plain.exr")
    print(f"max |plain - with add-on| / max = {np.abs(plain - reference).max() / reference.max():.2e}")
    assert np.abs(plain - reference).max() < 1e-5 * reference.max()
    assert np.abs(reference[5, 5] - COLOUR).max() > 0.05  # shifted
