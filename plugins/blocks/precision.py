"""The precision the coordinates carry, and the weld/conformity tolerance that follows from it.

Files store coordinates rounded somehow: to float32 (older software, many VTK files), to a number
of significant digits or decimals (text formats), or at full float64 precision. Two copies of a
point, or a vertex meant to lie on another surface, can then be off by up to the **quantum** of
that rounding, so the builder's default tolerance is a few quanta — not a fixed share of the
model size, which is too coarse for float64 data (it calls sub-millimetre details of a 20 km model
touching) and too fine for float32 data far from the origin (half a metre at UTM northings).

Files round every coordinate the same way, so the quantum is measured as the coarsest of these
descriptions that holds for every coordinate (each family's grids nest: they are tried from the
finest up on a sample, and the coarsest the sample fits is confirmed on all values):

* **float32** — every value is exactly a float32: the float32 spacing at the largest magnitude;
* **k decimals** — every value is within two float64 ulps (of the largest magnitude) of its
  rounding to ``k`` decimals (``k`` from −6): ``10^-k``;
* **s significant digits** — every value is within two float64 ulps of its rounding to ``s``
  significant digits: one unit of the ``s``-th digit of the largest magnitude;
* none (or only descriptions finer than 32 float64 ulps of the largest magnitude): **float64**,
  the float64 spacing there.

Values on a grid are on every finer grid too: the coarsest grid they all fit is the most
rounding they may have had (UTM coordinates in float32 carry 0.5 m: the spacing at their
northings). The tolerance is :data:`QUANTA` quanta (a vertex and an edge, each off by half a
quantum per axis, stay within ``√3`` quanta), kept between :data:`FLOOR` and :data:`CEILING`
times the bounding-box diagonal: the floor leaves room for arithmetic noise in float64 data, the
ceiling keeps coordinates lying on a coarse grid by construction (integers, quarter units) from
reading as heavily rounded data.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import FloatArray

__all__ = ["CEILING", "FLOOR", "QUANTA", "Precision", "data_tolerance", "measure_precision"]


#: Tolerance in quanta of the data's precision.
QUANTA = 4.0
#: Bounds of the data-derived tolerance, relative to the bounding-box diagonal.
FLOOR = 1e-9
CEILING = 1e-4
#: Most significant digits tested (float64 holds 15.9).
_MAX_DIGITS = 16
#: Coordinates tried first, to find the candidate description cheaply.
_SAMPLE = 4096

Test = Callable[[FloatArray], bool]


@dataclass(frozen=True)
class Precision:
    """The rounding quantum of a set of coordinates and what it was read from."""

    quantum: float
    source: str  # "float32", "8 significant digits", "float64"


def _float32(largest: float) -> tuple[float, Test]:
    def holds(v: FloatArray) -> bool:
        return bool(np.array_equal(v.astype(np.float32).astype(np.float64), v))

    return float(np.spacing(np.float32(largest))), holds


def _digits(largest: float, digits: int) -> tuple[float, Test]:
    top = np.floor(np.log10(largest))

    def holds(v: FloatArray) -> bool:
        size = np.abs(v)
        scale = np.power(10.0, digits - 1 - np.floor(np.log10(np.where(size > 0.0, size, 1.0))))
        return bool(np.all(np.abs(v - np.rint(v * scale) / scale) <= 2.0 * np.spacing(np.abs(v))))

    return float(10.0 ** (top - digits + 1)), holds


def _decimals(decimals: int, slack: float) -> tuple[float, Test]:
    def holds(v: FloatArray) -> bool:
        scaled = v * 10.0**decimals
        return bool(np.abs(scaled - np.rint(scaled)).max() <= slack * 10.0**decimals)

    return 10.0**-decimals, holds


def measure_precision(coordinates: FloatArray) -> Precision:
    """The rounding quantum the coordinates carry (see the module docstring).

    >>> import numpy as np
    >>> points = np.random.default_rng(0).random((1000, 3)) * [2e4, 2e4, 1e3] + [45e4, 67e5, 0]
    >>> measure_precision(points).source
    'float64'
    >>> measure_precision(np.round(points, 2))
    Precision(quantum=0.01, source='2 decimals')
    >>> measure_precision(points.astype(np.float32).astype(np.float64))  # northings: 0.5 m
    Precision(quantum=0.5, source='float32')
    """
    values = np.asarray(coordinates, dtype=np.float64).reshape(-1)
    largest = max(float(values.max(initial=0.0)), -float(values.min(initial=0.0)))
    if largest == 0.0:
        return Precision(0.0, "float64")
    step = max(1, values.size // _SAMPLE)
    sample = values[:: step + 1 if step % 3 == 0 else step]  # every axis in the sample
    # Decimals finer than 32 float64 ulps of the largest value cannot be told from float64.
    finest = 32.0 * float(np.spacing(largest))
    most = int(np.floor(-np.log10(finest)))
    slack = 2.0 * float(np.spacing(largest))
    # Each family's grids nest (a value on one is on every finer one): from the finest up.
    families = [
        [(*_float32(largest), "float32")],
        [(*_decimals(k, slack), f"{k} decimals") for k in range(most, -7, -1)],
        [(*_digits(largest, d), f"{d} significant digits") for d in range(_MAX_DIGITS, 0, -1)],
    ]
    found: list[Precision] = []
    for family in families:
        grids = [grid for grid in family if grid[0] > finest]
        fits = 0
        while fits < len(grids) and grids[fits][1](sample):
            fits += 1
        best = max((p.quantum for p in found), default=0.0)
        if fits and grids[fits - 1][0] <= best:
            continue  # cannot be coarser than what another family confirmed
        while fits > 0 and not grids[fits - 1][1](values):
            fits -= 1
        if fits:
            quantum, _, source = grids[fits - 1]
            found.append(Precision(quantum, source))
    if found:
        return max(found, key=lambda p: p.quantum)
    return Precision(float(np.spacing(largest)), "float64")


def data_tolerance(precision: Precision, diagonal: float) -> float:
    """:data:`QUANTA` quanta of ``precision``, kept within [:data:`FLOOR`, :data:`CEILING`] ×
    ``diagonal``.

    >>> data_tolerance(Precision(0.5, "float32"), 28_000.0)
    2.0
    >>> data_tolerance(Precision(1e-12, "float64"), 1000.0) == 1e-9 * 1000.0  # the floor
    True
    """
    return float(min(max(QUANTA * precision.quantum, FLOOR * diagonal), CEILING * diagonal))
