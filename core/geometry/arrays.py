"""The numpy array types the kernels' signatures use: one definition for every module.

These are plain :class:`numpy.typing.NDArray` aliases for type hints; the validated array
fields of the entity models are :mod:`geobrep.model.arrays`.

>>> import numpy as np
>>> faces: IntArray = np.zeros((0, 3), dtype=np.int64)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["BoolArray", "FloatArray", "IntArray", "UIntArray"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
UIntArray = NDArray[np.uint64]
BoolArray = NDArray[np.bool_]
