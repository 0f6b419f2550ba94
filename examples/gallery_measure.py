"""Numbers measured on the gallery's renders (``examples/gallery.py``), with what physics expects.

Expected values are docs/physics.md written out in numpy here (Doppler factor and aberration from
each pixel's viewing direction) and, for blackbodies, Planck spectra through the CIE 1931
observer from colour-science (skipped when colour-science is not installed). Images are linear
Rec.709 arrays [row (top first), column, channel]; a pixel (column i, row j) has its centre at
(i + 0.5, j + 0.5).
"""

import math

import numpy as np

SUN_TEMPERATURE = 5762.0


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def view_directions(context):
    """Unit camera-local viewing direction at every pixel centre, shape (h, w, 3)."""
    left, right, bottom, top = context["window"]
    width, height = context["size"]
    u = left + (np.arange(width) + 0.5) / width * (right - left)
    v = top - (np.arange(height) + 0.5) / height * (top - bottom)
    uu, vv = np.meshgrid(u, v)
    d = np.stack([uu, vv, -np.ones_like(uu)], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def doppler(context):
    """D = 1 / (gamma (1 - beta . d')) per pixel: the observer moves with beta, d' its camera-frame
    viewing direction (docs/physics.md)."""
    beta = np.asarray(context["beta_local"], float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    return 1.0 / (gamma * (1.0 - view_directions(context) @ beta))


def project(context, direction):
    left, right, bottom, top = context["window"]
    width, height = context["size"]
    x, y, z = direction
    return np.array([(x / -z - left) / (right - left) * width, (top - y / -z) / (top - bottom) * height])


def aberrate(k, beta):
    """Photon direction k (scene frame) -> k' in the frame moving with beta (docs/physics.md)."""
    k, beta = np.asarray(k, float), np.asarray(beta, float)
    b2 = beta @ beta
    if b2 == 0.0:
        return k
    g = 1.0 / math.sqrt(1.0 - b2)
    bhat = beta / math.sqrt(b2)
    return (k + (g - 1.0) * (bhat @ k) * bhat - g * beta) / (g * (1.0 - beta @ k))


def time_of_flight_view(view, beta):
    """Camera-frame viewing direction d of a scene-frame one under the Galilean transformation
    (Gray Fig. 1c, docs/camera.md): the unit d with d - beta along ``view``."""
    view, beta = np.asarray(view, float) / np.linalg.norm(view), np.asarray(beta, float)
    bv = beta @ view
    return beta + (math.sqrt(bv * bv + 1.0 - beta @ beta) - bv) * view


def sphere_image_centroid(context, centre, radius, samples=360):
    """Area centroid (pixels) of the cone of rays of a sphere seen from the origin, aberrated (or
    mapped by :func:`time_of_flight_view` when the context says ``time_of_flight``)."""
    centre = np.asarray(centre, float)
    axis = centre / np.linalg.norm(centre)
    half = math.asin(radius / np.linalg.norm(centre))
    e1 = np.cross(axis, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    points = []
    for phi in np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False):
        view = math.cos(half) * axis + math.sin(half) * (math.cos(phi) * e1 + math.sin(phi) * e2)
        if context.get("time_of_flight"):
            points.append(project(context, time_of_flight_view(view, context["beta_local"])))
        else:
            points.append(project(context, -aberrate(-view, context["beta_local"])))
    x, y = np.array(points).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)


def centroid(intensity, weights_mask=None):
    height, width = intensity.shape
    w = np.clip(intensity, 0.0, None) if weights_mask is None else np.clip(intensity, 0.0, None) * weights_mask
    ys, xs = np.mgrid[0:height, 0:width] + 0.5
    total = w.sum()
    return np.array([(xs * w).sum() / total, (ys * w).sum() / total]) if total > 0 else None


def spot(intensity, pixel, half):
    """Centroid and RMS radius (pixels) of the spot in a square window around ``pixel``."""
    height, width = intensity.shape
    c0, r0 = int(round(pixel[0])), int(round(pixel[1]))
    rows = slice(max(r0 - half, 0), min(r0 + half + 1, height))
    cols = slice(max(c0 - half, 0), min(c0 + half + 1, width))
    patch = np.clip(intensity[rows, cols], 0.0, None)
    ys, xs = np.mgrid[rows, cols] + 0.5
    total = patch.sum()
    if total <= 0.0:
        return None, float("nan")
    centre = np.array([(xs * patch).sum(), (ys * patch).sum()]) / total
    rms = math.sqrt((((xs - centre[0]) ** 2 + (ys - centre[1]) ** 2) * patch).sum() / total)
    return centre, rms


# --- families ---------------------------------------------------------------------------------


def _boxes(width, height):
    return {
        "centre": (slice(2 * height // 5, 3 * height // 5 + 1), slice(2 * width // 5, 3 * width // 5 + 1)),
        "left edge": (slice(2 * height // 5, 3 * height // 5 + 1), slice(0, max(width // 10, 1))),
    }


def street(images, contexts):
    out = {}
    geometry = images.get("weiskopf_fig5_street_geometry")
    if geometry is None:
        return out
    context = contexts["weiskopf_fig5_street_geometry"]
    d = doppler(context)
    y5 = luminance(geometry)
    for name, power in (("weiskopf_fig7_street_searchlight", 4), ("weiskopf_fig6_street_chang", 1)):
        if name not in images:
            continue
        y = luminance(images[name])
        values = {}
        for label, box in _boxes(*context["size"]).items():
            measured = y[box].sum() / y5[box].sum()
            expected = (d[box] ** power * y5[box]).sum() / y5[box].sum()
            values[f"{label} brightness / Fig. 5"] = measured
            values[f"{label} expected <D^{power}>"] = expected
            values[f"{label} mean D"] = d[box].mean()
        out[name] = values
    if "weiskopf_fig4_street_rest" in images:
        out["weiskopf_fig5_street_geometry"] = {
            "D at the image centre": d[d.shape[0] // 2, d.shape[1] // 2],
            "D at the image corner": d[0, 0],
        }
    return out


def _blackbody_y():
    try:
        import colour
    except ImportError:
        return None
    shape = colour.SpectralShape(360, 830, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    factors = np.linspace(0.3, 3.0, 136)
    ys = np.array(
        [
            colour.sd_to_XYZ(colour.sd_blackbody(f * SUN_TEMPERATURE, shape), cmfs, method="Integration")[1]
            for f in factors
        ]
    )
    y_rest = colour.sd_to_XYZ(colour.sd_blackbody(SUN_TEMPERATURE, shape), cmfs, method="Integration")[1]
    return lambda d: np.interp(d, factors, ys) / y_rest


def _cct(rgb):
    import colour

    xyz = colour.RGB_to_XYZ(
        rgb,
        colour.RGB_COLOURSPACES["ITU-R BT.709"],
        illuminant=None,
        chromatic_adaptation_transform=None,
        apply_cctf_decoding=False,
    )
    uv = colour.xy_to_UCS_uv(colour.XYZ_to_xy(xyz))
    return float(colour.temperature.uv_to_CCT(uv, method="Ohno 2013")[0])


def _sun_cores(y):
    """Per Sun (left to right): the mask of its image's inner pixels (all 3 x 3 neighbours lit)."""
    lit = y > 0.02 * y.max()
    inner = lit.copy()
    inner[1:-1, 1:-1] = np.all(
        [np.roll(np.roll(lit, i, 0), j, 1)[1:-1, 1:-1] for i in (-1, 0, 1) for j in (-1, 0, 1)], axis=0
    )
    inner[[0, -1], :] = False
    inner[:, [0, -1]] = False
    columns = inner.any(axis=0)
    runs, start = [], None
    for x, on in enumerate(list(columns) + [False]):
        if on and start is None:
            start = x
        elif not on and start is not None:
            mask = np.zeros_like(inner)
            mask[:, start:x] = inner[:, start:x]
            runs.append(mask)
            start = None
    return runs


def suns(images, contexts):
    out = {}
    rest = images.get("weiskopf_sun_rest")
    ratio = _blackbody_y()
    if rest is None or ratio is None:
        return out
    y_rest = luminance(rest)
    cores = _sun_cores(y_rest)
    if not cores:
        return out
    y0 = max(y_rest[mask].mean() for mask in cores)
    for name, spectrum_only in (("weiskopf_fig8_sun_doppler", True), ("weiskopf_fig9_sun_doppler_searchlight", False)):
        if name not in images:
            continue
        image, d = images[name], doppler(contexts[name])
        y = luminance(image)
        values = {}
        for index, mask in enumerate(_sun_cores(y)):
            dm = d[mask]
            expected = (ratio(dm) / dm**5).mean() if spectrum_only else ratio(dm).mean()
            measured = y[mask].mean() / y0
            formula = "Y(DT)/(D^5 Y(T))" if spectrum_only else "Y(DT)/Y(T)"
            values[f"Sun {index + 1} mean D"] = dm.mean()
            values[f"Sun {index + 1} brightness / rest"] = measured
            values[f"Sun {index + 1} expected {formula}"] = expected
            values[f"Sun {index + 1} colour temperature seen (K)"] = _cct(image[mask].mean(axis=0))
            values[f"Sun {index + 1} D T (K)"] = dm.mean() * SUN_TEMPERATURE
        out[name] = values
    return out


def sphere_arrays(images, contexts):
    out, radii = {}, {}
    for name in (
        "gray_fig3b_aperture_plane",
        "gray_fig4_aperture_plane_huge",
        "gray_fig5_detector_plane",
        "gray_fig6b_phase_hologram",
        "gray_fig7_focus_surface",
    ):
        if name not in images:
            continue
        context = contexts[name]
        y = luminance(images[name])
        half = max(2, round(10 * context["size"][0] / 320))
        pixels = [project(context, p) for p in context["points"]]
        spots = [spot(y, p, half) for p in pixels]
        offsets = [np.linalg.norm(c - p) for (c, _), p in zip(spots, pixels, strict=True) if c is not None]
        radius = np.array([r for _, r in spots])
        radii[name] = radius
        out[name] = {
            "spots found (of 81)": len(offsets),
            "RMS spot radius median (px)": np.nanmedian(radius),
            "RMS radius, centre sphere (px)": radius[40],
            "RMS radius, sphere at (1, 0, 10) near beta (px)": radius[44],
            "RMS radius, sphere at (-1, 0, 10) (px)": radius[36],
            "spot centroid to grid pixel, max (px)": max(offsets),
            "spot centroid to grid pixel, median (px)": np.median(offsets),
        }
    for name in ("gray_fig4_aperture_plane_huge", "gray_fig6b_phase_hologram"):
        if name in radii and "gray_fig5_detector_plane" in radii:
            ratio = np.nanmedian(radii[name] / radii["gray_fig5_detector_plane"])
            out[name]["RMS radius / Fig. 5's (same aperture 0.2), median"] = ratio
    return out


def tiles(images, contexts):
    out = {}
    for name in (
        "gray_fig1a_rest",
        "gray_fig1b_pinhole",
        "gray_fig1c_time_of_flight",
        "gray_fig1c_time_of_flight_enlarged",
        "gray_fig1_wide_aperture",
    ):
        if name not in images:
            continue
        context, image = contexts[name], images[name]
        red = np.clip(image[..., 0] - image[..., 1], 0.0, None)
        measured = centroid(red)
        if measured is None:  # Fig. 1(c)'s red sphere is a pixel at 320x240: none at a tiny size
            continue
        expected = sphere_image_centroid(context, *context["red"])
        y = luminance(image)
        sharp = np.abs(np.diff(y, axis=1)).mean() + np.abs(np.diff(y, axis=0)).mean()
        formula = "time-of-flight formula" if context.get("time_of_flight") else "pinhole aberration formula"
        out[name] = {
            "red sphere centroid x (px)": measured[0],
            "red sphere centroid y (px)": measured[1],
            f"{formula} x (px)": expected[0],
            f"{formula} y (px)": expected[1],
            "mean |luminance gradient| (per px)": sharp,
        }
    return out


def cylinders(images, contexts):
    rest, moving = images.get("gray_fig8a_rest"), images.get("gray_fig8b_fixed_point_surface")
    if rest is None or moving is None:
        return {}
    context = contexts["gray_fig8a_rest"]
    from gallery_scenes import FIXED_PLANE, MARKERS

    half = max(2, round(10 * context["size"][0] / 320))
    shifts = []
    for x, y in MARKERS:
        pixel = project(context, (x, y, -FIXED_PLANE))
        a, _ = spot(np.clip(rest[..., 0] - rest[..., 1], 0, None), pixel, half)
        b, _ = spot(np.clip(moving[..., 0] - moving[..., 1], 0, None), pixel, half)
        if a is not None and b is not None:
            shifts.append(np.linalg.norm(a - b))
    return {
        "gray_fig8b_fixed_point_surface": {
            "red discs found": len(shifts),
            "red discs in the focus plane, max shift from Fig. 8(a) (px)": max(shifts),
            "mean |Fig. 8(b) - Fig. 8(a)|, whole image": np.abs(moving - rest).mean(),
        }
    }


def window_residual_pixels(context, pixels):
    """Where Fig. 9(a) shows the backdrop points that Fig. 10's ``pixels`` (n, 2) see: the chief
    rays of the detector-plane shutter (ideal lens) through the Lorentz window, from the physics
    core (``shutter.lens_time``, ``shutter.lorentz_window_ray``), met with the backdrop plane."""
    from gallery_scenes import BACKDROP_DEPTH, GRAY_BETA, PORTRAIT_FOCUS, PORTRAIT_LENS_MM

    from relativity_addon.physics.shutter import fixed_point_plane, lens_time, lorentz_window_ray

    left, right, bottom, top = context["window"]
    width, height = context["size"]
    pixels = np.asarray(pixels, float)
    view = np.stack(
        [
            left + pixels[:, 0] / width * (right - left),
            top - pixels[:, 1] / height * (top - bottom),
            -np.ones(len(pixels)),
        ],
        axis=-1,
    )
    object_points = view * PORTRAIT_FOCUS
    image_distance = 1.0 / (1.0 / (PORTRAIT_LENS_MM * 1e-3) - 1.0 / PORTRAIT_FOCUS)
    lens = np.zeros_like(object_points)
    t_lens = lens_time(
        "DETECTOR_PLANE",
        lens,
        object_points,
        c=1.0,
        shutter_time=context["shutter_time"],
        detector_point=-object_points * (image_distance / PORTRAIT_FOCUS),
    )
    window_point, window_normal = fixed_point_plane(context["window_time"], GRAY_BETA, 1.0)
    _, origin, forward = lorentz_window_ray(lens, object_points, t_lens, GRAY_BETA, 1.0, window_point, window_normal)
    backdrop = origin - forward * ((origin[:, 2] + BACKDROP_DEPTH) / forward[:, 2])[:, None]
    u, v = backdrop[:, 0] / -backdrop[:, 2], backdrop[:, 1] / -backdrop[:, 2]
    return np.stack([(u - left) / (right - left) * width, (top - v) / (top - bottom) * height], axis=-1)


def bilinear(image, pixels):
    """``image`` sampled at pixel coordinates (n, 2) (pixel centres at i + 0.5), edges clamped."""
    height, width = image.shape
    x = np.clip(pixels[:, 0] - 0.5, 0.0, width - 1.0)
    y = np.clip(pixels[:, 1] - 0.5, 0.0, height - 1.0)
    x0, y0 = np.minimum(x.astype(int), width - 2), np.minimum(y.astype(int), height - 2)
    fx, fy = x - x0, y - y0
    top = image[y0, x0] * (1 - fx) + image[y0, x0 + 1] * fx
    bottom = image[y0 + 1, x0] * (1 - fx) + image[y0 + 1, x0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def pupil_parallax(anaglyph, context, eye_separation=0.4, convergence=5.0):
    """Left-minus-right image offset of the portrait's two pupils (dark discs on the white eyes) in a
    red-cyan anaglyph (red: the left eye's view, green: the right eye's), against the off-axis pair's
    parallax of a point at depth z, 2 delta with delta = (e / 2) f (1/z - 1/convergence). The eyes sit
    about the camera as its stereo pivot says (LEFT: the left eye at the camera, Blender's default)."""
    from gallery_scenes import PUPILS

    focal_px = context["size"][0] / (context["window"][1] - context["window"][0])
    half = max(2, round(7 * context["size"][0] / 320))
    offsets, expected = [], []
    for pupil in PUPILS:
        centre = project(context, pupil)
        delta = eye_separation / 2.0 * focal_px * (1.0 / -pupil[2] - 1.0 / convergence)
        # where each eye sees it, from the centre of the pair (CENTER pivot) shifted to the pivot's eye
        middle = centre + np.array([{"LEFT": -delta, "RIGHT": delta}.get(context["pivot"], 0.0), 0.0])
        left, _ = spot(np.clip(0.9 - anaglyph[..., 0], 0.0, None), middle + (delta, 0.0), half)
        right, _ = spot(np.clip(0.9 - anaglyph[..., 1], 0.0, None), middle - (delta, 0.0), half)
        if left is None or right is None:
            return {}
        offsets.append(left - right)
        expected.append(2.0 * delta)
    offsets = np.array(offsets)
    return {
        "pupils' parallax left - right, x (px), mean of two": offsets[:, 0].mean(),
        "off-axis parallax of the pupils' depth, x (px)": float(np.mean(expected)),
        "pupils' parallax left - right, y (px), mean of two": offsets[:, 1].mean(),
    }


def portrait(images, contexts):
    out = {}
    for rest_name, names, label in (
        (
            "gray_fig9a_rest",
            ("gray_fig9b_moving", "gray_fig9c_lorentz_window", "gray_fig10_window_detector_plane"),
            "Fig. 9(a)",
        ),
        ("gray_fig11a_stereo_rest", ("gray_fig11b_stereo_moving", "gray_fig11c_stereo_lorentz_window"), "Fig. 11(a)"),
    ):
        rest = images.get(rest_name)
        for name in names:
            if rest is not None and name in images:
                out[name] = {
                    f"mean |image - {label}|": np.abs(images[name] - rest).mean(),
                    f"mean of {label}": rest.mean(),
                }
    rest = images.get("gray_fig9a_rest")
    name = "gray_fig10_window_detector_plane"
    if name in out:
        # The backdrop in the strips beside the portrait (outer 15 % of the width): Fig. 10 against
        # Fig. 9(a) as it is, and against Fig. 9(a) moved by the physics core's window rays (each
        # pixel shows what Fig. 9(a) shows where its ray meets the backdrop)
        context = contexts[name]
        width, height = context["size"]
        y_rest, y_moved = luminance(rest), luminance(images[name])
        rows, columns = np.mgrid[0:height, 0:width]
        strip = (columns < 0.15 * width) | (columns >= 0.85 * width)
        pixels = np.stack([columns[strip], rows[strip]], axis=-1) + 0.5
        source = window_residual_pixels(context, pixels)
        shift = np.linalg.norm(source - pixels, axis=1)
        # only where Fig. 9(a) shows the point (not beyond its edge)
        inside = np.all((source >= 1.0) & (source <= np.array([width, height]) - 1.0), axis=1)
        moved_rest = bilinear(y_rest, source[inside])
        seen = y_moved[strip][inside]
        left = pixels[:, 0] < width / 2
        values = out[name]
        values["backdrop shift by the physics core, left strip, max (px)"] = shift[left].max()
        values["backdrop shift by the physics core, right strip, max (px)"] = shift[~left].max()
        values["strips: mean |Fig. 10 - Fig. 9(a)|"] = np.abs(seen - y_rest[strip][inside]).mean()
        values["strips: mean |Fig. 10 - Fig. 9(a) moved by the physics core|"] = np.abs(seen - moved_rest).mean()
    for name in ("gray_fig11a_stereo_rest", "gray_fig11c_stereo_lorentz_window"):
        if name in images:
            out.setdefault(name, {}).update(pupil_parallax(images[name], contexts[name]))
    moving = images.get("gray_fig11b_stereo_moving")
    if moving is not None:  # the anaglyph's red is the left eye's, green the right eye's
        left = centroid(moving[..., 0] - moving[..., 1])
        right = centroid(moving[..., 1] - moving[..., 0])
        context = contexts["gray_fig11b_stereo_moving"]
        focal_px = context["size"][0] / (context["window"][1] - context["window"][0])
        out.setdefault("gray_fig11b_stereo_moving", {}).update(
            {
                "left (red) minus right (cyan) patch centroid, x (px)": left[0] - right[0],
                "left minus right patch centroid, y (px)": left[1] - right[1],
                "off-axis parallax of a point at infinity, x (px)": -0.4 / 5.0 * focal_px,
            }
        )
    return out


def measure_all(images, contexts):
    numbers = {}
    for family in (street, suns, tiles, sphere_arrays, cylinders, portrait):
        numbers.update(family(images, contexts))
    return {name: {key: float(value) for key, value in values.items()} for name, values in numbers.items()}
