"""The add-on in the real Blender application: Debian's Blender 5.2 (no OSL) in a window under Xvfb
(issue 25). ``conftest.gui_session`` runs the session once; these tests read what it recorded: the
report, the screenshots, the F12 image and Blender's log, and compare the F12 image with the same
scene rendered by the ``bpy`` wheel here.
"""

import re
import sys
from pathlib import Path

import numpy as np
import pytest
from gui_scene import HEIGHT, WIDTH, rest_pixel

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "blender" / "camera"))
import camera_helpers as ch  # noqa: E402

INTERNAL = ("oslquery", "_cycles", "with_osl", "OSLUnavailableError", "BLENDER_EEVEE")
PANELS = (
    "01_exact_camera_before",
    "03_other_settings",
    "04_detector_plane",
    "05_geometry_before",
    "06_geometry_set_up",
)
# Blender's own log lines, not the add-on's (checked: none names the add-on).
BLENDER_LINES = (re.compile(r"Error: Not freed memory blocks"),)


def read_png(bpy, path):
    """RGB float pixels [row (top first), column, channel]."""
    return ch.read_image(bpy, path)[..., :3]


def blob(pixels, threshold):
    """(x, y) brightness-weighted centroid (pixel centres at +0.5) of pixels above ``threshold``, and
    how many there are."""
    brightness = pixels.mean(axis=2)
    weight = np.where(brightness > threshold, brightness, 0.0)
    rows, columns = np.indices(weight.shape)
    total = weight.sum()
    assert total > 0, "nothing bright in the image"
    return ((columns + 0.5) * weight).sum() / total, ((rows + 0.5) * weight).sum() / total, int((weight > 0).sum())


def sphere_colour(pixels):
    """Median display colour of the pixels brighter than half the brightest (the sphere's disc)."""
    brightness = pixels.mean(axis=2)
    return np.median(pixels[brightness > 0.5 * brightness.max()], axis=0)


def user_facing(message):
    assert message[:1].isupper(), message
    for name in INTERNAL:
        assert name not in message, message


def test_debian_blender_without_osl_runs_the_addon(gui_session):
    report = gui_session.report
    assert report.get("finished") and "driver_error" not in report, gui_session.describe()
    assert report["blender"].startswith("5.2"), report["blender"]
    assert report["with_osl"] is False  # the build this stage is for
    assert report["addon_enabled"] == [True, True], report["addon_enabled"]  # installed with install-file -e


def test_log_has_no_traceback_or_error(gui_session):
    lines = gui_session.log().splitlines()
    assert not any("Traceback" in line for line in lines), gui_session.log()[-6000:]
    errors = [line for line in lines if ("Error" in line or "ERROR" in line) and not line.startswith("gui-driver:")]
    errors = [line for line in errors if not any(pattern.search(line) for pattern in BLENDER_LINES)]
    refusals = {entry["error"].strip() for entry in gui_session.report["operators"].values() if "error" in entry}
    errors = [line for line in errors if line.strip() not in refusals]  # the refusals the tests expect
    assert not errors, errors


def test_every_panel_is_drawn(gui_session, factory_blender):
    """Each screenshot shows the 3D view's sidebar open on the add-on's tab, drawn (not one plain
    colour), and differing from the next screenshot's sidebar where the settings changed."""
    report = gui_session.report
    sidebars = {}
    for name in PANELS:
        pixels = read_png(factory_blender, gui_session.out / f"{name}.png")
        x, y, width, height = report["sidebar_rect"][name]  # window pixels, y up
        assert width > 150 and height > 500, (name, width, height)
        sidebar = pixels[pixels.shape[0] - (y + height) : pixels.shape[0] - y, x : x + width]
        assert sidebar.std() > 0.05, name
        sidebars[name] = sidebar
    for a, b in zip(PANELS, PANELS[1:], strict=False):
        assert np.abs(sidebars[a] - sidebars[b]).max() > 0.1, (a, b)


def test_exact_camera_is_refused_and_said_before_set_up(gui_session):
    report = gui_session.report
    hint = [m for m in report["panel_messages"]["01_exact_camera_before"] if "has no OSL" in m]
    assert hint and "Apparent Geometry" in hint[0], report["panel_messages"]
    user_facing(hint[0])
    refused = report["operators"]["setup_exact_camera"]
    assert "error" in refused, refused
    line = refused["error"].strip().splitlines()[-1].split(": ", 1)[-1]
    assert "has no OSL" in line and "Exact Camera" in line, line
    user_facing(line)
    assert report["exact_camera_scene_unchanged"] is True


def test_apparent_geometry_set_up_from_the_button(gui_session):
    report = gui_session.report
    assert report["operators"]["setup_geometry"] == {"result": ["FINISHED"]}, report["operators"]
    for name in ("05_geometry_before", "06_geometry_set_up"):
        said = [m for m in report["panel_messages"][name] if "has no OSL" in m and "boosted-mesh preview" in m]
        assert said, (name, report["panel_messages"][name])
        user_facing(said[0])


def test_f12_says_it_renders_the_preview(gui_session):
    report = gui_session.report
    assert report["operators"]["render"] == {"result": ["FINISHED"]}
    assert report["camera_type_after_render"] == "PERSP"
    popups = [(title, reason) for title, reason in report["popups"] if "boosted-mesh preview" in title]
    assert popups and "has no OSL" in popups[0][1], report["popups"]
    user_facing(popups[0][1])
    assert any("has no OSL" in m for m in report["panel_messages"]["08_after_f12"])


@pytest.fixture
def wheel_render(relativity_addon, factory_blender, tmp_path_factory):
    """The same scene rendered by the bpy wheel: Final Render: Boosted Meshes, which is what a
    build without OSL renders for Exact Camera (tests/blender/ui/test_no_osl_build.py)."""
    import gui_scene

    bpy = factory_blender
    scene, _, _ = gui_scene.build(bpy, method="GEOMETRY", final_render="PREVIEW")
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    path = tmp_path_factory.mktemp("gui-reference") / "wheel.png"
    scene.render.filepath = str(path)
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    return read_png(bpy, path)


def test_f12_matches_the_bpy_wheel(gui_session, wheel_render, factory_blender):
    """The moving sphere where the wheel puts it (within a pixel), as bright (within 5 %), and
    moved from where it is at rest (so the effect was applied)."""
    debian = read_png(factory_blender, gui_session.out / "f12.png")
    assert debian.shape == (HEIGHT, WIDTH, 3)
    x, y, count = blob(debian, 0.05)
    x_ref, y_ref, count_ref = blob(wheel_render, 0.05)
    print(f"F12 centroid Debian ({x:.2f}, {y:.2f}) px, {count} px; wheel ({x_ref:.2f}, {y_ref:.2f}) px, {count_ref} px")
    assert np.hypot(x - x_ref, y - y_ref) < 1.0
    mean, mean_ref = debian.mean(), wheel_render.mean()
    print(f"mean brightness Debian {mean:.5f}, wheel {mean_ref:.5f}")
    assert abs(mean / mean_ref - 1.0) < 0.05
    x_rest, y_rest = rest_pixel()
    print(f"at rest ({x_rest:.2f}, {y_rest:.2f}) px: {np.hypot(x - x_rest, y - y_rest):.1f} px away")
    assert np.hypot(x - x_rest, y - y_rest) > 5.0, ((x, y), (x_rest, y_rest))


def test_rendered_viewport_shows_the_preview(gui_session, factory_blender):
    """The Rendered viewport through the camera: the sphere where F12 puts it (the preview), to 2 %
    of the frame's width, and of its colour (Doppler-shifted orange to blue), measured in the
    screenshot inside the camera frame."""
    report = gui_session.report
    shot = read_png(factory_blender, gui_session.out / "07_viewport_rendered.png")
    x0, y0, x1, y1 = report["viewport_camera_frame"]
    height = shot.shape[0]
    top, bottom = int(round(height - y1)), int(round(height - y0))
    left, right = int(round(x0)), int(round(x1))
    frame = shot[top:bottom, left:right]
    assert frame.shape[0] > 50 and frame.shape[1] > 50, frame.shape
    x, y, count = blob(frame, 0.15)
    scale = WIDTH / frame.shape[1]
    x_f12, y_f12, _ = blob(read_png(factory_blender, gui_session.out / "f12.png"), 0.05)
    x, y = x * scale, y * scale
    print(f"viewport centroid ({x:.2f}, {y:.2f}) render px ({count} screen px); F12 ({x_f12:.2f}, {y_f12:.2f})")
    assert np.hypot(x - x_f12, y - y_f12) < 0.02 * WIDTH
    colour, colour_f12 = sphere_colour(frame), sphere_colour(read_png(factory_blender, gui_session.out / "f12.png"))
    print(f"sphere colour: viewport {np.round(colour, 3)}, F12 {np.round(colour_f12, 3)}")
    assert np.abs(colour - colour_f12).max() < 0.02


def test_switching_method_and_moving_light_say_why(gui_session):
    """Method switched to Exact Camera after Set Up: kept on Apparent Geometry, a popup and the
    panel say why; a moving light is rendered at rest, and the panel says why (no OSL)."""
    report = gui_session.report
    switched = [
        reason for title, reason in report["switch_popups"] if "not switched" in title and "has no OSL" in reason
    ]
    assert switched, report["switch_popups"]
    user_facing(switched[0])
    said = [m for m in report["panel_messages"]["09_method_switched"] if "has no OSL" in m and "Apparent" in m]
    assert said, report["panel_messages"]["09_method_switched"]
    at_rest = [m for m in report["panel_messages"]["10_moving_light"] if "'Lamp'" in m]
    assert at_rest and "at rest" in at_rest[0] and "has no OSL" in at_rest[0], report["panel_messages"]
    assert not any("final render is exact" in m for m in report["panel_messages"]["10_moving_light"])
    assert not any(m.startswith("Still set up") for m in report["panel_messages"]["10_moving_light"])  # Method back


def test_velocity_changed_in_the_panel_reaches_its_clip_end_warning(gui_session):
    """The sphere's own velocity set towards the camera in the running application under a Clip End
    of 30 m: seen where it was (docs/physics.md: a point approaching at 0.9c at distance d is seen
    at d / (1 - 0.9), about 51 m here, farther in the moving observer's boosted view), so the panel
    names the Clip End it needs, after the window's own redraws; none before the change."""
    report = gui_session.report
    assert not any("Clip End" in m for m in report["panel_messages"]["10b_clip_end_short"]), report["panel_messages"]
    said = [m for m in report["panel_messages"]["10c_towards_camera"] if "Clip End" in m]
    assert len(said) == 1 and "'Mover'" in said[0] and "Clip End 30 m" in said[0], report["panel_messages"]
    seen = float(said[0].split("seen ")[1].split(" m away")[0])
    assert seen > 5.0 / (1.0 - 0.9) * 0.8, said[0]
    # dragged back to its velocity of 10b (the callback writing that mesh only): the line goes
    assert not any("Clip End" in m for m in report["panel_messages"]["10d_velocity_back"]), report["panel_messages"]


def test_remove_from_the_button_restores_the_scene(gui_session):
    report = gui_session.report
    assert "result" in report["operators"]["remove"], report["operators"]
    assert report["after_remove"] == {"modifiers": [], "objects": ["Camera", "Mover"]}
