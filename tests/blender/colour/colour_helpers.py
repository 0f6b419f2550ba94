"""Helpers for the Doppler colour tests: emitter scenes, in-process Cycles renders, references.

Expected values come from docs/physics.md written out in numpy (Doppler factor from the pixel's
viewing direction) and from colour-science directly (Planck spectra through the CIE 1931
observer), not from the add-on's node groups.
"""

import functools
import importlib
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))

import camera_helpers as ch  # noqa: E402

RESOLUTION = (64, 48)
PLANE_DEPTH = 5.0


def addon_module(addon_name, name):
    return importlib.import_module(f"{addon_name}.blender.{name}")


def emitter_scene(bpy, samples=16, resolution=RESOLUTION):
    scene, camera = ch.new_scene(bpy, resolution=resolution, samples=samples)
    scene.cycles.pixel_filter_type = "BOX"  # keep each pixel's samples inside its own footprint
    scene.cycles.filter_width = 1.0
    return scene, camera


def add_emitter_plane(
    bpy,
    scene,
    name,
    x_range,
    y_range,
    colour=(0.5, 0.5, 0.5),
    beta=(0.0, 0.0, 0.0),
    temperature=None,
    depth=PLANE_DEPTH,
):
    """A flat emitter facing the camera (which looks down -Z from the origin).

    ``beta`` becomes the point attribute ``relativity_beta`` (velocity relative to the observer,
    fraction of c); ``temperature`` feeds the emission colour from a Blackbody node.
    """
    material = ch.emission_material(bpy, name)
    emission = material.node_tree.nodes["Emission"]
    emission.inputs["Color"].default_value = (*colour, 1.0)
    if temperature is not None:
        blackbody = material.node_tree.nodes.new("ShaderNodeBlackbody")
        blackbody.inputs["Temperature"].default_value = temperature
        material.node_tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    (x0, x1), (y0, y1) = x_range, y_range
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(x0, y0, -depth), (x1, y0, -depth), (x1, y1, -depth), (x0, y1, -depth)], [], [(0, 1, 2, 3)])
    if beta is not None:
        attribute = mesh.attributes.new("relativity_beta", "FLOAT_VECTOR", "POINT")
        for item in attribute.data:
            item.vector = beta
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def emission_in_group(bpy, material, kind, temperature):
    """Replace the material's Emission by one inside a node group (shared by every material given
    the same ``kind``), its colour a Blackbody at ``temperature``: inside the group, through a
    reroute (``inner group``), or outside, through the group's Color input (``passed group``)."""
    tree = material.node_tree
    for node in [n for n in tree.nodes if n.bl_idname in ("ShaderNodeEmission", "ShaderNodeBlackbody")]:
        tree.nodes.remove(node)
    group = bpy.data.node_groups.get(kind)
    if group is None:
        group = bpy.data.node_groups.new(kind, "ShaderNodeTree")
        group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
        emission = group.nodes.new("ShaderNodeEmission")
        group.links.new(emission.outputs[0], group.nodes.new("NodeGroupOutput").inputs["Shader"])
        reroute = group.nodes.new("NodeReroute")
        group.links.new(reroute.outputs[0], emission.inputs["Color"])
        if kind == "inner group":
            inner = group.nodes.new("ShaderNodeBlackbody")
            inner.inputs["Temperature"].default_value = temperature
            group.links.new(inner.outputs[0], reroute.inputs[0])
        else:
            group.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
            group.links.new(group.nodes.new("NodeGroupInput").outputs["Color"], reroute.inputs[0])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    output = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    tree.links.new(node.outputs["Shader"], output.inputs["Surface"])
    if kind == "passed group":
        outside = tree.nodes.new("ShaderNodeBlackbody")
        outside.inputs["Temperature"].default_value = temperature
        tree.links.new(outside.outputs[0], node.inputs["Color"])
    return node


def render_without_addon(bpy, blend, out):
    """Open ``blend`` in a fresh process where neither the add-on nor colour-science is installed,
    render it to ``out`` (EXR) and return the pixels: what a render-farm worker sees."""
    import subprocess

    worker = (
        "import os, sys\n"
        "sys.modules['colour'] = None  # colour-science must not be needed to render\n"
        "import bpy\n"
        f"bpy.ops.wm.open_mainfile(filepath={str(blend)!r})\n"
        "scene = bpy.context.scene\n"
        "assert not hasattr(scene, 'relativity'), 'add-on unexpectedly enabled'\n"
        f"scene.render.filepath = {str(out)!r}\n"
        "bpy.ops.render.render(write_still=True)\n"
        "sys.stdout.flush()\nsys.stderr.flush()\nos._exit(0)\n"  # bpy 4.5 can hang in exit()
    )
    result = subprocess.run([sys.executable, "-c", worker], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    return ch.read_exr(bpy, out)


def render(bpy, scene, path):
    return ch.render_exr(bpy, scene, path)


def pixel_photon_directions(bpy, scene, camera, offset=(0.5, 0.5)):
    """Photon propagation direction (toward the camera, world axes) at every pixel's centre, or
    at ``offset`` (pixels) from its top-left corner."""
    model = ch.pinhole_model(bpy, scene, camera)
    width, height = model.size
    px, py = np.meshgrid(np.arange(width) + offset[0], np.arange(height) + offset[1])
    view = model.pixel_direction(px, py) @ model.rotation.T
    return -view


def source_doppler_factor(k, beta_s):
    """D = 1 / (gamma_s (1 - beta_s . k)): source moving with beta_s in the observer frame."""
    beta_s = np.asarray(beta_s, float)
    gamma = 1.0 / math.sqrt(1.0 - beta_s @ beta_s)
    return 1.0 / (gamma * (1.0 - k @ beta_s))


def beta_for_doppler(d, direction=(0.0, 0.0, 1.0)):
    """Velocity along ``direction`` (toward the camera for +Z) giving D on that axis."""
    speed = (d * d - 1.0) / (d * d + 1.0)
    return tuple(speed * np.asarray(direction, float))


@functools.cache
def _cie_1931_observer_1nm():
    """colour-science's CIE 1931 2 degree observer on 360-830 nm in 1 nm steps (aligned once: the
    alignment cost 20 ms a call, two thousand calls in one test)."""
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    return shape, colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)


def blackbody_xyz_colour_science(temperature):
    """CIE 1931 XYZ of the Planck spectrum at ``temperature`` (K; a number or an array of them:
    XYZ in a last axis), straight from colour-science (independent reference): its Planck law per
    nm, as ``colour.sd_blackbody`` tabulates it, integrated against the observer by
    ``colour.msds_to_XYZ`` as ``colour.sd_to_XYZ`` does one spectrum, all temperatures at once."""
    import colour

    shape, cmfs = _cie_1931_observer_1nm()
    temperatures = np.asarray(temperature, float)
    spectra = colour.colorimetry.planck_law(shape.wavelengths * 1e-9, temperatures.ravel()) * 1e-9  # (nm, K)
    xyz = colour.msds_to_XYZ(spectra.T, cmfs, method="Integration", shape=shape)
    return np.asarray(xyz).reshape(*temperatures.shape, 3)


def linear_rec709_to_xyz(rgb):
    import colour

    return colour.RGB_to_XYZ(
        np.asarray(rgb, float),
        colour.RGB_COLOURSPACES["ITU-R BT.709"],
        illuminant=None,
        chromatic_adaptation_transform=None,
        apply_cctf_decoding=False,
    )


def delta_e_2000_normalised(xyz_a, xyz_b):
    """CIEDE2000 between two colours after scaling both to Y = 1 (exposure normalised), D65 white."""
    import colour

    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    lab_a = colour.XYZ_to_Lab(np.asarray(xyz_a) / xyz_a[1], white)
    lab_b = colour.XYZ_to_Lab(np.asarray(xyz_b) / xyz_b[1], white)
    return float(colour.delta_E(lab_a, lab_b, method="CIE 2000"))


# --- volumes and spectra (shared by the volume and lit-scene tests) -------------------------------


def volume_material(bpy, name, kind="ShaderNodeVolumePrincipled", **inputs):
    """A material whose Volume output is one ``kind`` node with these input values (colours as RGB)."""
    from relativity_addon.blender.common import compat

    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    volume = tree.nodes.new(kind)
    for socket, value in inputs.items():
        socket = socket.replace("_", " ")
        volume.inputs[socket].default_value = (*value, 1.0) if isinstance(value, tuple) else value
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(volume.outputs[0], output.inputs["Volume"])
    return material


def add_box(bpy, scene, name, x_range, y_range, z_range, material):
    """An axis-aligned closed box (outward faces) with ``material``."""
    mesh = bpy.data.meshes.new(name)
    corners = [(x, y, z) for x in x_range for y in y_range for z in z_range]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(corners, [], faces)
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def scene_frame_directions(bpy, scene, camera, beta):
    """Per pixel, the photon's propagation direction in the scene frame: the pixel's direction in
    the moving camera's frame aberrated back (docs/physics.md)."""
    seen = pixel_photon_directions(bpy, scene, camera)
    beta = -np.asarray(beta, float)
    return np.array([ch.aberrate(k, beta) for k in seen.reshape(-1, 3)]).reshape(seen.shape)


def pixel_doppler(bpy, scene, camera, beta):
    """``D = 1 / (gamma (1 - beta.d))`` at every pixel centre, ``d`` its viewing direction."""
    view = -pixel_photon_directions(bpy, scene, camera)
    beta = np.asarray(beta, float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    return 1.0 / (gamma * (1.0 - view @ beta))


def cmfs_1nm():
    """CIE 1931 2 degree functions on 360-830 nm at 1 nm: (wavelengths, (W, 3) values)."""
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    return cmfs.wavelengths, cmfs.values


def planck(wavelength_nm, temperature):
    from colour.colorimetry import planck_law

    with np.errstate(over="ignore"):
        return planck_law(np.asarray(wavelength_nm) * 1e-9, temperature)


def mallett_reflectance(rgb, wavelength_nm):
    """Mallett & Yuksel's sRGB basis with weights ``rgb``, held at the 420-655 nm band's edge values
    outside it (the add-on's documented extension, docs/spectral-model.md)."""
    import colour

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    clipped = np.clip(wavelength_nm, 420.0, 655.0)
    values = np.stack([np.interp(clipped, basis.wavelengths, basis.values[:, i]) for i in range(3)], -1)
    return values @ np.asarray(rgb, float)


def emitted_spectrum(rgb):
    """``S(mu)`` of an emitted linear Rec.709 colour as docs/spectral-model.md defines it: the basis
    in 6504 K white light, weighted so that its CIE integral (1 nm sum) at rest is ``rgb``'s XYZ."""
    wavelengths, cmfs = cmfs_1nm()
    white = planck(wavelengths, 6504.0)
    columns = np.stack([cmfs.T @ (white * mallett_reflectance(np.eye(3)[i], wavelengths)) for i in range(3)], -1)
    weights = np.linalg.solve(columns, linear_rec709_to_xyz(rgb))

    def spectrum(mu):
        return planck(mu, 6504.0) * mallett_reflectance(weights, mu)

    return spectrum


def observed_xyz(spectrum, doppler):
    """XYZ of ``D^5 L(lambda D)`` for a scene-frame spectral radiance ``spectrum(mu)`` (per nm)."""
    wavelengths, cmfs = cmfs_1nm()
    return doppler**5 * spectrum(wavelengths * doppler) @ cmfs
