"""The sky lights objects moving with the camera as the moving camera receives it (issue 28 part 1,
docs/cockpit.md): aberrated, beamed by the searchlight (docs/physics.md, "Radiance": ``L' = D^4 L``
with ``D = 1 / (gamma (1 - beta . v'))`` for the camera-frame direction ``v'`` toward the sky).

Three white diffuse plates (albedo 0.8) move with a camera at 0.9c under a uniform sky of radiance
1 at rest in the scene. A Lambertian plate of normal ``n`` then has radiance

    0.8 / pi * integral over the hemisphere of n of D(v')^4 (n . v') dOmega',

computed here by numpy quadrature of that relation (at rest: 0.8). The plates face 10, 40 and 90
degrees from the direction of motion. Before this change the cockpit's rest render had no world:
the plates were black.
"""

import importlib
import math

import numpy as np
import pytest

import camera_helpers as ch
from blender_support import ADDON_MODULE

RESOLUTION = (128, 64)
SAMPLES = 64
ALBEDO = 0.8
SPEED = 0.9
MOTION_DEG = 40.0  # the camera moves at 40 degrees from its backward axis (+Z) toward +X
PLATE_YAWS_DEG = (-50.0, 0.0, 50.0)  # each plate's normal, turned from +Z toward +X
PLATE_X = (-0.75, 0.0, 0.75)


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _beta():
    angle = math.radians(MOTION_DEG)
    return SPEED * np.array([math.sin(angle), 0.0, math.cos(angle)])


def _normal(yaw_deg):
    yaw = math.radians(yaw_deg)
    return np.array([math.sin(yaw), 0.0, math.cos(yaw)])


def expected_radiance(normal, beta, albedo=ALBEDO, steps=(600, 1200)):
    """``albedo / pi * integral D^4 cos dOmega`` over the hemisphere of ``normal`` (midpoint rule)."""
    normal = np.asarray(normal, float)
    beta = np.asarray(beta, float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    dt, dp = (math.pi / 2.0) / steps[0], (2.0 * math.pi) / steps[1]
    theta = (np.arange(steps[0]) + 0.5) * dt
    phi = (np.arange(steps[1]) + 0.5) * dp
    t, p = np.meshgrid(theta, phi, indexing="ij")
    e1 = np.cross(normal, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    v = (
        np.cos(t)[..., None] * normal
        + (np.sin(t) * np.cos(p))[..., None] * e1
        + (np.sin(t) * np.sin(p))[..., None] * e2
    )
    doppler = 1.0 / (gamma * (1.0 - v @ beta))
    integral = np.sum(doppler**4 * np.cos(t) * np.sin(t)) * dt * dp
    return albedo / math.pi * integral


def test_quadrature_at_rest_and_against_the_closed_form():
    """The quadrature: 0.8 at rest; facing the motion, ``int D^4 cos`` in closed form (mu = cos of the
    angle to beta, D = 1 / (gamma (1 - b mu))): 2 pi int_0^1 mu / (gamma^4 (1 - b mu)^4) dmu."""
    assert expected_radiance([0, 0, 1], [0, 0, 0]) == pytest.approx(ALBEDO, rel=1e-5)
    b = SPEED
    g = 1.0 / math.sqrt(1.0 - b * b)
    mu = np.linspace(0.0, 1.0, 200001)
    f = mu / (g**4 * (1.0 - b * mu) ** 4)
    closed = 2.0 * math.pi * np.sum((f[1:] + f[:-1]) / 2.0 * np.diff(mu))  # trapezoids
    assert expected_radiance([0, 0, 1], [0, 0, b]) == pytest.approx(ALBEDO / math.pi * closed, rel=1e-4)


def _plate(bpy, scene, camera, index, material):
    mesh = bpy.data.meshes.new(f"Plate {index}")
    h = 0.3
    mesh.from_pydata([(-h, -h, 0.0), (h, -h, 0.0), (h, h, 0.0), (-h, h, 0.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(f"Plate {index}", mesh)
    scene.collection.objects.link(obj)
    obj.parent = camera
    obj.location = (PLATE_X[index], 0.0, -2.0)
    obj.rotation_euler = (0.0, math.radians(PLATE_YAWS_DEG[index]), 0.0)
    obj.relativity["moves_with_camera"] = True  # by its stored value: the test runs on the code before it too
    return obj


def _scene(bpy):
    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=SAMPLES)
    camera.data.lens = 25.0
    scene.cycles.seed = 0
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 1.0
    material = ch.diffuse_material(bpy, "White", (ALBEDO,) * 3)
    plates = [_plate(bpy, scene, camera, index, material) for index in range(3)]
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(_beta())
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = True
    bpy.context.view_layer.update()
    return scene, camera, plates


def _plate_masks(bpy, scene, tmp_path):
    """Pixels well inside each plate: opaque in a transparent-film render at rest, their neighbours
    too, split by image thirds (one plate in each)."""
    scene.render.film_transparent = True
    ch.render_exr(bpy, scene, tmp_path / "mask.exr")
    alpha = ch.read_image(bpy, tmp_path / "mask.exr")[..., 3]
    scene.render.film_transparent = False
    inside = alpha > 0.999
    inside[:, 1:-1] &= inside[:, :-2] & inside[:, 2:]
    inside[1:-1, :] &= inside[:-2, :] & inside[2:, :]
    width = inside.shape[1]
    masks = []
    for third in range(3):
        columns = slice(third * width // 3, (third + 1) * width // 3)
        mask = np.zeros_like(inside)
        mask[:, columns] = inside[:, columns]
        masks.append(mask)
    return masks


def test_sky_lights_the_cockpit_beamed(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, _camera, plates = _scene(bpy)
    masks = _plate_masks(bpy, scene, tmp_path)
    assert all(mask.sum() > 40 for mask in masks), [int(mask.sum()) for mask in masks]
    at_rest = ch.render_exr(bpy, scene, tmp_path / "rest.exr")  # Blender's own render, no add-on
    _effect().apply(scene)
    image = ch.render_exr(bpy, scene, tmp_path / "moving.exr")
    scene.cycles.seed = 1
    _effect().sync(scene)
    noise_image = ch.render_exr(bpy, scene, tmp_path / "moving_seed1.exr")
    assert np.all(np.isfinite(image))
    beta = _beta()
    measured, expected, noise = [], [], []
    for index, mask in enumerate(masks):
        measured.append(image[mask].mean())
        expected.append(expected_radiance(_normal(PLATE_YAWS_DEG[index]), beta))
        noise.append(abs(noise_image[mask].mean() - measured[-1]))
        angle = math.degrees(math.acos(_normal(PLATE_YAWS_DEG[index]) @ beta / SPEED))
        print(
            f"plate {index} ({angle:.0f} deg from the motion, {mask.sum()} px): {measured[-1]:.4f} against "
            f"0.8/pi int D^4 cos = {expected[-1]:.4f} (ratio {measured[-1] / expected[-1]:.4f}; "
            f"seed difference {noise[-1]:.4f}; at rest {at_rest[mask].mean():.4f})"
        )
    for index in range(3):
        assert at_rest[masks[index]].mean() == pytest.approx(ALBEDO, rel=0.03)
        assert measured[index] == pytest.approx(expected[index], rel=0.05), index
    assert measured[2] > 3.0 * measured[0]  # the plate facing the motion is the brightest

    # Remove: the sky and its groups go
    _effect().remove(scene)
    assert not [w for w in bpy.data.worlds if w.name.startswith("Relativity")]
    assert not [g for g in bpy.data.node_groups if g.name.startswith("Relativity Cockpit Sky")]
    assert len(plates) == 3


MIRROR_DEG = 60.0  # the mirror sends the camera's central ray 60 degrees from the motion (-Z) to +X


def _gradient_sky(bpy, scene):
    """A sky brighter toward +X: a linear gradient of the direction's x (Texture Coordinate's
    Generated, which the cockpit's sky must read in the scene-frame direction), tinted."""
    tree = scene.world.node_tree
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    gradient = tree.nodes.new("ShaderNodeTexGradient")
    tint = tree.nodes.new("ShaderNodeMix")
    tint.data_type = "RGBA"
    tint.blend_type = "MULTIPLY"
    tint.inputs["Factor"].default_value = 1.0
    tint.inputs[7].default_value = (1.0, 0.8, 0.5, 1.0)
    tree.links.new(coordinates.outputs["Generated"], gradient.inputs["Vector"])
    tree.links.new(gradient.outputs["Color"], tint.inputs[6])
    tree.links.new(tint.outputs[2], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 2.0


def test_mirror_in_the_cockpit_shows_the_sky_the_camera_sees(relativity_addon, factory_blender, tmp_path):
    """A mirror moving with the camera at 0.9c (Doppler colour and searchlight on) sends the central
    ray 60 degrees from the motion; what it shows there is the sky the moving camera photographs when
    it looks that way (the exact camera turned 60 degrees, same velocity): the same aberrated
    direction of a sky that varies (without aberration it would read the gradient at x = 0.87
    instead of 0.69), the same Doppler colour and searchlight."""
    bpy = factory_blender
    scene, camera = ch.new_scene(bpy, resolution=(32, 32), samples=16)
    camera.data.lens = 100.0
    _gradient_sky(bpy, scene)
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = (0.0, 0.0, -SPEED)
    scene.relativity.use_doppler = True
    scene.relativity.use_searchlight = True
    angle = math.radians(MIRROR_DEG)
    reflected = np.array([math.sin(angle), 0.0, -math.cos(angle)])
    camera.rotation_euler = (0.0, -angle, 0.0)  # looks along the reflected ray
    bpy.context.view_layer.update()
    assert np.allclose(-np.array(camera.matrix_world.col[2][:3]), reflected, atol=1e-6)
    _effect().apply(scene)
    turned = ch.render_exr(bpy, scene, tmp_path / "turned.exr")
    _effect().remove(scene)
    camera.rotation_euler = (0.0, 0.0, 0.0)
    normal = reflected - np.array([0.0, 0.0, -1.0])
    normal /= np.linalg.norm(normal)
    mirror_material = bpy.data.materials.new("Mirror")
    tree = ch.compat.material_node_tree(mirror_material)
    tree.nodes.clear()
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    glossy.inputs["Roughness"].default_value = 0.0
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(glossy.outputs[0], output.inputs["Surface"])
    mesh = bpy.data.meshes.new("Mirror")
    mesh.from_pydata([(-0.4, -0.4, 0.0), (0.4, -0.4, 0.0), (0.4, 0.4, 0.0), (-0.4, 0.4, 0.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(mirror_material)
    mirror = bpy.data.objects.new("Mirror", mesh)
    scene.collection.objects.link(mirror)
    mirror.parent = camera
    mirror.location = (0.0, 0.0, -1.0)
    mirror.rotation_euler = (0.0, math.atan2(normal[0], normal[2]), 0.0)
    mirror.relativity["moves_with_camera"] = True
    bpy.context.view_layer.update()
    _effect().apply(scene)
    reflection = ch.render_exr(bpy, scene, tmp_path / "mirror.exr")
    centre = (slice(12, 20), slice(12, 20))
    seen, shown = turned[centre].reshape(-1, 3).mean(axis=0), reflection[centre].reshape(-1, 3).mean(axis=0)
    print(
        f"sky seen looking {MIRROR_DEG:g} deg from the motion {np.round(seen, 4)}; in the mirror {np.round(shown, 4)}"
    )
    assert seen.max() > 0.05
    assert np.allclose(shown, seen, rtol=0.03)
