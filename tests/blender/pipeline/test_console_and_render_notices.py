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
