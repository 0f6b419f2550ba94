"""Issue 26, F12 on the many-object scene: the render's depsgraph is built from scratch and reports
every object updated, which is no change when an applied mesh's inputs there are the viewport's
(``changes.reported``). F12 with nothing changed since the last sync then takes no mesh's
signature, clip-end depth or note again; a keyed location changed without a key just before F12
(the render's depsgraph evaluates the keys again, so its matrix is not the original's) renders
where the keys put it, as Blender renders it (``handlers._keys_before_render``), computed again
for that mesh alone."""

import numpy as np
from test_geometry_many_objects import _count_work, _done, _scene

import camera_helpers as ch
import geometry_helpers as gh


def test_f12_with_nothing_changed_takes_no_mesh_work_again(relativity_addon, monkeypatch, tmp_path):
    import bpy

    scene, _movers = _scene(bpy, None)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    ch.render_exr(bpy, scene, tmp_path / "f12.exr")  # the first F12 after Set Up (its output settings too)
    work = _count_work(monkeypatch)
    bpy.context.evaluated_depsgraph_get()  # a redraw: Blender tagged the rendered objects' shading
    assert not work["signature"], f"a shading update taken as the meshes' change: {_done(work)}"

    ch.render_exr(bpy, scene, tmp_path / "f12.exr")

    assert not work["signature"] and not work["depth"] and not work["warnings"], _done(work)


def test_keyed_location_changed_without_a_key_before_f12_reaches_the_render(relativity_addon, monkeypatch, tmp_path):
    import bpy

    scene, movers = _scene(bpy, None)
    for obj in movers:
        obj.data.materials.append(gh.coloured_emission(bpy, f"Glow {obj.name}", (1.0, 0.5, 0.2)))
    keyed = movers[3]
    for frame, z in ((1, -6.0), (40, -5.0)):
        keyed.location.z = z
        keyed.keyframe_insert("location", index=2, frame=frame)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    clean = ch.render_exr(bpy, scene, tmp_path / "clean.exr")
    work = _count_work(monkeypatch)

    keyed.location.z = -3.0  # a script (or the user) moves it; no key: the render's frame evaluates the keys
    bpy.context.evaluated_depsgraph_get()  # the viewport follows (and its sync computes the moved mesh)
    moved = keyed.evaluated_get(bpy.context.evaluated_depsgraph_get()).matrix_world.translation.z
    assert abs(moved + 3.0) < 1e-6, "the viewport shows the moved object"
    assert work["update"]["Mover 3"] >= 1, f"the viewport's sync did not follow the move: {_done(work)}"
    bpy.context.evaluated_depsgraph_get()  # its writes evaluated: the next sync finds it current
    for kind in work:
        work[kind].clear()
    tweaked = ch.render_exr(bpy, scene, tmp_path / "tweaked.exr")

    # Blender renders the keyed position (the render evaluates the keys at its frame): the image of
    # the un-keyed scene, the same samples and seed (main: Mover 3 missing, 1.37 % of the pixels).
    assert np.abs(clean).max() > 0.05, "something renders"
    wrong = np.abs(tweaked - clean).max(axis=-1) > 0.02
    assert not wrong.any(), f"{wrong.mean():.2%} of the pixels differ from the render of the keyed position"
    assert work["update"]["Mover 3"] >= 1, f"the render's keyed position was not computed: {_done(work)}"
    assert not {name for counts in work.values() for name in counts} - {"Mover 3"}, _done(work)
