"""Driver for the real-application stage: runs inside Debian's Blender, in a window under Xvfb.

    blender --python gui_driver.py -- OUT_DIR

It is not a test (pytest does not collect it): ``test_real_blender.py`` starts Blender with it and
checks what it writes to ``OUT_DIR``: ``report.json``, screenshots of the whole X screen
(``*.png``, taken with ``xwd``: ``bpy.ops.screen.screenshot`` reads a black front buffer under
Xvfb's software OpenGL) and ``f12.png``. Every step runs from a ``bpy.app.timers`` timer, so the
window is live between steps (panels drawn, the viewport rendering); operators run with the real
window, 3D view area and sidebar region as their context, as when the user clicks the button.

What the add-on draws is observed, not replaced: the panel module's ``_message`` (every warning the
panels draw) and ``render_notice._popup`` (the popups) are wrapped to record their text and then
do what they did.
"""

import json
import os
import subprocess
import sys
import traceback

import bpy

OUT = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gui_scene  # noqa: E402

ADDON = "bl_ext.user_default.relativity_addon"
report = {"steps": [], "panel_messages": {}, "popups": [], "operators": {}, "screenshots": {}}
_drawn = []  # warnings the panels drew since the last clear
_popups = []


def log(text):
    report["steps"].append(text)
    print(f"gui-driver: {text!r}", flush=True)


def window():
    return bpy.context.window_manager.windows[0]


def view3d():
    """(area, sidebar region, main region) of the 3D view."""
    for area in window().screen.areas:
        if area.type == "VIEW_3D":
            regions = {region.type: region for region in area.regions}
            return area, regions["UI"], regions["WINDOW"]
    raise RuntimeError("no 3D view in the window")


def redraw():
    with bpy.context.temp_override(window=window()):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)


def screenshot(name):
    """The whole X screen as OUT/name.png (xwd, converted with Blender's image API)."""
    import numpy as np

    redraw()
    raw = os.path.join(OUT, f"{name}.xwd")
    subprocess.run(["xwd", "-root", "-silent", "-out", raw], check=True)
    with open(raw, "rb") as file:
        data = file.read()
    os.remove(raw)
    fields = np.frombuffer(data[:100], ">u4")
    header, width, height, byte_order, line_bytes, colours = (int(fields[i]) for i in (0, 4, 5, 7, 12, 19))
    start = header + colours * 12
    pixels = np.frombuffer(data, np.uint8, count=line_bytes * height, offset=start).reshape(height, line_bytes)
    pixels = pixels[:, : width * 4].reshape(height, width, 4)
    rgb = pixels[..., 2::-1] if byte_order == 0 else pixels[..., 1:]  # LSB first: B, G, R, pad
    image = bpy.data.images.new(f"gui-{name}", width, height)
    rgba = np.concatenate([rgb[::-1].astype(np.float32) / 255.0, np.ones((height, width, 1), np.float32)], axis=2)
    image.pixels.foreach_set(rgba.ravel())
    path = os.path.join(OUT, f"{name}.png")
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    report["screenshots"][name] = path
    log(f"screenshot {name}")


def call(name, operator):
    """Run an operator as the sidebar's button does (INVOKE, the real window, area and region);
    record its result or its error line."""
    area, sidebar, _ = view3d()
    try:
        with bpy.context.temp_override(window=window(), area=area, region=sidebar):
            result = sorted(operator("INVOKE_DEFAULT"))
        report["operators"][name] = {"result": result}
    except RuntimeError as error:
        report["operators"][name] = {"error": str(error)}
    log(f"{name}: {report['operators'][name]}")


def messages(name):
    """The warnings the panels drew at the last redraws, recorded under ``name``."""
    report["panel_messages"][name] = sorted(set(_drawn))


def observe_addon():
    panel = sys.modules[f"{ADDON}.blender.ui.panel"]
    notice = sys.modules[f"{ADDON}.blender.pipeline.render_notice"]
    message, popup = panel._message, notice._popup

    def recorded_message(layout, context, text, icon="ERROR"):
        _drawn.append(text)
        return message(layout, context, text, icon)

    def recorded_popup(title, reason):
        _popups.append([title, reason])
        return popup(title, reason)

    panel._message = recorded_message
    notice._popup = recorded_popup


def select_only(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(other == obj)
    bpy.context.view_layer.objects.active = obj


def draw_and_shoot(name, wait=1.0):
    _drawn.clear()
    _, sidebar, _ = view3d()
    sidebar.tag_redraw()
    redraw()
    yield wait
    redraw()
    messages(name)
    _, sidebar, _ = view3d()
    report.setdefault("sidebar_rect", {})[name] = [sidebar.x, sidebar.y, sidebar.width, sidebar.height]
    screenshot(name)


def camera_frame(scene, camera, region, r3d):
    """The camera's frame in window pixels (x0, y0, x1, y1; y up) in the camera view."""
    from bpy_extras.view3d_utils import location_3d_to_region_2d

    corners = [camera.matrix_world @ corner for corner in camera.data.view_frame(scene=scene)]
    points = [location_3d_to_region_2d(region, r3d, corner) for corner in corners]
    xs = [p.x + region.x for p in points]
    ys = [p.y + region.y for p in points]
    return [min(xs), min(ys), max(xs), max(ys)]


def steps():
    import _cycles
    import addon_utils

    yield 2.0
    report["blender"] = bpy.app.version_string
    report["python"] = sys.version.split()[0]
    report["with_osl"] = bool(getattr(_cycles, "with_osl", False))
    report["addon_enabled"] = list(addon_utils.check(ADDON))
    try:
        import colour  # noqa: F401

        report["colour_science"] = True
    except ImportError:
        report["colour_science"] = False
    if not report["addon_enabled"][1]:
        raise RuntimeError(f"{ADDON} is not enabled after install-file")
    observe_addon()
    window().screen.areas  # noqa: B018
    area, sidebar, main = view3d()
    area.spaces.active.show_region_ui = True
    yield 1.0
    _, sidebar, main = view3d()
    sidebar.active_panel_category = "Relativity"
    report["sidebar_width"] = sidebar.width

    # 1. Exact Camera (the default Method) in a build without OSL: the hint before Set Up, the refusal.
    scene, camera, sphere = gui_scene.build(bpy, method="CAMERA", moving_sphere=False)
    select_only(sphere)
    yield from draw_and_shoot("01_exact_camera_before")
    before = (camera.data.type, len(bpy.data.objects), len(bpy.data.node_groups), len(bpy.data.texts))
    call("setup_exact_camera", bpy.ops.relativity.setup_scene)
    after = (camera.data.type, len(bpy.data.objects), len(bpy.data.node_groups), len(bpy.data.texts))
    report["exact_camera_scene_unchanged"] = before == after
    yield from draw_and_shoot("02_exact_camera_refused")

    # 2. Every sub-panel's other branches: detector-plane lens, arbitrary plane, Lorentz window,
    #    Blackbody lighting, the camera's animation as velocity, a moving light as active object.
    settings = scene.relativity
    settings.shutter_model = "ARBITRARY_PLANE"
    settings.use_lorentz_window = True
    settings.lorentz_window_shutter = "SHUTTER_MODEL"
    settings.fast_illuminant = "BLACKBODY"
    settings.velocity_source = "CAMERA_ANIMATION"
    data = bpy.data.lights.new("Lamp", "SPOT")
    lamp = bpy.data.objects.new("Lamp", data)
    scene.collection.objects.link(lamp)
    lamp.relativity.motion = "CONSTANT"
    lamp.relativity.beta = (0.3, 0.0, 0.0)
    select_only(lamp)
    yield from draw_and_shoot("03_other_settings")
    settings.shutter_model = "DETECTOR_PLANE"
    lamp.relativity.motion = "ANIMATION"
    yield from draw_and_shoot("04_detector_plane")

    # 3. Apparent Geometry, Final Render: Exact Camera: said before Set Up, Set Up from the button.
    scene, camera, sphere = gui_scene.build(bpy, method="GEOMETRY", final_render="EXACT")
    select_only(sphere)
    yield from draw_and_shoot("05_geometry_before")
    call("setup_geometry", bpy.ops.relativity.setup_scene)
    yield from draw_and_shoot("06_geometry_set_up")

    # 4. The Rendered viewport, through the camera, overlays off (no selection outline on the
    #    sphere), sidebar and toolbar closed (they overlap the view).
    area, sidebar, main = view3d()
    space = area.spaces.active
    space.region_3d.view_perspective = "CAMERA"
    space.overlay.show_overlays = space.show_gizmo = False
    space.show_region_ui = space.show_region_toolbar = False
    space.shading.type = "RENDERED"
    yield 1.0
    area, sidebar, main = view3d()
    with bpy.context.temp_override(window=window(), area=area, region=main):
        bpy.ops.view3d.view_center_camera()
    yield 20.0  # Cycles renders the viewport on the CPU, progressively
    area, sidebar, main = view3d()
    report["viewport_camera_frame"] = camera_frame(scene, camera, main, area.spaces.active.region_3d)
    report["screen_height"] = window().height
    screenshot("07_viewport_rendered")
    space.shading.type = "SOLID"
    space.overlay.show_overlays = space.show_gizmo = True
    space.show_region_ui = space.show_region_toolbar = True
    yield 1.0
    area, sidebar, main = view3d()

    # 5. F12 (the render operator, writing the still) on Final Render: Exact Camera without OSL.
    _popups.clear()
    scene.render.filepath = os.path.join(OUT, "f12.png")
    with bpy.context.temp_override(window=window(), area=area, region=main):
        report["operators"]["render"] = {"result": sorted(bpy.ops.render.render(write_still=True))}
    log(f"render: {report['operators']['render']}")
    report["camera_type_after_render"] = camera.data.type
    yield 2.0  # the add-on's notice timer shows its popup
    report["popups"] = list(_popups)
    yield from draw_and_shoot("08_after_f12", wait=1.5)

    # 6. Still set up: Method switched to Exact Camera (kept on Apparent Geometry, and said why), and
    #    a moving light (rendered at rest, and said why); then both taken back.
    _popups.clear()
    scene.relativity.method = "CAMERA"
    yield 2.0  # the handlers sync, the notice timer shows the popup
    report["switch_popups"] = list(_popups)
    report["method_after_switch"] = scene.relativity.method
    yield from draw_and_shoot("09_method_switched")
    scene.relativity.method = "GEOMETRY"
    data = bpy.data.lights.new("Lamp", "POINT")
    lamp = bpy.data.objects.new("Lamp", data)
    lamp.location = (0.0, 2.0, -4.0)
    scene.collection.objects.link(lamp)
    lamp.relativity.motion = "CONSTANT"
    lamp.relativity.beta = (0.3, 0.0, 0.0)
    select_only(lamp)
    yield from draw_and_shoot("10_moving_light")
    bpy.data.objects.remove(lamp)
    bpy.data.lights.remove(data)
    select_only(sphere)
    yield 1.0

    # 6b. The sphere's own velocity set towards the camera (as the panel's field does) under a short
    #     Clip End: the window's redraws evaluate it, and the panel names the Clip End it needs (the
    #     evaluated bounds, taken by the depsgraph update after the callback: pipeline/settled.py).
    camera.data.clip_end = 30.0
    yield from draw_and_shoot("10b_clip_end_short")
    sphere.relativity.beta = (0.0, 0.0, 0.9)
    yield from draw_and_shoot("10c_towards_camera")
    # 6c. Dragged back (a second change: that mesh and the stages only, effect.velocity_changed): the
    #     warning goes with the speed once the window's redraw evaluates it.
    sphere.relativity.beta = gui_scene.SPHERE_BETA
    yield from draw_and_shoot("10d_velocity_back")
    camera.data.clip_end = 1000.0
    yield 1.0

    # 7. Remove from the button: the scene as before Set Up.
    call("remove", bpy.ops.relativity.remove_all)
    report["after_remove"] = {
        "modifiers": [m.name for m in sphere.modifiers],
        "objects": sorted(o.name for o in bpy.data.objects),
    }
    yield from draw_and_shoot("11_removed")


_steps = None


def tick():
    global _steps
    try:
        if _steps is None:
            _steps = steps()
        return next(_steps)
    except StopIteration:
        report["finished"] = True
    except Exception:  # noqa: BLE001 - reported to the test, then Blender quits
        report["driver_error"] = traceback.format_exc()
        print("gui-driver: FAILED\n" + report["driver_error"], flush=True)
    with open(os.path.join(OUT, "report.json"), "w") as file:
        json.dump(report, file, indent=1)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(tick, first_interval=1.0)
