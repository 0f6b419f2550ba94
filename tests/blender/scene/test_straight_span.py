"""``animation.straight_span`` (issue 26: keyframed motion on straight keys without reading a key at
every frame step): read once around a frame, it must give what ``animation.straight_keys`` gives for
every window of positive length inside the span, and nothing beyond it (a window crossing either end
meets another line, a Bezier segment or a held value, where ``straight_keys`` gives another answer)."""

import importlib

import numpy as np
import pytest


@pytest.fixture
def modules(relativity_addon, factory_blender):
    return (
        importlib.import_module(f"{relativity_addon}.blender.scene.animation"),
        importlib.import_module(f"{relativity_addon}.blender.common.compat"),
    )


def _mover(bpy, compat):
    """x: held before -30, linear to 10 and (faster) to 40, Bezier to 70, held after; y: one linear
    segment from -100 to 100, held outside; z: not animated; a rotation key (held)."""
    obj = bpy.data.objects.new("Mover", None)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = (0.0, 0.0, 1.25)
    for frame, x in ((-30, 1.0), (10, 3.0), (40, 12.0), (70, 20.0)):
        obj.location.x = x
        obj.keyframe_insert("location", index=0, frame=frame)
    for frame, y in ((-100, -2.0), (100, 6.0)):
        obj.location.y = y
        obj.keyframe_insert("location", index=1, frame=frame)
    obj.rotation_euler.z = 0.4
    obj.keyframe_insert("rotation_euler", index=2, frame=1)
    for curve in compat.action_fcurves(obj.animation_data):
        for index, point in enumerate(curve.keyframe_points):
            point.interpolation = "BEZIER" if curve.array_index == 0 and index == 2 else "LINEAR"
    return obj


def test_straight_span_answers_straight_keys_inside_and_not_beyond(modules, factory_blender):
    animation, compat = modules
    obj = _mover(factory_blender, compat)
    rng = np.random.default_rng(7)
    spans = {}
    for frame in (-150.0, -60.0, -5.0, 25.0, 55.0, 90.0, 150.0):
        span = animation.straight_span(obj, frame)
        spans[frame] = None if span is None else (span[2], span[3])
        if span is None:  # around frame 55 the x keys are Bezier: no line
            assert animation.straight_keys(obj, frame - 0.5, frame + 0.5) is None
            continue
        start, rate, low, high = span
        for _ in range(20):  # windows inside the span (clipped to +-300 frames)
            a, b = np.sort(rng.uniform(max(low, -300.0), min(high, 300.0), 2))
            line = animation.straight_keys(obj, a, b)
            assert line is not None, (frame, a, b)
            assert np.array_equal(line[0], start) and np.array_equal(line[1], rate)
        for end in (low, high):  # a window across an end: another answer
            if np.isfinite(end):
                other = animation.straight_keys(obj, end - 1.0, end + 1.0)
                assert other is None or not (np.array_equal(other[0], start) and np.array_equal(other[1], rate))
    assert spans == {
        -150.0: (-np.inf, -100.0),
        -60.0: (-100.0, -30.0),
        -5.0: (-30.0, 10.0),
        25.0: (10.0, 40.0),
        55.0: None,
        90.0: (70.0, 100.0),
        150.0: (100.0, np.inf),
    }
