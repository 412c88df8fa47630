"""Parameters and knot vectors: chord length, averaging, approximation knots, knot insertion.

Piegl & Tiller, *The NURBS Book*, §9.2 (eq. 9.5, 9.8, 9.68-9.69) and A5.1 (knot insertion).

>>> import numpy as np
>>> averaged_knots(2, np.array([0.0, 0.25, 0.5, 1.0])).tolist()
[0.0, 0.0, 0.0, 0.375, 1.0, 1.0, 1.0]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray

__all__ = [
    "approximation_knots",
    "averaged_knots",
    "chord_parameters",
    "insert_knots",
    "merge_knots",
    "missing_knots",
    "uniform_knots",
]


def chord_parameters(
    points: FloatArray, *, centripetal: bool = False, label: str = "row"
) -> FloatArray:
    """Chord-length (or centripetal) parameters of ordered points, normalised to ``[0, 1]``.

    Raises:
        DegenerateGeometryError: two consecutive points coincide, or all points do.
    """
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    if centripetal:
        steps = np.sqrt(steps)
    total = float(steps.sum())
    scale = float(np.abs(points).max(initial=0.0)) or 1.0
    if total <= 1e-12 * scale or np.any(steps <= 1e-12 * total):
        where = int(np.argmin(steps)) if steps.size else 0
        raise DegenerateGeometryError(
            f"{label}: points {where} and {where + 1} coincide; remove duplicate points "
            "before interpolating"
        )
    params = np.concatenate([[0.0], np.cumsum(steps) / total])
    params[-1] = 1.0
    return params


def averaged_knots(degree: int, params: FloatArray) -> FloatArray:
    """Clamped knots for interpolation at ``params`` by averaging (eq. 9.8)."""
    n = params.shape[0]
    if n - degree - 1 <= 0:
        inner = np.zeros(0)
    else:
        windows = np.lib.stride_tricks.sliding_window_view(params[1:-1], degree)
        inner = windows.mean(axis=1)[: n - degree - 1]
    return np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])


def approximation_knots(degree: int, n_ctrl: int, params: FloatArray) -> FloatArray:
    """Clamped knots for least squares with ``n_ctrl`` control points (eq. 9.68-9.69)."""
    m = params.shape[0]
    n_inner = n_ctrl - degree - 1
    if n_inner <= 0:
        return np.concatenate([np.zeros(degree + 1), np.ones(degree + 1)])
    d = m / (n_ctrl - degree)
    j = np.arange(1, n_inner + 1)
    i = np.floor(j * d).astype(np.int64)
    alpha = j * d - i
    inner = (1.0 - alpha) * params[np.clip(i - 1, 0, m - 1)] + alpha * params[np.clip(i, 0, m - 1)]
    return np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])


def uniform_knots(degree: int, n_spans: int, start: float = 0.0, end: float = 1.0) -> FloatArray:
    """Clamped uniform knots with ``n_spans`` spans on ``[start, end]``."""
    inner = np.linspace(start, end, n_spans + 1)[1:-1]
    return np.concatenate([np.full(degree + 1, start), inner, np.full(degree + 1, end)])


def _group(values: FloatArray, tolerance: float) -> tuple[FloatArray, NDArray[np.int64]]:
    """Distinct values of a sorted array (closer than ``tolerance`` count as one) and counts."""
    if values.size == 0:
        return values, np.zeros(0, dtype=np.int64)
    starts = np.r_[0, np.flatnonzero(np.diff(values) > tolerance) + 1]
    counts = np.diff(np.r_[starts, values.shape[0]])
    return values[starts], counts.astype(np.int64)


def _multiplicities(
    representatives: FloatArray, vector: FloatArray, tolerance: float
) -> NDArray[np.int64] | None:
    """How often each representative occurs in ``vector``; None if ``vector`` has other values."""
    index = np.clip(np.searchsorted(representatives, vector - tolerance), 0, None)
    index = np.minimum(index, representatives.shape[0] - 1)
    if not bool(np.all(np.abs(representatives[index] - vector) <= tolerance)):
        return None
    return np.bincount(index, minlength=representatives.shape[0]).astype(np.int64)


def merge_knots(vectors: list[FloatArray], tolerance: float = 1e-12) -> FloatArray:
    """The union of knot vectors on one domain: every value with its largest multiplicity.

    Values closer than ``tolerance`` count as equal (they come from the same normalisation).

    >>> a, b = np.array([0.0, 0.0, 0.5, 1.0, 1.0]), np.array([0.0, 0.0, 0.25, 1.0, 1.0])
    >>> merge_knots([a, b]).tolist()
    [0.0, 0.0, 0.25, 0.5, 1.0, 1.0]
    """
    representatives, _ = _group(np.sort(np.concatenate(vectors)), tolerance)
    multiplicity = np.zeros(representatives.shape[0], dtype=np.int64)
    for vector in vectors:
        counts = _multiplicities(representatives, np.sort(vector), tolerance)
        assert counts is not None  # every value of vector is a representative
        multiplicity = np.maximum(multiplicity, counts)
    return np.repeat(representatives, multiplicity)


def missing_knots(
    target: FloatArray, have: FloatArray, tolerance: float = 1e-12
) -> FloatArray | None:
    """The knots of ``target`` that ``have`` lacks (as multisets), or None if ``have ⊄ target``.

    >>> fine = np.array([0.0, 0.0, 0.25, 0.5, 1.0, 1.0])
    >>> missing_knots(fine, np.array([0.0, 0.0, 0.5, 1.0, 1.0])).tolist()
    [0.25]
    """
    representatives, counts = _group(np.sort(target), tolerance)
    used = _multiplicities(representatives, np.sort(have), tolerance)
    if used is None or bool(np.any(used > counts)):
        return None
    return np.repeat(representatives, counts - used)


def insert_knots(
    degree: int, knots: FloatArray, control_points: FloatArray, new_knots: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Insert ``new_knots`` into a B-spline (A5.1 applied once per knot; the curve is unchanged).

    ``control_points`` is ``(n, d)``; returns the refined knots and control points.
    """
    knots = np.asarray(knots, dtype=np.float64)
    points = np.asarray(control_points, dtype=np.float64)
    p = degree
    for t in np.sort(np.asarray(new_knots, dtype=np.float64)):
        n_ctrl = knots.shape[0] - p - 1
        k = int(np.searchsorted(knots, t, side="right")) - 1
        k = min(max(k, p), n_ctrl - 1)
        i = np.arange(k - p + 1, k + 1)
        denom = knots[i + p] - knots[i]
        alpha = np.where(denom > 0, (t - knots[i]) / np.where(denom > 0, denom, 1.0), 0.0)
        middle = alpha[:, None] * points[i] + (1.0 - alpha[:, None]) * points[i - 1]
        points = np.concatenate([points[: k - p + 1], middle, points[k:]])
        knots = np.concatenate([knots[: k + 1], [t], knots[k + 1 :]])
    return knots, points
