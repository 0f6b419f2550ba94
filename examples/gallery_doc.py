"""docs/gallery.md from the gallery's measurements (written by ``examples/gallery.py``).

Each figure: the image, the paper's caption in our words, the settings, the numbers measured on
the render and what physics expects (the same numbers the script prints).
"""

W99 = "Weiskopf, Kraus, Ruder (1999)"
G20 = "Gray et al. (2020)"
STREET = (
    "Camera method, observer at 0.8c straight down the street (beta along the view), 16 mm lens "
    "(104 degrees), Doppler colour off (the paper's grey-scale street: total radiance, eq. 15)"
)
SUN = (
    "Camera method, observer at 0.5c along the camera's +X (the Suns pass by to the left), 20 mm lens; "
    "five 5762 K blackbody spheres placed so that the moving observer sees them at -36, -18, 0, 18 and "
    "36 degrees"
)
GRAY = (
    "c = 1, beta = (0.1, 0, 0.99) in Dr TIM's axes = (0.1, 0, -0.99) in the camera's, "
    "Doppler colour and searchlight off (Gray's renders show geometry only)"
)
ARRAY = (
    "9 x 9 white spheres (radius 0.05) centred on the scene-frame surface that the moving camera "
    "focuses on the camera-frame plane at distance 10; 100 mm lens (20 degrees)"
)

FIGURES = [
    (
        "weiskopf_fig4_street_rest",
        f"{W99} Fig. 4",
        "The street as it is, seen at rest.",
        "Camera at rest, 16 mm lens; boxes, a row of glowing street lamps and the sun, all at rest.",
    ),
    (
        "weiskopf_fig5_street_geometry",
        f"{W99} Fig. 5",
        "Rushing into the street at 0.8c, geometry only: aberration pulls the whole street, even what was "
        "behind, into the middle of the view; searchlight and Doppler ignored.",
        STREET + "; searchlight off.",
    ),
    (
        "weiskopf_fig6_street_chang",
        f"{W99} Fig. 6",
        "The same, with the searchlight as Chang et al. (1996) derived it (one power of D), which Weiskopf et "
        "al. show to be wrong.",
        STREET + "; `use_chang_searchlight` (D^1).",
    ),
    (
        "weiskopf_fig7_street_searchlight",
        f"{W99} Fig. 7",
        "The same with the correct searchlight, radiance times D^4 (eq. 15): the street ahead is blinding "
        "(D = 3 straight ahead, D^4 = 81), at the same exposure as Figs. 4-6.",
        STREET + "; searchlight on (D^4).",
    ),
    (
        "weiskopf_sun_rest",
        f"{W99} Figs. 8-9, reference",
        "The Suns seen at rest from the same place (not a figure of the paper; the reference for the "
        "brightness ratios: at rest every Sun is equally bright). Without aberration they lie further left, "
        "at -57, -44.5, -30, -13 and 7 degrees, so this 20 mm view (84 degrees wide) shows three whole, one "
        "cut by the left edge and the fifth not at all.",
        "Camera at rest; " + SUN.split("; ")[1] + "; exposure -0.5 stops as Figs. 8-9.",
    ),
    (
        "weiskopf_fig8_sun_doppler",
        f"{W99} Fig. 8",
        "The Sun passing at 0.5c, Doppler effect only as the paper defines it: the shifted spectrum "
        "L(lambda D) with no further factor, so a blackbody at T is seen at the colour of D T with "
        "Y(D T) / (D^5 Y(T)) of its rest brightness. Ahead it turns bluish, behind orange, and the brightness "
        "hardly changes: Y(D T) / (D^5 Y(T)) is largest, 1.02, near D = 0.9 and falls on both sides, to about "
        "0.8 for the Sun behind (D = 0.67) and for the one ahead (D = 1.23). Aberration draws the Sun behind "
        "larger and the one ahead smaller.",
        SUN + "; Doppler colour on, searchlight off, `doppler_only_brightness = 'SPECTRUM'`.",
    ),
    (
        "weiskopf_fig9_sun_doppler_searchlight",
        f"{W99} Fig. 9",
        "The same with Doppler and searchlight together (eq. 14): a blackbody seen at D T, brightness "
        "Y(D T) / Y(T): ahead 2.3 times as bright as at rest (bluish white, 7070 K; clipped to white in the PNG), "
        "behind a ninth as bright and orange-brown (3860 K).",
        SUN + "; Doppler colour and searchlight on.",
    ),
    (
        "gray_fig1a_rest",
        f"{G20} Fig. 1(a)",
        "The scene (tiled floor, back wall, three spheres) photographed at rest.",
        "c = 1, camera at rest, 12 mm lens (113 degrees), pinhole.",
    ),
    (
        "gray_fig1b_pinhole",
        f"{G20} Fig. 1(b)",
        "The camera moving at 99.5 % of c through the scene, pinhole shutter model: the scene is shrunk "
        "into a small patch around the direction of motion.",
        GRAY + "; pinhole shutter at t_S = 0; 100 mm lens.",
    ),
    (
        "gray_fig1c_time_of_flight",
        f"{G20} Fig. 1(c)",
        "The same camera and speed with light-travel time alone (*Time of Flight Only*: the Galilean "
        "transformation instead of the Lorentz one, light at c in the camera frame; no searchlight or "
        "Doppler, as in Gray's renders): a point is seen where it was when its light left it, "
        "x_seen = x + beta r in the camera frame. The look is relativity's, more so: directions perpendicular "
        "to beta are seen acos(beta) = 5.7 degrees from it in both, but what lies ahead is squeezed about ten "
        "times more, so the wall and the spheres fill a few pixels right of the image centre (the red "
        "sphere is 1.4 px from the direction of beta here, 11.9 px in (b)). Relativity is this plus the "
        "Lorentz contraction of the scene by gamma = 10 along beta, which spreads what is ahead. The red "
        "sphere's centroid is measured against the time-of-flight formula (it covers about one pixel "
        "here; see the enlargement). Gray's own panel was probably made with light at c in the scene "
        'frame instead, which squeezes far less (docs/camera.md, "Time of flight only").',
        GRAY + "; pinhole shutter at t_S = 0; 100 mm lens; `use_time_of_flight`.",
    ),
    (
        "gray_fig1c_time_of_flight_enlarged",
        f"{G20} Fig. 1(c), enlarged",
        "The centre of Fig. 1(c) through a 3000 mm lens (30 times the focal length, 0.69 degrees wide), "
        "shifted to centre the direction of motion: the back wall and the three spheres, whole, in a few "
        "pixels of Fig. 1(c). The red sphere's centroid against the time-of-flight formula.",
        "As Fig. 1(c), 3000 mm lens, lens shift x = 0.101 * 3000 / 36 = 8.42.",
    ),
    (
        "gray_fig1_wide_aperture",
        f"{G20} (Fig. 1 with a wide aperture)",
        "The same moving camera with a wide aperture (radius 0.2) and the aperture-plane shutter, focused at "
        "distance 10: the relativistic blur of Section 3 (not a panel of Fig. 1, whose (c) is the Galilean "
        "time-of-flight picture above).",
        GRAY + "; aperture-plane shutter, 100 mm lens.",
    ),
    (
        "gray_fig3b_aperture_plane",
        f"{G20} Fig. 3(b)",
        "Aperture-plane shutter, medium aperture (radius 0.05): the spheres, placed to be in focus, come out "
        "blurred, except near the centre and the direction of beta (relativistic coma).",
        ARRAY + "; aperture-plane shutter at t_S = 0; " + GRAY + ".",
    ),
    (
        "gray_fig4_aperture_plane_huge",
        f"{G20} Fig. 4",
        "As Fig. 3(b) with a huge aperture (radius 0.2): each sphere is drawn into a curved streak.",
        ARRAY + "; aperture radius 0.2; " + GRAY + ".",
    ),
    (
        "gray_fig5_detector_plane",
        f"{G20} Figs. 5 and 6(a)",
        "Detector-plane shutter with an ideal thin lens: every sphere is sharp, at its grid position, even "
        "with the huge aperture (Fig. 6(a)).",
        ARRAY + " (detector-plane centres); shutter time so that the axial chief ray passes the lens at t = 0; "
        "aperture radius 0.2; " + GRAY + ".",
    ),
    (
        "gray_fig6b_phase_hologram",
        f"{G20} Fig. 6(b)",
        "As Fig. 6(a) (the detector-plane shutter, huge aperture), but the lens is a phase hologram of the "
        "ideal thin lens: same ray directions, no time delays, so rays from a point to its image take "
        "different times (`imaging_element = 'PHASE_HOLOGRAM'`). The chief rays keep the ideal lens's times, "
        "so the spheres are where they were; the other rays pass them at other times, which eq. (1) spreads "
        "along beta: the array is out of focus. Here each sphere is drawn out into a long streak pointing away "
        "from the direction of beta (right of the centre), a fan like coma (Gray section 5 calls it a "
        "coma-type aberration), and much more blurred than in Gray's panel: the 100 mm lens at "
        "aperture radius 0.2 (f/0.25) puts the detector 0.1 behind the lens, and a ray through the rim "
        "takes |L - D| - |D| = 0.12 longer to the detector than the chief ray, which gamma ~ 7 turns into "
        "a spread of about 0.9 scene units, several sphere spacings (Dr TIM's detector distance is not "
        "given; not checked against it).",
        ARRAY + " (detector-plane centres, as Fig. 5); shutter time as Fig. 5; aperture radius 0.2; "
        "phase-hologram lens; " + GRAY + ".",
    ),
    (
        "gray_fig7_focus_surface",
        f"{G20} Fig. 7",
        "Focus-surface shutter (every ray passes the focus surface at t_S): spheres placed on its scene-frame "
        "focus surface, in focus but some strongly distorted. Here the array is in focus in the middle, "
        "surrounded by many smeared copies of spheres on a bright ring: the rays' lens times spread by "
        "|P| / c across the image (10 at the centre, 10.16 at the edge), during which the camera moves "
        "gamma beta c ~ 1.6 scene units, as far as the array is wide, so it sweeps through the array. Looks "
        "busier than Gray's Fig. 7; not checked against Dr TIM, but it is what Gray's equations give: a chief-ray "
        "trace from the physics core (tools/check_gallery_rays.py, independent of the shader) finds the same "
        "sphere pixels, ring included, at 98.2 % of the pixels away from outlines (the rest is the aperture's blur).",
        ARRAY + " (focus-surface centres); t_S = -10, so that the axial chief ray passes the lens at t = 0; "
        "aperture radius 0.05; " + GRAY + ".",
    ),
    (
        "gray_fig8a_rest",
        f"{G20} Fig. 8(a)",
        "Cylinders whose axes lie in the focus plane z = 8, four red discs in that plane, a tiled floor; "
        "camera at rest.",
        "c = 1, 50 mm lens focused at 8, aperture radius 0.02.",
    ),
    (
        "gray_fig8b_fixed_point_surface",
        f"{G20} Fig. 8(b)",
        "The same camera moving, fixed-point-surface shutter: whatever lies in the focus plane (the discs, "
        "the cylinder axes) stays exactly where it was at rest; the rest of the scene is distorted. The grey "
        "ring right of the centre surrounds the direction of beta: there the scene-frame rays through the "
        "fixed points fan out about D ~ 20 times wider than seen, graze the focus plane and hit the "
        "cylinders' mantles: the bars around the direction of beta swell into that ring. Not checked against "
        "Dr TIM, but a chief-ray trace from the physics core (tools/check_gallery_rays.py) finds the same "
        "cylinder pixels at 100 % of the 72214 pixels away from outlines.",
        GRAY + "; fixed-point-surface shutter, 50 mm lens focused at 8.",
    ),
    (
        "gray_fig9a_rest",
        f"{G20} Fig. 9(a)",
        "A portrait-like scene, eyes in the focus plane; camera at rest.",
        "c = 1, 50 mm lens focused at 4.4, aperture radius 0.05.",
    ),
    (
        "gray_fig9b_moving",
        f"{G20} Fig. 9(b)",
        "Moving camera, shutter in the plane perpendicular to beta through (0.111, 0, 1.1) opening at t_S = -1: "
        "the portrait is distorted and out of focus. Here it is shrunk to a small blurred patch: aberration at "
        "99.5 % of c shrinks the view ahead about 20-fold (Gray's panel looks larger; not checked against Dr TIM). "
        "A chief-ray trace from the physics core (tools/check_gallery_rays.py) puts the backdrop at 189-215 x "
        "108-131 px, centroid (202.3, 120.0); the render's blurred patch spans 183-220 x 103-137, centroid "
        "(202.2, 120.2).",
        GRAY + "; arbitrary-plane shutter, point (0.111, 0, -1.1), normal (0.1, 0, -0.99) (camera axes), t_S = -1.",
    ),
    (
        "gray_fig9c_lorentz_window",
        f"{G20} Fig. 9(c)",
        "As (b) with a Lorentz window in the shutter plane, a plane of spatial fixed points for t_S: the "
        "photo equals the photo at rest.",
        "As Fig. 9(b), `use_lorentz_window`.",
    ),
    (
        "gray_fig10_window_detector_plane",
        f"{G20} Fig. 10(b)",
        "The same Lorentz window (the plane of spatial fixed points for t = -1) with the detector-plane "
        "shutter timing the rays: only the axial chief ray crosses the window at t = -1, the others earlier "
        "or later, and eq. (1) moves their crossing events along beta. The window undoes the distortion only "
        "imperfectly: the backdrop's checks bend at the left edge (away from beta), the portrait in the "
        'middle is almost as at rest (Gray: "a slight distortion ... (floor tiles)"; here up to 37 px at '
        "320x240 in the corners, where the rays run furthest from beta). Measured in the strips beside the "
        "portrait (outer 15 % of the width, the backdrop at distance 10): the difference from Fig. 9(a) as it "
        "is, and from Fig. 9(a) with every pixel moved to where the physics core's window ray (chief ray, "
        "`shutter.lens_time` then `shutter.lorentz_window_ray`) meets the backdrop: the prediction takes away "
        "91 % of the difference; the rest is sampling noise, the aperture (radius 0.05) and interpolation "
        "at the checks' edges.",
        "As Fig. 9(c), but `shutter_model = 'DETECTOR_PLANE'` (ideal lens) with `lorentz_window_shutter = "
        "'SHUTTER_MODEL'`, `lorentz_window_time = -1`, and the shutter time Gray's caption gives: the axial "
        "chief ray has Fig. 9's timing (t_S = -1 + 1.1112 + 0.0506 = 0.1618); the preset *Gray 2020 Fig 10 "
        "Lorentz window detector plane*.",
    ),
    (
        "gray_fig11a_stereo_rest",
        f"{G20} Fig. 11(a)",
        "The portrait of Fig. 9 through Blender's stereo camera at rest, as a red-cyan anaglyph (left eye red, "
        "right eye green and blue): horizontal parallax only, zero for the plane at distance 5. Measured: "
        "the pupils' parallax between the eyes against the off-axis pair's, 0.4 f (1/z - 1/5) at their "
        "depth z = 4.31.",
        "As Fig. 9(a); Stereo 3D, off-axis eyes 0.4 apart converging at 5, Blender's default pivot (left eye "
        "at the camera) (the preset *Gray 2020 Fig 11 stereo Lorentz window* without motion).",
    ),
    (
        "gray_fig11b_stereo_moving",
        f"{G20} Fig. 11(b)",
        "The stereo camera moving as in Fig. 9(b), both eyes with one shutter plane and one shutter time: "
        "each eye's photo is shrunk into a small blurred patch around the direction of motion as in Fig. 9(b); "
        "the two patches are about as far apart as the off-axis parallax of a point at infinity (the squeezed "
        "scene is seen far away). The vertical disparity that keeps a moving pair from fusing (Gray section 4) "
        "is too small to see at this scale; `tests/blender/camera/test_camera_stereo.py` measures it on "
        "markers (-11.7 to +8.9 px at 200x150).",
        "As Fig. 9(b), stereo as (a).",
    ),
    (
        "gray_fig11c_stereo_lorentz_window",
        f"{G20} Fig. 11(c)",
        "As (b) with the Lorentz window in the shared shutter plane (a plane of spatial fixed points for "
        "t_S): the anaglyph equals the anaglyph at rest (a), pupils' parallax included.",
        "As Fig. 9(c), stereo as (a).",
    ),
    (
        "cockpit_street_flythrough",
        "A fly-through frame from a cockpit (issue 28; Gray et al. appendix A)",
        "The street of Figs. 4-7 entered at 0.9c from a cockpit that moves with the camera (docs/cockpit.md): "
        "an opaque frame with an open window and a glowing instrument strip, parented to the camera and "
        "marked *Moves With Camera*, with a lamp moving with it. The cockpit is photographed as at rest "
        "(Blender's render of it, laid over the relativistic one): not aberrated, not Doppler-shifted, not "
        "beamed. It is lit by its lamp and by the sky as the moving camera receives it (aberrated, "
        "`D^4`-beamed, Doppler-shifted; `colour/cockpit_sky.py`): the frame faces backward, where the sky "
        "is dim. Through the window the street is the relativistic photograph (aberration, Doppler colour, "
        "searchlight), the lamp lighting it as a moving light. The street's sun, behind and above the "
        "camera in the street, shines on the cockpit from ahead in its frame (aberration: its light, 40 "
        "degrees from straight behind, arrives 116 degrees from it; eq. 18, `lights/cockpit_lamps.py`), so "
        "it lights the frame's far side, out of view. The glowing street lamps are meshes, whose light "
        "does not reach the cockpit (left out, docs/cockpit.md).",
        STREET.replace("0.8c", "0.9c").replace(
            "Doppler colour off (the paper's grey-scale street: total radiance, eq. 15)",
            "Doppler colour and searchlight on",
        )
        + "; exposure -3 stops.",
    ),
]

PENDING = """## Pending

- Nothing of the two papers' figures: every panel the add-on can render is above.
"""


CLAMP_NOTE = """## Note: Cycles' sample clamp and the searchlight

Cycles clamps indirect samples at 10 by default (Render Properties > Light Paths > Clamping). The
exact camera applies the searchlight's `D^4` to the camera ray's throughput, so bright indirect
light seen ahead is cut: in the street at 0.8c the centre came out 4.5 % darker than `<D^4>` with
the default clamp (64.64 against 67.71 at 320x240, 16 samples; the same 4.5 % for Chang's `D^1`),
and within 1 % with no clamping (67.29 against 67.71, Chang's 2.848 against 2.865, same size and
samples). The gallery renders with both clamps off. Since then the add-on scales the clamps by the
brightest `D^4`, `(gamma (1 + beta))^4`, while the exact camera renders, and gives the user's values
back on removal (`blender/camera/clamping.py`).
"""


def _number(value):
    if abs(value) >= 100 or value == int(value):
        return f"{value:.0f}" if value == int(value) or abs(value) >= 1000 else f"{value:.1f}"
    return f"{value:.4g}"


def write(path, numbers, size, samples):
    lines = [
        "# Gallery: the papers' figures",
        "",
        "Made by `python examples/gallery.py` (all figures, "
        f"{size[0]}x{size[1]}, {samples} samples, no denoising; `--only NAME`, `--size WxH`, `--samples N`; "
        "`--list` names the figures). Each scene is built from code (`examples/gallery_scenes.py`) and "
        "rendered through the add-on (`effect.apply`, Cycles); the numbers below are measured on the linear "
        "render by `examples/gallery_measure.py` and are written here by the script. The PNGs use the "
        "Standard view transform at one exposure per family, so brightness compares within a family. "
        "Expected values: docs/physics.md (D = 1 / (gamma (1 - beta . d')) for a pixel's camera-frame "
        "viewing direction d', aberration) and, for blackbodies, Planck spectra through the CIE 1931 "
        "observer (colour-science).",
        "",
        "**Doppler only, two definitions** (`scene.relativity.doppler_only_brightness`, shown when Doppler "
        "colour is on and the searchlight off): *Rest Brightness* (`REST`, the default) keeps the rest-frame "
        "brightness and changes the colour only; *Shifted Spectrum* (`SPECTRUM`) is Weiskopf et al.'s "
        "Fig. 8: the spectrum `L(lambda D)` with no further factor, `D^-5` of eq. 14's, so a blackbody "
        "shows `Y(D T) / (D^5 Y(T))` of its rest brightness. With the searchlight on both give eq. 14.",
        "",
        "![contact sheet](gallery/contact_sheet.png)",
        "",
    ]
    for name, title, caption, settings in FIGURES:
        lines += [
            f"## {title}: `{name}`",
            "",
            f"![{name}](gallery/{name}.png)",
            "",
            caption,
            "",
            f"Settings: {settings}",
            "",
        ]
        values = numbers.get(name)
        if values:
            lines += ["| measured | value |", "|---|---|"]
            lines += [f"| {key} | {_number(value)} |" for key, value in values.items()]
            lines.append("")
    lines += [CLAMP_NOTE, PENDING]
    path.write_text("\n".join(lines))


if __name__ == "__main__":  # rewrite docs/gallery.md from docs/gallery/measurements.json
    import json
    from pathlib import Path

    docs = Path(__file__).resolve().parents[1] / "docs"
    data = json.loads((docs / "gallery" / "measurements.json").read_text())
    write(docs / "gallery.md", data["numbers"], data["size"], data["samples"])
