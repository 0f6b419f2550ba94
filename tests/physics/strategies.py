"""Hypothesis strategies shared by the physics tests."""

import numpy as np
from hypothesis import strategies as st

finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)
vectors = st.tuples(finite, finite, finite).map(np.array)


def _direction(values):
    v = np.array(values)
    return v / np.linalg.norm(v)


directions = (
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
    .filter(lambda v: np.linalg.norm(v) > 0.1)
    .map(_direction)
)


@st.composite
def velocities(draw, max_speed=0.999):
    """Velocities as fractions of c, |beta| <= max_speed, including zero."""
    direction = draw(directions)
    speed = draw(st.floats(min_value=0.0, max_value=max_speed))
    return speed * direction


speeds_of_light = st.sampled_from([1.0, 3.0, 299792458.0])
