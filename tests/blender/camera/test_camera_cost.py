"""The exact camera at rest runs what a minimal OSL camera runs per camera sample, and no more
(issue 26: the exact camera on its floor).

Counted on the code Cycles runs: OSL's runtime optimiser folds the shader's parameters (constant
for a render) before compiling it, and prints what is left with ``OSL_OPTIONS=debug=2``
(``tools/osl_camera_ops.py``, a fresh Blender process per count). A count does not depend on the
machine's load; ``benchmarks/panorama_overhead.py`` measures the render times beside it.
"""

import collections

import pytest
from osl_camera_ops import optimised_camera_ops, work_ops


@pytest.mark.parametrize("projection", ["PERSP", "EQUIRECTANGULAR"])
def test_exact_camera_at_rest_runs_no_more_than_the_minimal_camera(projection):
    minimal = work_ops(optimised_camera_ops(projection, "minimal"))
    exact = work_ops(optimised_camera_ops(projection, "exact"))
    assert minimal["compref"] == 2, minimal  # the raster position was read: the listing parsed
    assert exact - minimal == collections.Counter(), (
        f"the exact camera at rest runs more than the minimal camera: {dict(exact - minimal)} "
        f"(exact {dict(exact)}, minimal {dict(minimal)})"
    )


def test_a_moving_camera_runs_the_lorentz_transformation():
    """The count follows the parameters: at 0.5c the aberration (a normalised transformed
    direction, Gray eq. 2) and the Doppler factor are computed per sample."""
    minimal = work_ops(optimised_camera_ops("PERSP", "minimal"))
    moving = work_ops(optimised_camera_ops("PERSP", "exact", beta=(0.0, 0.5, 0.0)))
    extra = moving - minimal
    assert extra["normalize"] >= 1 and extra["dot"] >= 1, dict(moving)
