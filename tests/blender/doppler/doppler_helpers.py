"""Helpers for the Doppler colour tests: emitter scenes, in-process Cycles renders, references.

Expected values come from docs/physics.md written out in numpy (Doppler factor from the pixel's
viewing direction) and from colour-science directly (Planck spectra through the CIE 1931
observer), not from the add-on's node groups.
"""

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


def add_emitter_plane(bpy, scene, name, x_range, y_range, colour=(0.5, 0.5, 0.5), beta=(0.0, 0.0, 0.0),
                      temperature=None, depth=PLANE_DEPTH):
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


def blackbody_xyz_colour_science(temperature):
    """CIE 1931 XYZ of a Planck spectrum, straight from colour-science (independent reference)."""
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    sd = colour.sd_blackbody(temperature, shape)
    return colour.sd_to_XYZ(sd, cmfs, method="Integration")


def linear_rec709_to_xyz(rgb):
    import colour

    return colour.RGB_to_XYZ(
        np.asarray(rgb, float), colour.RGB_COLOURSPACES["ITU-R BT.709"], illuminant=None,
        chromatic_adaptation_transform=None, apply_cctf_decoding=False,
    )


def delta_e_2000_normalised(xyz_a, xyz_b):
    """CIEDE2000 between two colours after scaling both to Y = 1 (exposure normalised), D65 white."""
    import colour

    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    lab_a = colour.XYZ_to_Lab(np.asarray(xyz_a) / xyz_a[1], white)
    lab_b = colour.XYZ_to_Lab(np.asarray(xyz_b) / xyz_b[1], white)
    return float(colour.delta_E(lab_a, lab_b, method="CIE 2000"))
