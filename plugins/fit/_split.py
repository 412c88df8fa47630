"""Split survey points into the dense, even core and the sparse rim.

By a point property (a flag), by a polygon, or automatically from point density: the distance to
the k-th nearest neighbour separates into two classes (Otsu's threshold on its logarithm); the
largest connected cluster of dense points spans the core region (its convex hull), and every
point inside that region belongs to the core.

>>> import numpy as np
>>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
>>> inside_polygon(np.array([[0.5, 0.5], [2.0, 0.5]]), square).tolist()
[True, False]
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError, cKDTree

from geobrep import PointSet
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import BoolArray, FloatArray

__all__ = [
    "core_by_density",
    "core_by_property",
    "inside_polygon",
    "otsu_threshold",
    "point_roles",
]


def inside_polygon(xy: FloatArray, polygon: FloatArray) -> BoolArray:
    """Even-odd test of points ``(n, 2)`` against a closed polygon ``(k, 2)`` (vectorised)."""
    a = polygon
    b = np.roll(polygon, -1, axis=0)
    inside = np.zeros(xy.shape[0], dtype=bool)
    for start in range(0, xy.shape[0], 4096):
        x = xy[start : start + 4096, 0][:, None]
        y = xy[start : start + 4096, 1][:, None]
        crosses = (a[None, :, 1] > y) != (b[None, :, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (
                b[None, :, 1] - a[None, :, 1]
            )
        inside[start : start + 4096] = (np.count_nonzero(crosses & (x < at), axis=1) % 2) == 1
    return inside


def core_by_property(points: PointSet | None, name: str) -> BoolArray:
    """Core flags from a point property (non-zero = core)."""
    if points is None or name not in points.point_data:
        available = sorted(points.point_data) if points is not None else []
        raise OptionsError(
            f"fitter 'hybrid': option 'core_property': the points have no property {name!r} "
            f"(they have: {', '.join(available) or 'none'})"
        )
    values = np.asarray(points.point_data[name].values)
    if values.ndim != 1:
        raise OptionsError(
            f"fitter 'hybrid': option 'core_property': {name!r} is not a scalar property"
        )
    return np.asarray(values != 0)


def point_roles(
    points: PointSet | None, n_points: int, weight: str | None, exact: str | None, label: str
) -> tuple[FloatArray | None, BoolArray | None]:
    """Per-point weights and hard-data flags from the options ``weight_property`` and
    ``exact_property`` (None where the option is not given)."""
    weights = None
    if weight is not None:
        weights = _scalar(points, n_points, weight, "weight_property", label).astype(np.float64)
        if not (np.isfinite(weights).all() and (weights >= 0).all()):
            raise OptionsError(
                f"{label}: option 'weight_property': {weight!r} holds a weight that is negative "
                "or not finite"
            )
    flags = None
    if exact is not None:
        flags = _scalar(points, n_points, exact, "exact_property", label) != 0
    return weights, flags


def _scalar(
    points: PointSet | None, n_points: int, name: str, option: str, label: str
) -> NDArray[Any]:
    if points is None or name not in points.point_data:
        available = sorted(points.point_data) if points is not None else []
        raise OptionsError(
            f"{label}: option {option!r}: the points have no property {name!r} "
            f"(they have: {', '.join(available) or 'none'})"
        )
    values = np.asarray(points.point_data[name].values)
    if values.ndim != 1 or values.shape[0] != n_points:
        raise OptionsError(
            f"{label}: option {option!r}: {name!r} is not one number per point of the fit"
        )
    return values


def otsu_threshold(values: FloatArray) -> float:
    """The threshold splitting ``values`` into two classes of maximal between-class variance."""
    v = np.sort(values)
    n = v.shape[0]
    csum = np.cumsum(v)
    k = np.arange(1, n)
    mean_low = csum[:-1] / k
    mean_high = (csum[-1] - csum[:-1]) / (n - k)
    between = k * (n - k) * (mean_low - mean_high) ** 2
    best = int(np.argmax(between))
    return float(0.5 * (v[best] + v[best + 1]))


def core_by_density(ab: FloatArray, k: int = 8) -> BoolArray:
    """Core flags from point density (points ``(n, 2)`` in the best-fit plane).

    Raises:
        DegenerateGeometryError: no clearly denser region (density contrast below 2).
    """
    n = ab.shape[0]
    if n < 2 * k:
        raise DegenerateGeometryError(
            f"fitter 'hybrid': {n} points are too few to find a dense core automatically; give "
            "core_property or core_polygon"
        )
    tree = cKDTree(ab)
    distance, _ = tree.query(ab, k=k + 1)
    radius = np.log(np.maximum(distance[:, k], 1e-300))
    threshold = otsu_threshold(radius)
    dense = radius < threshold
    # density ∝ 1/r², so the contrast between the classes is exp(2 Δ log r)
    contrast = float(np.exp(2.0 * (np.median(radius[~dense]) - np.median(radius[dense]))))
    if contrast < 2.0 or dense.sum() < 4:
        raise DegenerateGeometryError(
            f"fitter 'hybrid': no dense core found (density contrast {contrast:.2f}); give "
            "core_property or core_polygon"
        )
    seeds = np.flatnonzero(dense)
    spacing = float(np.median(tree.query(ab[seeds], k=2)[0][:, 1]))
    pairs = cKDTree(ab[seeds]).query_pairs(2.5 * spacing, output_type="ndarray")
    graph = sp.coo_matrix(
        (np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(seeds.size, seeds.size)
    )
    _, labels = connected_components(graph, directed=False)
    largest = seeds[labels == np.bincount(labels).argmax()]
    try:
        hull = ConvexHull(ab[largest])
    except QhullError as exc:
        raise DegenerateGeometryError(
            "fitter 'hybrid': the dense points are collinear; give core_property or core_polygon"
        ) from exc
    polygon = ab[largest][hull.vertices]
    centre = polygon.mean(axis=0)
    grown = centre + (polygon - centre) * (1.0 + 1e-9)  # keep the hull's own vertices inside
    return inside_polygon(ab, grown)
