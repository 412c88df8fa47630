"""NURBS skinning (Piegl & Tiller §10.3): a surface through ordered sections of points.

Each section (a row of points, or a PolyLine part) is interpolated by a curve of one common
degree; rows with the same number of points share averaged parameters and so one knot vector,
and rows of different counts are made compatible by inserting the union of their knots (knot
insertion does not change a curve). The compatible control polygons are then interpolated across
the sections. The surface passes through every input point: ``S(ū_ki, v_k) = Q_ki``.

Scattered points that form a rough lattice (survey grids, section lines) are sorted into rows
automatically: the lattice direction comes from the nearest-neighbour directions, rows from gaps
in the coordinate across them.

>>> import numpy as np
>>> x, y = np.meshgrid(np.linspace(0, 3, 5), np.linspace(0, 2, 4))
>>> rows = [np.column_stack([x[k], y[k], np.sin(x[k]) + y[k] ** 2]) for k in range(4)]
>>> surface = skin_rows(rows, degree_u=3, degree_v=3)
>>> u, v = surface.row_parameters[1], np.full(5, surface.section_parameters[1])
>>> bool(np.abs(surface.evaluate(u, v) - rows[1]).max() < 1e-12)
True
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.geometry.nurbs import NurbsNet, basis_matrix, surface_points
from geobrep.plugins.fit._curves import BSplineCurve, interpolate_curve
from geobrep.plugins.fit._knots import averaged_knots, chord_parameters, merge_knots

__all__ = ["SkinnedNet", "lattice_angle", "rows_from_lattice", "skin_rows"]


@dataclass(frozen=True)
class SkinnedNet:
    """A skinned B-spline net with the parameters of the points it interpolates.

    ``row_parameters[k]`` are the u parameters of row ``k``'s points, ``section_parameters[k]``
    its v parameter.
    """

    net: NurbsNet
    row_parameters: list[FloatArray]
    section_parameters: FloatArray

    def evaluate(self, u: FloatArray, v: FloatArray) -> FloatArray:
        return surface_points(self.net, u, v)

    def point_parameters(self) -> tuple[FloatArray, FloatArray]:
        """``(u, v)`` of every input point, rows concatenated in order."""
        u = np.concatenate(self.row_parameters)
        v = np.concatenate(
            [
                np.full(len(t), s)
                for t, s in zip(self.row_parameters, self.section_parameters, strict=True)
            ]
        )
        return u, v


def _row_curves(rows: list[FloatArray], degree: int) -> list[BSplineCurve]:
    """Interpolate each row; rows of equal count share averaged parameters and knots."""
    params = [chord_parameters(row, label=f"row {k}") for k, row in enumerate(rows)]
    counts = np.array([len(row) for row in rows])
    curves: list[BSplineCurve | None] = [None] * len(rows)
    for count in np.unique(counts):
        members = np.flatnonzero(counts == count)
        shared = np.mean([params[k] for k in members], axis=0)
        knots = averaged_knots(degree, shared)
        for k in members:
            curves[k] = interpolate_curve(rows[k], degree, shared, knots, label=f"row {k}")
    return [c for c in curves if c is not None]


def skin_rows(
    rows: list[FloatArray], degree_u: int = 3, degree_v: int = 3, label: str = "skinning"
) -> SkinnedNet:
    """Skin ordered rows of points ``(n_k, 3)`` (rows may differ in count) into one surface.

    Raises:
        OptionsError: fewer rows than ``degree_v + 1`` or a row shorter than ``degree_u + 1``.
        DegenerateGeometryError: duplicate consecutive points or coincident sections.
    """
    if len(rows) < degree_v + 1:
        raise OptionsError(
            f"{label}: option 'degree_v': {len(rows)} sections cannot be skinned with degree "
            f"{degree_v} (it needs at least {degree_v + 1}); lower degree_v or add sections"
        )
    for k, row in enumerate(rows):
        if len(row) < degree_u + 1:
            raise OptionsError(
                f"{label}: option 'degree_u': row {k} has {len(row)} points, degree {degree_u} "
                f"needs at least {degree_u + 1}; lower degree_u or merge short rows"
            )
    curves = _row_curves(rows, degree_u)
    knots_u = merge_knots([c.knots for c in curves])
    compatible = [c.refined(knots_u) for c in curves]
    polygons = np.stack([c.control_points for c in compatible])  # (n_sections, n_u, 3)
    gaps = np.linalg.norm(np.diff(polygons, axis=0), axis=2).mean(axis=1)
    if np.any(gaps <= 1e-12 * max(1.0, float(np.abs(polygons).max()))):
        k = int(np.argmin(gaps))
        raise DegenerateGeometryError(f"{label}: sections {k} and {k + 1} coincide")
    section = np.r_[0.0, np.cumsum(gaps)] / gaps.sum()
    section[-1] = 1.0
    knots_v = averaged_knots(degree_v, section)
    collocation = basis_matrix(degree_v, knots_v, section)
    n_sections, n_u, _ = polygons.shape
    try:
        net = np.linalg.solve(collocation, polygons.reshape(n_sections, -1))
    except np.linalg.LinAlgError as exc:
        raise DegenerateGeometryError(f"{label}: the cross-sectional system is singular") from exc
    control = net.reshape(n_sections, n_u, 3).transpose(1, 0, 2)
    return SkinnedNet(
        net=NurbsNet(degree_u, degree_v, knots_u, knots_v, np.ascontiguousarray(control)),
        row_parameters=[c.parameters for c in compatible],
        section_parameters=section,
    )


def lattice_angle(xy: FloatArray) -> float:
    """Direction (radians, in ``[-π/4, π/4)``) of a roughly square lattice of points.

    The nearest-neighbour directions of a lattice cluster at multiples of 90°; their circular
    mean after multiplying angles by 4 gives the lattice orientation.
    """
    if xy.shape[0] < 3:
        return 0.0
    _, index = cKDTree(xy).query(xy, k=2)
    d = xy[index[:, 1]] - xy
    angle = np.arctan2(d[:, 1], d[:, 0])
    mean = np.angle(np.exp(4j * angle).mean()) / 4.0
    return float(mean)


def _split_rows(ab: FloatArray, spacing: float) -> list[IntArray]:
    order = np.argsort(ab[:, 1], kind="stable")
    jumps = np.flatnonzero(np.diff(ab[order, 1]) > 0.5 * spacing) + 1
    return [g.astype(np.int64) for g in np.split(order, jumps)]


def _row_slope(ab: FloatArray, rows: list[IntArray]) -> float:
    """Common slope of the rows: pooled regression of b on a within rows."""
    da = np.concatenate([ab[r, 0] - ab[r, 0].mean() for r in rows])
    db = np.concatenate([ab[r, 1] - ab[r, 1].mean() for r in rows])
    denominator = float(da @ da)
    return float(da @ db) / denominator if denominator > 0 else 0.0


def rows_from_lattice(ab: FloatArray, label: str = "skinning") -> tuple[list[IntArray], float]:
    """Sort lattice-like points ``(a, b)`` into rows; returns the rows and the row direction.

    The direction (radians from the a axis) starts from :func:`lattice_angle` and is refined by
    regressing b on a within the rows found; a new row starts where the b values (across the
    rows) jump by more than half the typical nearest-neighbour spacing. Rows are ordered across,
    and the points of a row along, the row direction.

    Raises:
        DegenerateGeometryError: no row structure (fewer than 2 rows found) or duplicate points.
    """
    tree = cKDTree(ab)
    distance, _ = tree.query(ab, k=2)
    nearest = distance[:, 1]
    if np.any(nearest <= 1e-12 * max(1.0, float(np.abs(ab).max()))):
        i = int(np.argmin(nearest))
        raise DegenerateGeometryError(
            f"{label}: duplicate points (point {i} coincides with another); remove duplicates"
        )
    spacing = float(np.median(nearest))
    angle = lattice_angle(ab)
    rows: list[IntArray] = []
    for _ in range(4):
        c, s = np.cos(angle), np.sin(angle)
        turned = ab @ np.array([[c, -s], [s, c]])
        rows = _split_rows(turned, spacing)
        multi = [r for r in rows if r.size > 1]
        if len(rows) < 2 or not multi:
            break
        correction = float(np.arctan(_row_slope(turned, multi)))
        angle += correction
        if abs(correction) < 1e-6:
            break
    c, s = np.cos(angle), np.sin(angle)
    turned = ab @ np.array([[c, -s], [s, c]])
    rows = _split_rows(turned, spacing)
    if len(rows) < 2 or float(np.median([r.size for r in rows])) < 3:
        raise DegenerateGeometryError(
            f"{label}: the points do not form rows (no gaps across the lattice direction); give "
            "the rows explicitly (a PolyLine with one part per section, or option 'row_property')"
        )
    return [g[np.argsort(turned[g, 0], kind="stable")] for g in rows], angle
