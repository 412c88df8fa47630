"""Well markers joining the scattered points of a fit (``geobrep.fit(..., markers=...)``).

The markers that name the surface (``marker.surface``, or the marker's name when it names no
surface) are placed on their wells' paths at their measured depth (minimum-curvature arcs where
the stations carry their angles, :meth:`~geobrep.Well.position_at`) and appended to the points,
flagged by the point property ``marker``. ``marker_weight`` weighs them in a least-squares fit
(the fitter option ``weight_property``) or, as ``"hard"``, makes them points the surface passes
through (``exact_property``); kriging honours every data point already. The report gains the
subset ``markers`` and, in ``details["markers"]``, each marker's misfit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import OptionsError
from geobrep.model.entities import Entity, PointSet, Well
from geobrep.model.properties import Property, PropertyMap
from geobrep.model.scene import Scene

if TYPE_CHECKING:
    from geobrep.host.registry import FitterSpec
    from geobrep.ops.fitting import FitResult

__all__ = [
    "MARKER",
    "MARKER_WEIGHT",
    "MarkerPicks",
    "join_markers",
    "marker_report",
    "outside_footprint",
    "picks",
]

#: Point property flagging the marker points of a joined fit.
MARKER = "marker"
#: Point property of the misfit weights of a joined fit (1 for the scattered points).
MARKER_WEIGHT = "marker_weight"


@dataclass(frozen=True)
class MarkerPicks:
    """The markers of one surface: their positions and where they come from."""

    positions: NDArray[np.float64]
    rows: list[dict[str, Any]]


def _wells(markers: Any) -> list[Well]:
    if isinstance(markers, Well):
        return [markers]
    if isinstance(markers, Scene):
        return list(markers.wells)
    if isinstance(markers, Entity) or not isinstance(markers, Iterable):
        raise OptionsError(
            f"markers: expected a Well, a Scene or wells, got {type(markers).__name__}"
        )
    wells: list[Well] = []
    for item in markers:
        wells.extend(_wells(item))
    return wells


def picks(markers: Any, surface: str | None) -> MarkerPicks:
    """The markers of ``surface`` on the wells of ``markers`` (every marker when ``surface`` is
    None and they all name one surface)."""
    wells = _wells(markers)
    every = [(w, m) for w in wells for m in w.markers]
    names = sorted({m.surface or m.name for _, m in every})
    if surface is None:
        if len(names) > 1:
            raise OptionsError(
                f"markers: the wells' markers name {len(names)} surfaces ({', '.join(names)}); "
                "choose one with marker_surface (--marker-surface)"
            )
        surface = names[0] if names else ""
    chosen = [(w, m) for w, m in every if (m.surface or m.name) == surface]
    if not chosen:
        raise OptionsError(
            f"markers: no marker of {len(wells)} well(s) names the surface {surface!r} "
            f"(they name: {', '.join(names) or 'nothing'})"
        )
    positions = np.concatenate([w.position_at([m.md]) for w, m in chosen]).reshape(-1, 3)
    rows = [{"well": w.name or w.label, "marker": m.name, "md": m.md} for w, m in chosen]
    return MarkerPicks(positions, rows)


def _extended(prop: Property, count: int) -> Property:
    values = prop.values
    shape = (count, *values.shape[1:])
    if values.dtype.kind == "f":
        fill = prop.no_data_value if prop.no_data_value is not None else np.nan
        extra = np.full(shape, fill, dtype=values.dtype)
    else:
        extra = np.zeros(shape, dtype=values.dtype)
    return prop.model_copy(update={"values": np.concatenate([values, extra])})


def join_markers(
    entity: Entity,
    found: MarkerPicks,
    weight: float | str | None,
    spec: FitterSpec,
    options: Mapping[str, Any],
) -> tuple[PointSet, dict[str, Any]]:
    """The points with the markers appended, and the fitter options that weigh them."""
    if not isinstance(entity, PointSet):
        raise OptionsError(f"markers join scattered points: give a PointSet, not a {entity.label}")
    taken = {MARKER, MARKER_WEIGHT} & set(entity.point_data)
    if taken:
        raise OptionsError(f"markers: the points already have a property {sorted(taken)[0]!r}")
    n, extra = entity.n_points, found.positions.shape[0]
    data = {name: _extended(prop, extra) for name, prop in entity.point_data.items()}
    flags = np.concatenate([np.zeros(n, np.uint8), np.ones(extra, np.uint8)])
    data[MARKER] = Property(values=flags, description="1: a well marker")
    updated = dict(options)
    if weight is not None:
        fields = getattr(spec.options, "model_fields", {})
        hard = isinstance(weight, str)
        if hard and weight != "hard":
            raise OptionsError(f"marker_weight must be a number ≥ 0 or 'hard', got {weight!r}")
        key = "exact_property" if hard else "weight_property"
        if key in fields:
            if updated.get(key) is not None:
                raise OptionsError(f"marker_weight sets the fitter option {key}: give one of them")
            updated[key] = MARKER if hard else MARKER_WEIGHT
        elif not (hard and spec.name == "kriging"):  # kriging honours its data exactly
            raise OptionsError(
                f"{spec.label}: takes no marker_weight ({'hard data' if hard else 'weights'})"
            )
        if not hard:
            value = float(weight)
            if not (np.isfinite(value) and value >= 0):
                raise OptionsError(f"marker_weight must be finite and ≥ 0, got {weight!r}")
            weights = np.concatenate([np.ones(n), np.full(extra, value)])
            data[MARKER_WEIGHT] = Property(values=weights, description="misfit weight")
    joined = entity.replace(
        vertices=np.concatenate([entity.vertices, found.positions]), point_data=PropertyMap(data)
    )
    return joined, updated


def _crossings_inside(
    xy: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64], tolerance: float
) -> NDArray[np.bool_]:
    """Even-odd test of points ``(m, 2)`` against the closed boundary edges ``a → b`` (holes
    and several loops included); points within ``tolerance`` of an edge count as inside."""
    inside = np.zeros(xy.shape[0], dtype=bool)
    step = max(1, 4_000_000 // max(a.shape[0], 1))
    ab = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    for start in range(0, xy.shape[0], step):
        x = xy[start : start + step, 0][:, None]
        y = xy[start : start + step, 1][:, None]
        crosses = (a[None, :, 1] > y) != (b[None, :, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = a[None, :, 0] + (y - a[None, :, 1]) * ab[None, :, 0] / ab[None, :, 1]
        odd = (np.count_nonzero(crosses & (x < at), axis=1) % 2) == 1
        t = np.clip(((x - a[:, 0]) * ab[:, 0] + (y - a[:, 1]) * ab[:, 1]) / length2, 0.0, 1.0)
        near = np.hypot(a[:, 0] + t * ab[:, 0] - x, a[:, 1] + t * ab[:, 1] - y).min(axis=1)
        inside[start : start + step] = odd | (near <= tolerance)
    return inside


def _boundary(surface: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The surface's boundary in map view as edges ``(a, b)``, or None for other entities."""
    from geobrep.geometry.mesh import boundary_edges
    from geobrep.geometry.nurbs import surface_points
    from geobrep.model.entities import NurbsSurface, Surface

    if isinstance(surface, NurbsSurface):
        net = surface.net
        (u0, u1), (v0, v1) = net.domain
        t = np.linspace(0.0, 1.0, 2001)[:-1]
        u = np.concatenate(
            [u0 + t * (u1 - u0), np.full(t.size, u1), u1 - t * (u1 - u0), np.full(t.size, u0)]
        )
        v = np.concatenate(
            [np.full(t.size, v0), v0 + t * (v1 - v0), np.full(t.size, v1), v1 - t * (v1 - v0)]
        )
        loop = surface_points(net, u, v)[:, :2]
        return loop, np.roll(loop, -1, axis=0)
    if isinstance(surface, Surface):
        vertices = np.asarray(surface.vertices, dtype=np.float64)[:, :2]
        edges = boundary_edges(surface.faces)
        return vertices[edges[:, 0]], vertices[edges[:, 1]]
    return None


def outside_footprint(surface: Any, xy: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Which points ``(m, 2)`` lie outside the surface in map view (x, y).

    A triangle mesh covers what its boundary edges enclose; a NURBS surface what its four
    boundary curves (sampled 2,000 times each) enclose. Points within 10⁻⁶ of the surface's
    size of the boundary count as inside.
    """
    edges = _boundary(surface)
    points = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if edges is None or edges[0].shape[0] == 0:
        return np.zeros(points.shape[0], dtype=bool)
    a, b = edges
    centre = a.mean(axis=0)
    size = float(np.ptp(a, axis=0).max()) or 1.0
    return ~_crossings_inside(points - centre, a - centre, b - centre, 1e-6 * size)


def _check_footprint(result: FitResult, found: MarkerPicks) -> None:
    outside = outside_footprint(result.surface, found.positions[:, :2])
    if not outside.any():
        return
    index = np.flatnonzero(outside)
    first = found.rows[int(index[0])]
    x, y = found.positions[index[0], :2]
    box = result.surface.bounds
    assert box is not None
    bounds = np.array([box.mins, box.maxs], dtype=np.float64)
    raise OptionsError(
        f"markers: {index.size} marker(s) lie outside the fitted surface in map view, the first "
        f"{first['marker']!r} of well {first['well']!r} (MD {first['md']:g}) at x = {x:.3f}, "
        f"y = {y:.3f}; the surface spans x {bounds[0, 0]:.3f} – {bounds[1, 0]:.3f}, "
        f"y {bounds[0, 1]:.3f} – {bounds[1, 1]:.3f}: widen its domain (the kriging grid's gridx "
        "and gridy, the boundary curves) or leave that well out"
    )


def marker_report(result: FitResult, found: MarkerPicks, first: int) -> FitResult:
    """``result`` with the subset ``markers`` (rows ``first:``) and each marker's misfit.

    Raises:
        OptionsError: a marker lies outside the fitted surface in map view (its misfit would be
            the distance to the surface's edge).
    """
    from geobrep.ops.fitting import SubsetReport

    _check_footprint(result, found)
    distances = result.distances
    report = result.report
    if distances is None or report is None:
        return result
    mask = np.zeros(distances.shape[0], dtype=bool)
    mask[first:] = True
    subset = SubsetReport.from_distances(distances[mask], epsilon=report.epsilon)
    rows = [
        {**row, "distance": float(d)} for row, d in zip(found.rows, distances[mask], strict=True)
    ]
    report = report.model_copy(
        update={
            "subsets": {**report.subsets, "markers": subset},
            "details": {**report.details, "markers": rows},
        }
    )
    return dataclasses.replace(result, report=report, subsets={**result.subsets, "markers": mask})
