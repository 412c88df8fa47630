"""Casting values read from (or written to) a file to another dtype only when every value fits.

``numpy.astype`` wraps, truncates and turns NaN into garbage without a word (``int8`` of
``(nan, 1e10, 300)`` is ``(0, 0, 44)``). Every adapter that converts file data to a declared
dtype goes through :func:`cast_exactly`, which converts only when the conversion loses nothing
and otherwise names the first value that does not fit.

>>> import numpy as np
>>> cast_exactly(np.array([1.0, 2.0]), "int8", "column 'v'").tolist()
[1, 2]
>>> cast_exactly(np.array([1.0, 300.0]), "int8", "column 'v'", "a.csv")
Traceback (most recent call last):
...
geobrep.errors.FormatError: a.csv: column 'v': row 1 holds 300.0, which does not fit int8
"""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np
from numpy.typing import DTypeLike, NDArray

from geobrep.errors import FormatError

__all__ = ["cast_exactly", "misfit_rows"]


def misfit_rows(values: NDArray[Any], dtype: DTypeLike) -> NDArray[np.bool_]:
    """Per row (first axis), True where some value changes when cast to ``dtype`` and back.

    NaN fits a float dtype; it fits no integer or boolean dtype. Non-numeric values fit nothing.
    """
    target = np.dtype(dtype)
    array = np.asarray(values)
    if array.dtype == target:
        return np.zeros(array.shape[:1], dtype=bool)
    if array.dtype.kind not in "biuf" or target.kind not in "biuf":
        return np.ones(array.shape[:1], dtype=bool)
    with np.errstate(invalid="ignore", over="ignore"):
        back = array.astype(target).astype(array.dtype)
    fits = back == array
    if target.kind in "iu" and array.dtype.kind in "iu":  # same width: a wrap comes back intact
        info = np.iinfo(target)
        fits &= (array >= info.min) & (array <= info.max)
    if array.dtype.kind == "f":
        if target.kind == "f":
            fits |= np.isnan(array) & np.isnan(back)
        else:  # NaN and inf have no integer: their cast can land back on any value
            fits &= np.isfinite(array)
    if fits.ndim > 1:
        fits = fits.all(axis=tuple(range(1, fits.ndim)))
    misfits: NDArray[np.bool_] = ~fits
    return misfits


def cast_exactly(
    values: NDArray[Any],
    dtype: DTypeLike,
    what: str,
    path: str | PathLike[str] | None = None,
) -> NDArray[Any]:
    """``values`` as ``dtype``; :class:`FormatError` naming ``what`` and the first row holding a
    value that does not fit (the array itself when it already has that dtype)."""
    target = np.dtype(dtype)
    array = np.asarray(values)
    if array.dtype == target:
        return array
    bad = misfit_rows(array, target)
    if bad.any():
        row = int(np.argmax(bad))
        shown = array[row].tolist() if array.ndim else array.item()
        raise FormatError(f"{what}: row {row} holds {shown!r}, which does not fit {target}", path)
    return array.astype(target)
