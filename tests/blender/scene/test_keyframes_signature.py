"""``animation.keyframes_signature``, the key under which the keyframed motion's evaluated samples
are kept (``geometry/keyframed.py``): what moves an object enters it (its keys, the values of the
channels no key animates, its parent's), and what a frame step changes does not (the values
Blender evaluated from the keys at the frame). Issue 26: with the current values in it, every frame
step of 1,000 keyframed objects looked like a keyframe edit and evaluated every sample again."""

import pytest


@pytest.fixture
def animation(relativity_addon, factory_blender):
    import importlib

    return importlib.import_module(f"{relativity_addon}.blender.scene.animation")


def _keyed(bpy, name, parent=None):
    obj = bpy.data.objects.new(name, None)
    bpy.context.scene.collection.objects.link(obj)
    obj.parent = parent
    for frame, x, angle in ((1, 0.0, 0.0), (40, 3.0, 0.5)):
        obj.location.x = x
        obj.rotation_euler.z = angle
        obj.keyframe_insert("location", index=0, frame=frame)
        obj.keyframe_insert("rotation_euler", index=2, frame=frame)
    return obj


def test_a_frame_step_keeps_the_signature_and_a_key_edit_changes_it(animation, factory_blender):
    bpy = factory_blender
    scene = bpy.context.scene
    parent = _keyed(bpy, "Parent")
    child = _keyed(bpy, "Child", parent)
    scene.frame_set(5)
    before = animation.keyframes_signature(child)
    x_before = child.location.x

    scene.frame_set(17)

    assert child.location.x != x_before, "the frame step moved the keyed channel"
    assert animation.keyframes_signature(child) == before, "a frame step changed no key"

    child.location.y = 2.0  # a channel no key animates: its value is the motion
    assert animation.keyframes_signature(child) != before
    child.location.y = 0.0
    assert animation.keyframes_signature(child) == before
    parent.keyframe_insert("location", index=0, frame=60)  # a key of the parent at its value at 17
    assert animation.keyframes_signature(child) != before


def test_f_curve_modifiers_settings_enter_the_signature(animation, factory_blender):
    """A curve with modifiers gave no signature (None), so a cache keyed on it held its value when a
    modifier's settings were edited: their settings are in it now, an envelope's points too."""
    bpy = factory_blender
    obj = _keyed(bpy, "Noisy")
    curve = next(c for c in animation.compat.action_fcurves(obj.animation_data) if c.data_path == "location")
    noise = curve.modifiers.new("NOISE")
    envelope = curve.modifiers.new("ENVELOPE")
    point = envelope.control_points.add(10)
    point.min, point.max = -1.0, 1.0
    before = animation.keyframes_signature(obj)
    assert before is not None
    noise.strength = 2.5
    assert animation.keyframes_signature(obj) != before
    noise.strength = 1.0
    assert animation.keyframes_signature(obj) == before
    point.max = 2.0
    assert animation.keyframes_signature(obj) != before
    point.max = 1.0
    envelope.show_expanded = not envelope.show_expanded  # the panel's state moves nothing
    assert animation.keyframes_signature(obj) == before
