"""What the user hears from the add-on outside its operators: nothing on the console from a scene
never set up (the handlers sync every scene), and, for a set-up scene whose render is refused
(speed above c after Set Up, then F12), the reason where the UI shows it: the panel, and a popup
after the render when Blender has a window."""

import pipeline_helpers as wh
from relativity_addon.blender.common import compat


def _relativity_lines(capfd):
    out, err = capfd.readouterr()
    return [line for line in (out + err).splitlines() if "Relativity" in line]


def test_a_scene_never_set_up_prints_nothing(relativity_addon, factory_blender, capfd):
    """The factory default scene (EEVEE, a cube) without a camera: editing it and changing frames
    prints no line, though its problems are still computed for the panel."""
    bpy = factory_blender
    scene = bpy.context.scene
    scene.render.engine = compat.eevee_engine()
    mesh = bpy.data.meshes.new("Cube")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    cube = bpy.data.objects.new("Cube", mesh)
    scene.collection.objects.link(cube)
    bpy.context.view_layer.update()
    capfd.readouterr()
    for _ in range(5):
        cube.location.x += 1.0
        bpy.context.view_layer.update()
    for frame in (2, 3, 1):
        scene.frame_set(frame)
    scene.relativity.beta = (0.0, 0.0, -0.5)  # a setting changed in the panel, still not set up
    bpy.context.view_layer.update()
    assert _relativity_lines(capfd) == []
    effect = _effect(bpy)
    assert effect.scene_warnings(scene)  # the panel still says why Set Up is not possible


def _effect(bpy):
    import importlib

    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.pipeline.effect")


def _module(bpy, name):
    import importlib

    package = type(bpy.context.scene.relativity).__module__.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.{name}")


def test_a_set_up_scene_still_says_why_on_the_console(relativity_addon, factory_blender, capfd):
    bpy = factory_blender
    scene, _, _ = wh.new_scene(bpy, samples=1)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    capfd.readouterr()
    scene.relativity.beta = (0.0, 0.0, -1.2)
    assert any("must be below 1" in line for line in _relativity_lines(capfd))


def test_a_refusal_repeated_by_later_syncs_is_printed_once(relativity_addon, factory_blender, capfd):
    """Every edit syncs again; the same refusal at each of them was printed each time (seven lines
    for one instancing problem). Once per change of what is refused; a new reason is printed."""
    bpy = factory_blender
    scene, _, _ = wh.new_scene(bpy, samples=1)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    capfd.readouterr()
    scene.relativity.beta = (0.0, 0.0, -1.2)
    for frame in (2, 3, 4):  # later edits and frame changes, still faster than light
        scene.frame_set(frame)
        bpy.context.view_layer.update()
    lines = _relativity_lines(capfd)
    assert len([line for line in lines if "must be below 1" in line]) == 1, lines
    scene.relativity.beta = (0.0, 0.0, -2.0)  # another value: said again
    assert any("must be below 1" in line for line in _relativity_lines(capfd))


def _set_up_then_faster_than_light(bpy):
    scene, _, _ = wh.new_scene(bpy, samples=1)
    scene.relativity.beta = (0.0, 0.0, -0.5)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    scene.relativity.beta = (0.0, 0.0, -1.2)
    return scene


def test_f12_refused_after_set_up_is_shown_in_the_panel(relativity_addon, factory_blender):
    """F12 is Blender's operator: it finishes, the exact camera renders black; the panel says why,
    and in background mode no popup is queued (the batch script exits 1 instead)."""
    from test_ui_workflow import draw_panel

    bpy = factory_blender
    notice = _module(bpy, "pipeline.render_notice")
    scene = _set_up_then_faster_than_light(bpy)
    assert notice.last_refusal(scene) is None
    assert bpy.ops.render.render() == {"FINISHED"}
    assert "must be below 1" in notice.last_refusal(scene)
    assert notice._pending.empty()
    assert notice._popup("title", "reason") is None  # no window in background: nothing to show it in
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert any(
        e[0] == "label" and e[2] == "ERROR" and e[1].startswith("Last render refused: ") and "must be below 1" in e[1]
        for e in log
    ), log

    scene.relativity.beta = (0.0, 0.0, -0.5)
    assert bpy.ops.render.render() == {"FINISHED"}
    assert notice.last_refusal(scene) is None
    log = draw_panel(bpy, "RELATIVITY_PT_main", scene)
    assert not any(e[0] == "label" and e[1].startswith("Last render refused") for e in log)


def test_f12_refused_pops_up_after_the_render_with_a_window(relativity_addon, factory_blender, monkeypatch):
    """With a window (not background), the render thread queues the notice and the main-thread
    timer shows it once as a popup; the timer is registered only then."""
    bpy = factory_blender
    notice = _module(bpy, "pipeline.render_notice")
    assert not bpy.app.timers.is_registered(notice.show_pending)  # background: no timer
    shown = []
    monkeypatch.setattr(notice, "_background", lambda: False)
    monkeypatch.setattr(notice, "_popup", lambda title, reason: shown.append((title, reason)))
    notice.register()
    try:
        assert bpy.app.timers.is_registered(notice.show_pending)
        _set_up_then_faster_than_light(bpy)
        assert bpy.ops.render.render() == {"FINISHED"}
        assert bpy.ops.render.render() == {"FINISHED"}
        assert shown == []  # nothing from the render thread itself
        assert notice.show_pending() == notice.POLL_SECONDS
        assert len(shown) == 1, shown
        title, reason = shown[0]
        assert title == "Relativity: this render is black" and "must be below 1" in reason
        assert notice.show_pending() == notice.POLL_SECONDS and len(shown) == 1
    finally:
        notice.unregister()
    assert not bpy.app.timers.is_registered(notice.show_pending)


def test_an_ordinary_render_of_a_scene_never_set_up_queues_nothing(relativity_addon, factory_blender, monkeypatch):
    bpy = factory_blender
    notice = _module(bpy, "pipeline.render_notice")
    monkeypatch.setattr(notice, "_background", lambda: False)
    scene, _, _ = wh.new_scene(bpy, samples=1)
    scene.relativity.beta = (0.0, 0.0, -1.2)
    assert bpy.ops.render.render() == {"FINISHED"}
    assert notice.last_refusal(scene) is None and notice._pending.empty()
