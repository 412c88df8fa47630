"""The hybrid interpolation–approximation workflow (Li, Miao, Liu & Wang 2011).

1. Split the data into the dense, even core and the sparse rim (flag, polygon or density).
2. Skin the core: the surface passes through every core point.
3. Lay the skinned patch into a 3 × 3 patch layout over the whole area: the core's knots become
   the middle knot spans of one global knot vector, the rim gets uniform spans on either side,
   and the seams are knots of multiplicity p (C0 joins), so the core block of the global net *is*
   the skinned net and the core's boundary curves are rows of it.
4. Approximate the rim: the in-plane map of the rim patches is the harmonic fill between the
   core's boundary and the outer rectangle, rim points are parameterised by inverting it, and
   the rim heights minimise misfit + bending energy with the core block held fixed (the core's
   boundary is the constraint). The net is refined until the rim meets ε.
5. Report σ, max |d| and n overall and per subset, and the seam gap between the skinned core and
   the rim patches along the four seams.

The result is one NurbsSurface: exact on the core, within ε on the rim, gap-free at the seams.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from geobrep import Entity, NurbsSurface, PointSet
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import NurbsNet, greville_abscissae, surface_points
from geobrep.plugins import FitResult
from geobrep.plugins.fit._approximation import (
    NetFit,
    coarse_to_fine,
    collect_points,
    nurbs_from_local,
    smoothing_weight,
    solve_net,
)
from geobrep.plugins.fit._core_correction import correct_core, inside_core, on_core_points
from geobrep.plugins.fit._domain_map import (
    check_fold_free,
    fill_net,
    piecewise_linear,
    planar_map,
)
from geobrep.plugins.fit._frame import LocalFrame
from geobrep.plugins.fit._projection import invert_planar_map
from geobrep.plugins.fit._skinning import SkinnedNet, rows_from_lattice, skin_rows
from geobrep.plugins.fit._split import (
    core_by_density,
    core_by_property,
    inside_polygon,
    point_roles,
)
from geobrep.plugins.fit.distance import surface_distances
from geobrep.plugins.fit.options import HybridOptions
from geobrep.plugins.fit.report import accuracy_report, sigma

__all__ = ["Layout", "fit_hybrid", "layout_knots", "seam_gap"]

LABEL = "fitter 'hybrid'"


@dataclass(frozen=True)
class Layout:
    """Where the skinned core sits in the global knot vectors and net."""

    knots_u: FloatArray
    knots_v: FloatArray
    breaks_u: tuple[float, float]
    breaks_v: tuple[float, float]
    offset: tuple[int, int]
    """Net index of the core block's first control point."""
    core_shape: tuple[int, int]


def layout_knots(
    degree: int,
    core_knots: FloatArray,
    spans_before: int,
    spans_after: int,
    breaks: tuple[float, float],
) -> tuple[FloatArray, int]:
    """Global knots: uniform spans, the core's knots on ``breaks``, uniform spans; p-fold seams.

    Returns the knots and the index of the core's first control point.
    """
    a0, a1 = breaks
    n_core = core_knots.shape[0] - degree - 1
    core_inner = a0 + core_knots[degree + 1 : n_core] * (a1 - a0)
    before = np.linspace(0.0, a0, spans_before + 1)[1:-1]
    after = np.linspace(a1, 1.0, spans_after + 1)[1:-1]
    knots = np.concatenate(
        [
            np.zeros(degree + 1),
            before,
            np.full(degree, a0),
            core_inner,
            np.full(degree, a1),
            after,
            np.ones(degree + 1),
        ]
    )
    return knots, spans_before + degree - 1


def _core_mask(
    points: FloatArray, ab: FloatArray, options: HybridOptions, pointset: PointSet | None
) -> NDArray[np.bool_]:
    if options.core_property is not None:
        return core_by_property(pointset, options.core_property)
    if options.core_polygon is not None:
        return inside_polygon(points[:, :2], np.asarray(options.core_polygon, dtype=np.float64))
    return core_by_density(ab)


def _rim_levels(
    widths: FloatArray, rim_area: float, n_rim: int, options: HybridOptions
) -> list[NDArray[np.int64]]:
    """Span counts of the four rim sections (left, right, bottom, top), coarse to fine."""
    limit = max(1, options.max_control_points - max(options.degree_u, options.degree_v))
    if options.epsilon is None:
        step = 2.0 * np.sqrt(rim_area / max(n_rim, 1))
        return [np.clip(np.ceil(widths / step), 1, limit).astype(np.int64)]
    smallest = np.sqrt(2.0 * rim_area / max(n_rim, 1))  # about half as many controls as rim points
    levels: list[NDArray[np.int64]] = []
    step = float(widths.max())
    while True:
        spans = np.clip(np.ceil(widths / step - 1e-9), 1, limit).astype(np.int64)
        if not levels or not np.array_equal(spans, levels[-1]):
            if levels and step < smallest:
                break
            levels.append(spans)
        if np.all(spans >= limit):
            break
        step *= 0.8
    return levels


def _outer_boundary(
    net: FloatArray,
    fixed: NDArray[np.bool_],
    core: FloatArray,
    layout: Layout,
    gu: FloatArray,
    gv: FloatArray,
    rect: tuple[float, float, float, float],
) -> None:
    """Fix the outer rows of the in-plane net on the rectangle, aligned with the core's corners."""
    a0, a1, b0, b1 = rect
    (p0, p1), (q0, q1) = layout.breaks_u, layout.breaks_v
    for j, b, row in ((0, b0, core[:, 0, 0]), (-1, b1, core[:, -1, 0])):
        net[:, j, 0] = piecewise_linear(
            gu, np.array([0.0, p0, p1, 1.0]), np.array([[a0], [row[0]], [row[-1]], [a1]])
        )[:, 0]
        net[:, j, 1] = b
    for i, a, column in ((0, a0, core[0, :, 1]), (-1, a1, core[-1, :, 1])):
        net[i, :, 0] = a
        net[i, :, 1] = piecewise_linear(
            gv, np.array([0.0, q0, q1, 1.0]), np.array([[b0], [column[0]], [column[-1]], [b1]])
        )[:, 0]
    fixed[[0, -1], :] = True
    fixed[:, [0, -1]] = True


@dataclass(frozen=True)
class _Data:
    """The points in local coordinates, grouped: skinned core, other core (exact), rim."""

    skinned: FloatArray
    exact: FloatArray
    rim: FloatArray
    rim_weights: FloatArray | None = None


def _fit_level(
    skinned: SkinnedNet,
    spans: NDArray[np.int64],
    data: _Data,
    rect: tuple[float, float, float, float],
    breaks: tuple[tuple[float, float], tuple[float, float]],
    lam: float,
) -> tuple[NetFit, Layout]:
    p, q = skinned.net.degree_u, skinned.net.degree_v
    ku, iu0 = layout_knots(p, skinned.net.knots_u, int(spans[0]), int(spans[1]), breaks[0])
    kv, jv0 = layout_knots(q, skinned.net.knots_v, int(spans[2]), int(spans[3]), breaks[1])
    core = skinned.net.control_points
    ncu, ncv = core.shape[:2]
    layout = Layout(ku, kv, breaks[0], breaks[1], (iu0, jv0), (ncu, ncv))
    nu, nv = ku.shape[0] - p - 1, kv.shape[0] - q - 1
    gu, gv = greville_abscissae(p, ku), greville_abscissae(q, kv)
    a0, a1, b0, b1 = rect
    width, height = a1 - a0, b1 - b0
    block = (slice(iu0, iu0 + ncu), slice(jv0, jv0 + ncv))
    planar = np.zeros((nu, nv, 2))
    fixed = np.zeros((nu, nv), dtype=bool)
    planar[block] = core[..., :2]
    fixed[block] = True
    _outer_boundary(planar, fixed, core, layout, gu, gv, rect)
    planar = fill_net(gu * width, gv * height, planar, fixed)
    in_plane = planar_map((p, q), (ku, kv), planar)
    check_fold_free(in_plane, LABEL, skip=breaks)
    u_rim, v_rim, _ = invert_planar_map(in_plane, data.rim[:, :2])
    u_exact, v_exact, _ = invert_planar_map(in_plane, data.exact[:, :2])
    u_core, v_core = _core_parameters(skinned, layout)
    core_fixed = np.zeros((nu, nv), dtype=bool)
    core_fixed[block] = True
    core_heights = np.zeros((nu, nv, 1))
    core_heights[block] = core[..., 2:]
    heights = solve_net(
        (p, q),
        (ku, kv),
        u_rim,
        v_rim,
        data.rim[:, 2],
        lam=lam,
        lengths=(width, height),
        fixed=core_fixed,
        fixed_values=core_heights,
        exact=(u_exact, v_exact, data.exact[:, 2]),
        weights=data.rim_weights,
        label=LABEL,
    )
    net = in_plane.with_control_points(np.concatenate([planar, heights], axis=2))
    u = np.concatenate([u_core, u_exact, u_rim])
    v = np.concatenate([v_core, v_exact, v_rim])
    local = np.concatenate([data.skinned, data.exact, data.rim])
    residuals = np.linalg.norm(surface_points(net, u, v) - local, axis=1)
    fitted = NetFit(
        net,
        u,
        v,
        residuals,
        [],
        {
            "control_points": [nu, nv],
            "core_control_points": [ncu, ncv],
            "core_rows_skinned": len(skinned.row_parameters),
            "core_points_constrained": int(data.exact.shape[0]),
            "rim_spans": [int(s) for s in spans],
            "smoothing_lambda": lam,
        },
    )
    return fitted, layout


def _core_parameters(skinned: SkinnedNet, layout: Layout) -> tuple[FloatArray, FloatArray]:
    """Global parameters of the core points (in the order of the skinned rows)."""
    u, v = skinned.point_parameters()
    (a0, a1), (b0, b1) = layout.breaks_u, layout.breaks_v
    return a0 + u * (a1 - a0), b0 + v * (b1 - b0)


def seam_gap(
    surface: NurbsSurface, core: NurbsSurface, layout: Layout, samples: int = 200
) -> float:
    """Largest distance between the skinned core and the rim patches along the four seams.

    Each rim patch is cut out of the merged net as its own clamped surface and evaluated on the
    seam; the core is evaluated on its own boundary. Both are taken about the net's centre.
    """
    net = surface.net
    centre = net.centre
    points = net.control_points - centre
    p, q, ku, kv = net.degree_u, net.degree_v, net.knots_u, net.knots_v
    iu0, jv0 = layout.offset
    ncu, ncv = layout.core_shape
    (a0, a1), (b0, b1) = layout.breaks_u, layout.breaks_v
    core_net = core.net.with_control_points(core.net.control_points - centre)
    t = np.linspace(0.0, 1.0, samples)
    u_seam, v_seam = a0 + t * (a1 - a0), b0 + t * (b1 - b0)
    zeros, ones = np.zeros(samples), np.ones(samples)
    left = NurbsNet(p, q, np.r_[ku[: iu0 + p + 1], a0], kv, points[: iu0 + 1])
    right = NurbsNet(p, q, np.r_[a1, ku[iu0 + ncu :]], kv, points[iu0 + ncu - 1 :])
    bottom = NurbsNet(p, q, ku, np.r_[kv[: jv0 + q + 1], b0], points[:, : jv0 + 1])
    top = NurbsNet(p, q, ku, np.r_[b1, kv[jv0 + ncv :]], points[:, jv0 + ncv - 1 :])
    # each rim patch with the seam's parameters on it, then on the core
    seams = (
        (left, a0 + zeros, v_seam),
        (right, a1 + zeros, v_seam),
        (bottom, u_seam, b0 + zeros),
        (top, u_seam, b1 + zeros),
    )
    on_core = ((zeros, t), (ones, t), (t, zeros), (t, ones))
    gap = 0.0
    for (rim, u_rim, v_rim), (u_core, v_core) in zip(seams, on_core, strict=True):
        apart = surface_points(rim, u_rim, v_rim) - surface_points(core_net, u_core, v_core)
        gap = max(gap, float(np.linalg.norm(apart, axis=1).max()))
    return gap


def _regular_rows(rows: list[NDArray[np.int64]], ab: FloatArray, minimum: int) -> tuple[int, int]:
    """The longest run of consecutive rows that start and end where most rows do."""
    spacing = float(np.median(cKDTree(ab).query(ab, k=2)[0][:, 1]))
    starts = np.array([ab[r[0], 0] for r in rows])
    ends = np.array([ab[r[-1], 0] for r in rows])
    ok = (np.abs(starts - np.median(starts)) <= 1.5 * spacing) & (
        np.abs(ends - np.median(ends)) <= 1.5 * spacing
    )
    best, run_start = (0, 0), None
    for k, flag in enumerate([*ok.tolist(), False]):
        if flag and run_start is None:
            run_start = k
        elif not flag and run_start is not None:
            if k - run_start > best[1] - best[0]:
                best = (run_start, k)
            run_start = None
    if best[1] - best[0] < minimum:
        raise DegenerateGeometryError(
            f"{LABEL}: the core has no {minimum} consecutive rows of the same extent to skin; give "
            "core_property or core_polygon, or lower degree_v"
        )
    return best


def fit_hybrid(entities: list[Entity], options: HybridOptions) -> FitResult:
    """The ``hybrid`` fitter: skin the core, approximate the rim against it, report accuracy."""
    points, pointset = collect_points(entities, LABEL)
    frame = LocalFrame.from_points(points, LABEL)
    weights, hard = point_roles(
        pointset, points.shape[0], options.weight_property, options.exact_property, LABEL
    )
    hard = np.zeros(points.shape[0], bool) if hard is None else hard
    # the core interpolates: a weighted point there would be met exactly, against its weight
    not_core = hard if weights is None else hard | (weights != 1.0)
    core_mask = _checked_core_mask(points, frame, options, pointset, not_core)
    core = _corrected_core(
        _skinned_core(points, core_mask, frame, options, (weights, hard)), options
    )
    fitted, layout = _fit_rim(core, options, int((~core_mask).sum()))
    fitted.details.update(core.details)
    return _hybrid_result(points, pointset, core_mask, core, (fitted, layout), options)


@dataclass(frozen=True)
class _Core:
    """The skinned core, in the frame turned to its rows, and the points grouped for the rim."""

    frame: LocalFrame
    local: FloatArray
    """Every point in ``frame``."""
    skinned: SkinnedNet
    data: _Data
    order: NDArray[np.int64]
    """Input index of each point of ``data`` (skinned core, other core, rim)."""
    details: dict[str, object] = field(default_factory=dict)
    """What the correction for points inside the core did (empty when none is inside)."""


def _checked_core_mask(
    points: FloatArray,
    frame: LocalFrame,
    options: HybridOptions,
    pointset: PointSet | None,
    not_core: NDArray[np.bool_],
) -> NDArray[np.bool_]:
    """The core points (never hard data nor points of weight other than 1, which the core
    would meet exactly); a core too small to skin or an empty rim is an options error."""
    p, q = options.degree_u, options.degree_v
    found = _core_mask(points, frame.to_local(points)[:, :2], options, pointset)
    core_mask = found & ~not_core
    n_core, n_rim = int(core_mask.sum()), int((~core_mask).sum())
    if n_core < (p + 1) * (q + 1):
        left_out = int((found & not_core).sum())
        why = (
            f"; {left_out} of the {int(found.sum())} core candidates are hard or weighted "
            "points (weight other than 1), which are never core points"
            if left_out
            else ""
        )
        raise OptionsError(
            f"{LABEL}: option 'degree_u'/'degree_v': the core has {n_core} points, too few to skin "
            f"a surface of degrees ({p}, {q}) (it needs at least {(p + 1) * (q + 1)}){why}"
        )
    if n_rim == 0:
        raise OptionsError(f"{LABEL}: every point is in the core; use method='skinning'")
    return core_mask


def _skinned_core(
    points: FloatArray,
    core_mask: NDArray[np.bool_],
    frame: LocalFrame,
    options: HybridOptions,
    roles: tuple[FloatArray | None, NDArray[np.bool_]],
) -> _Core:
    """Skin the longest run of regular rows of the core; the other core rows and the hard data
    become exact."""
    weights, hard = roles
    p, q = options.degree_u, options.degree_v
    core_index = np.flatnonzero(core_mask)
    rows, angle = rows_from_lattice(frame.to_local(points[core_index])[:, :2], LABEL)
    frame = frame.rotated(angle)
    local = frame.to_local(points)
    first, last = _regular_rows(rows, local[core_index, :2], q + 1)
    skinned = skin_rows([local[core_index[r]] for r in rows[first:last]], p, q, LABEL)
    skinned_index = np.concatenate([core_index[r] for r in rows[first:last]])
    others = rows[:first] + rows[last:]
    exact_index = np.concatenate([*(core_index[r] for r in others), np.flatnonzero(hard)]).astype(
        np.int64
    )
    rim_index = np.flatnonzero(~core_mask & ~hard)
    order = np.concatenate([skinned_index, exact_index, rim_index])
    rim_weights = None if weights is None else weights[rim_index]
    data = _Data(local[skinned_index], local[exact_index], local[rim_index], rim_weights)
    return _Core(frame, local, skinned, data, order)


def _corrected_core(core: _Core, options: HybridOptions) -> _Core:
    """The core corrected for the exact and rim points that lie inside its patch: hard points
    are met exactly, rim points fitted by least squares, the skinned points kept (see
    :mod:`~geobrep.plugins.fit._core_correction`)."""
    data = core.data
    exact_in, exact_params = inside_core(core.skinned, data.exact)
    rim_in, rim_params = inside_core(core.skinned, data.rim)
    world = core.frame.to_world(data.skinned)
    exact_in[exact_in] &= ~on_core_points(
        world, core.frame.to_world(data.exact[exact_in]), np.ones(int(exact_in.sum()), bool), LABEL
    )
    rim_in[rim_in] &= ~on_core_points(
        world, core.frame.to_world(data.rim[rim_in]), np.zeros(int(rim_in.sum()), bool), LABEL
    )
    if not (exact_in.any() or rim_in.any()):
        return core
    n_exact = int(exact_in.sum())
    weights = None
    if data.rim_weights is not None:
        weights = np.r_[np.ones(n_exact), data.rim_weights[rim_in]]
    correction = correct_core(
        core.skinned,
        np.concatenate([exact_params[exact_in], rim_params[rim_in]]),
        np.concatenate([data.exact[exact_in, 2], data.rim[rim_in, 2]]),
        np.r_[np.ones(n_exact, bool), np.zeros(int(rim_in.sum()), bool)],
        weights,
        options.smoothing,
        LABEL,
    )
    details: dict[str, object] = {
        "core_points_corrected": {"exact": n_exact, "least_squares": int(rim_in.sum())},
        "core_knots_inserted": list(correction.inserted),
        "core_max_height_change": correction.max_correction,
    }
    if correction.max_correction > 8.0 * correction.max_misfit:  # about 3x for isolated points
        details["core_correction_note"] = (
            f"the core moved by up to {correction.max_correction:.3g} to meet points it missed by "
            f"at most {correction.max_misfit:.3g}: a point close to a core point at a height "
            "that does not follow the core's slope"
        )
    return dataclasses.replace(core, skinned=correction.skinned, details=details)


_Rectangle = tuple[float, float, float, float]
_Breaks = tuple[tuple[float, float], tuple[float, float]]


def _rim_rectangle(core: _Core) -> tuple[_Rectangle, _Breaks, FloatArray]:
    """The data rectangle ``(a0, a1, b0, b1)`` (2 % margin), the core's seams in it (0..1), and
    the widths of the four rim sections (left, right, bottom, top)."""
    core_net = core.skinned.net.control_points
    outline = np.concatenate([core.local[:, :2], core_net[..., :2].reshape(-1, 2)])
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    margin = 0.02 * float((hi - lo).max())
    a0, b0 = lo - margin
    a1, b1 = hi + margin
    rect = (float(a0), float(a1), float(b0), float(b1))
    width, height = rect[1] - rect[0], rect[3] - rect[2]
    core_left, core_right = core_net[0, :, 0].mean(), core_net[-1, :, 0].mean()
    core_bottom, core_top = core_net[:, 0, 1].mean(), core_net[:, -1, 1].mean()
    breaks = (
        ((core_left - a0) / width, (core_right - a0) / width),
        ((core_bottom - b0) / height, (core_top - b0) / height),
    )
    if not (0 < breaks[0][0] < breaks[0][1] < 1 and 0 < breaks[1][0] < breaks[1][1] < 1):
        raise DegenerateGeometryError(f"{LABEL}: the skinned core is not inside the data area")
    widths = np.array(
        [core_left - a0, a1 - core_right, core_bottom - b0, b1 - core_top], dtype=np.float64
    )
    return rect, breaks, widths


def _fit_rim(core: _Core, options: HybridOptions, n_rim: int) -> tuple[NetFit, Layout]:
    """Approximate the rim against the fixed core, on finer rim nets until σ(rim) < ε."""
    rect, breaks, widths = _rim_rectangle(core)
    width, height = rect[1] - rect[0], rect[3] - rect[2]
    core_net = core.skinned.net.control_points
    core_area = float(np.ptp(core_net[..., 0]) * np.ptp(core_net[..., 1]))
    rim_area = max(width * height - core_area, 0.25 * width * height)
    lam = smoothing_weight(options.smoothing, n_rim, width, height)
    rim_rows = slice(core.data.skinned.shape[0] + core.data.exact.shape[0], None)
    epsilon = options.epsilon

    def fit_level(number: int, spans: NDArray[np.int64]) -> tuple[NetFit, Layout]:
        fitted, layout = _fit_level(core.skinned, spans, core.data, rect, breaks, lam)
        fitted.details["nets_tried"] = number
        return fitted, layout

    def rim_meets_epsilon(best: tuple[NetFit, Layout]) -> bool:
        return epsilon is not None and sigma(best[0].residuals[rim_rows]) < epsilon

    levels = _rim_levels(widths, rim_area, n_rim, options)
    return coarse_to_fine(levels, fit_level, rim_meets_epsilon)


def _hybrid_result(
    points: FloatArray,
    pointset: PointSet | None,
    core_mask: NDArray[np.bool_],
    core: _Core,
    best: tuple[NetFit, Layout],
    options: HybridOptions,
) -> FitResult:
    """The world surface, its distances to every point and the report (overall, core, rim)."""
    fitted, layout = best
    kind = pointset.kind if pointset is not None else None
    surface = nurbs_from_local(fitted, core.frame, "hybrid", kind)
    core_net = core.skinned.net
    core_surface = NurbsSurface(
        degree_u=core_net.degree_u,
        degree_v=core_net.degree_v,
        knots_u=core_net.knots_u,
        knots_v=core_net.knots_v,
        control_points=core.frame.to_world(core_net.control_points.reshape(-1, 3)).reshape(
            core_net.control_points.shape
        ),
        weights=np.ones(core_net.shape),
        name="hybrid core",
    )
    gap = seam_gap(surface, core_surface, layout)
    inverse = np.empty_like(core.order)
    inverse[core.order] = np.arange(core.order.shape[0])
    distances = surface_distances(surface, points, fitted.u[inverse], fitted.v[inverse])
    notes = list(fitted.notes)
    details = dict(fitted.details)
    if "core_correction_note" in details:
        notes.append(str(details.pop("core_correction_note")))
    rim_sigma = sigma(distances[~core_mask])
    if options.epsilon is not None and not rim_sigma < options.epsilon:
        nu, nv = fitted.net.shape
        notes.append(
            f"ε = {options.epsilon:g} cannot be met on the rim: σ = {rim_sigma:.4g} with the "
            f"finest rim net the data support ({nu} × {nv} control points overall for "
            f"{int((~core_mask).sum())} rim points)"
        )
    report = accuracy_report(
        distances,
        points,
        epsilon=options.epsilon,
        method="hybrid",
        subsets={"core": core_mask, "rim": ~core_mask},
        labels=np.where(core_mask, "core", "rim"),
        seam_gap=gap,
        notes=notes,
        details=details,
    )
    return FitResult(
        surface=surface,
        report=report,
        distances=distances,
        method="hybrid",
        points=points,
        subsets={"core": core_mask, "rim": ~core_mask},
    )
