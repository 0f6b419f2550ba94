"""Type aliases for the physics core's signatures (numpy arrays in, float64 arrays out)."""

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
Float32Array = npt.NDArray[np.float32]
IndexArray = npt.NDArray[np.integer[Any]]
BoolArray = npt.NDArray[np.bool_]

# A function of wavelength (array) returning a spectral quantity of the same shape.
Spectrum = Callable[[FloatArray], ArrayLike]
# world_line(t, index): positions (M, 3) of the points numbered index (M,) at times t (M,).
WorldLine = Callable[[FloatArray, IndexArray], ArrayLike]
