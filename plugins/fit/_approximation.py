"""Least-squares approximation of scattered points by a B-spline surface.

The points are parameterised by projection onto their best-fit plane (or, for steep, folded or
overturned interfaces, by closest points on a base surface). The control net minimises the
squared misfit plus a bending energy (so data gaps stay plausible), while prescribed boundary
curves are held exactly: their control points become fixed rows of the net, so a neighbouring
piece fitted to the same curve joins without a gap. Without a fixed net size, the net is refined
until σ meets ε, and no further than the data support (half as many control points as points);
when even that net misses ε the report says so.

>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> xy = rng.uniform(0, 100, (400, 2))
>>> pts = np.column_stack([xy, 0.002 * xy[:, 0] ** 2 - 0.05 * xy[:, 1]])
>>> fitted = approximate_points(pts, ApproximationOptions(epsilon=0.01))
>>> bool(fitted.sigma < 0.01)
True
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np
import scipy.linalg as la
from numpy.typing import NDArray

from geobrep import Entity, NurbsSurface, PointSet, PolyLine
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import (
    NurbsNet,
    basis_matrix,
    greville_abscissae,
    surface_grid,
    surface_points,
)
from geobrep.plugins import FitResult
from geobrep.plugins.fit._bending import bending_matrix
from geobrep.plugins.fit._curves import BSplineCurve, Side
from geobrep.plugins.fit._design import normal_equations, surface_design_matrix
from geobrep.plugins.fit._domain_map import check_fold_free, fill_net, planar_map
from geobrep.plugins.fit._frame import LocalFrame
from geobrep.plugins.fit._knots import approximation_knots, merge_knots, uniform_knots
from geobrep.plugins.fit._lsq import single_threaded_blas, solve_penalised
from geobrep.plugins.fit._projection import invert_planar_map, project_points
from geobrep.plugins.fit._split import point_roles
from geobrep.plugins.fit.distance import surface_distances
from geobrep.plugins.fit.options import ApproximationOptions
from geobrep.plugins.fit.report import accuracy_report, sigma

__all__ = [
    "NetFit",
    "approximate_points",
    "coarse_to_fine",
    "collect_points",
    "fit_approximation",
    "smoothing_weight",
    "solve_net",
    "unmet_note",
]

Level = TypeVar("Level")
Fitted = TypeVar("Fitted")

_ALONG_V: tuple[Side, ...] = ("u0", "u1")  # curves on these sides run along v


@dataclass(frozen=True)
class NetFit:
    """A fitted net in local coordinates with the data parameters and residuals."""

    net: NurbsNet
    u: FloatArray
    v: FloatArray
    residuals: FloatArray
    """``|S(uᵢ, vᵢ) − Pᵢ|``: an upper bound of each point's distance to the surface."""
    notes: list[str] = field(default_factory=list)
    details: dict[str, object] = field(default_factory=dict)

    @property
    def sigma(self) -> float:
        return sigma(self.residuals)


@dataclass(frozen=True)
class Roles:
    """Per-point misfit weights and hard-data flags (None: every point weighs 1, none is hard)."""

    weights: FloatArray | None = None
    exact: NDArray[np.bool_] | None = None

    def split(
        self, u: FloatArray, v: FloatArray, values: FloatArray
    ) -> tuple[dict[str, Any], tuple[FloatArray, FloatArray, FloatArray] | None]:
        """``solve_net`` arguments: the least-squares points with their weights, and the hard
        points as its ``exact`` argument."""
        free = np.ones(u.shape[0], bool) if self.exact is None else ~self.exact
        weights = None if self.weights is None else self.weights[free]
        exact = None
        if self.exact is not None and self.exact.any():
            exact = (u[self.exact], v[self.exact], values[self.exact])
        return {"u": u[free], "v": v[free], "values": values[free], "weights": weights}, exact


def collect_points(entities: list[Entity], label: str) -> tuple[FloatArray, PointSet | None]:
    """Vertices of the PointSets and PolyLines given to a fitter, and the first PointSet."""
    parts = []
    first: PointSet | None = None
    for entity in entities:
        if isinstance(entity, PointSet):
            first = first or entity
            parts.append(np.asarray(entity.vertices))
        elif isinstance(entity, PolyLine):
            parts.append(np.asarray(entity.vertices))
        else:
            raise OptionsError(f"{label}: cannot fit a {entity.label}; give points")
    if not parts:
        raise OptionsError(f"{label}: no points given")
    return np.concatenate(parts), first


def coarse_to_fine(
    levels: Iterable[Level],
    fit: Callable[[int, Level], Fitted],
    good_enough: Callable[[Fitted], bool],
) -> Fitted:
    """Fit level after level (``fit(number, level)``, numbered from 1) until one is good enough;
    the finest one when none is."""
    fitted: Fitted | None = None
    for number, level in enumerate(levels, 1):
        fitted = fit(number, level)
        if good_enough(fitted):
            break
    assert fitted is not None
    return fitted


def _sigma_below(epsilon: float | None) -> Callable[[NetFit], bool]:
    """Whether a fit's σ meets ``epsilon`` (never, without one: the first net is final)."""
    return lambda fitted: epsilon is not None and fitted.sigma < epsilon


def smoothing_weight(smoothing: float, n_points: int, width: float, height: float) -> float:
    """``λ = smoothing · ρ · D⁴``: dimensionless ``smoothing`` to the bending-energy weight."""
    area = max(width * height, 1e-300)
    return float(smoothing * n_points / area * (width**2 + height**2) ** 2)


def solve_net(
    degrees: tuple[int, int],
    knots: tuple[FloatArray, FloatArray],
    u: FloatArray,
    v: FloatArray,
    values: FloatArray,
    *,
    lam: float,
    lengths: tuple[float, float],
    fixed: NDArray[np.bool_] | None = None,
    fixed_values: FloatArray | None = None,
    exact: tuple[FloatArray, FloatArray, FloatArray] | None = None,
    weights: FloatArray | None = None,
    label: str = "approximation",
) -> FloatArray:
    """Control values ``(nu, nv, k)`` minimising misfit + ``lam`` · bending energy.

    ``lengths`` scale the unit parameter square to physical lengths for the bending energy;
    ``fixed`` holds control points at ``fixed_values``; ``exact = (u, v, values)`` are points the
    surface must pass through; ``weights`` weigh the misfit of each point.
    """
    (p, q), (ku, kv) = degrees, knots
    nu, nv = ku.shape[0] - p - 1, kv.shape[0] - q - 1
    normal, rhs = normal_equations(p, q, ku, kv, u, v, values, weights)
    penalty = None
    if lam > 0:
        penalty = bending_matrix(
            greville_abscissae(p, ku) * lengths[0], greville_abscissae(q, kv) * lengths[1]
        )
    k = rhs.shape[1]
    equality = None
    if exact is not None and exact[0].size:
        rows = surface_design_matrix(p, q, ku, kv, exact[0], exact[1])
        equality = (rows, exact[2].reshape(exact[0].shape[0], -1))
    solution = solve_penalised(
        normal,
        rhs,
        penalty=penalty,
        smoothing=lam,
        fixed=None if fixed is None else fixed.reshape(-1),
        fixed_values=None if fixed_values is None else fixed_values.reshape(nu * nv, k),
        equality=equality,
        what=label,
    )
    return solution.reshape(nu, nv, k)


def _inner_knots(degree: int, spans: int, required: list[FloatArray]) -> FloatArray:
    """Uniform knots for ``spans`` spans merged with the knots of the required curves.

    Uniform knots closer than a quarter span to a required knot are dropped (no sliver spans).
    """
    if not required:
        return uniform_knots(degree, spans)
    needed = merge_knots(required)
    interior_needed = needed[(needed > 0) & (needed < 1)]
    candidates = np.linspace(0.0, 1.0, spans + 1)[1:-1]
    if interior_needed.size:
        gap = np.abs(candidates[:, None] - interior_needed[None, :]).min(axis=1)
        candidates = candidates[gap > 0.25 / spans]
    extra = np.concatenate([np.zeros(degree + 1), candidates, np.ones(degree + 1)])
    return merge_knots([needed, extra])


def _spans_for(
    width: float, height: float, step: float, limit: int, p: int, q: int
) -> tuple[int, int]:
    return (
        int(min(max(1, np.ceil(width / step - 1e-9)), limit - p)),
        int(min(max(1, np.ceil(height / step - 1e-9)), limit - q)),
    )


def net_levels(
    width: float, height: float, n_points: int, options: ApproximationOptions
) -> Iterator[tuple[int, int]]:
    """Span counts ``(along u, along v)`` to try, coarse to fine."""
    p, q = options.degree_u, options.degree_v
    limit = max(options.max_control_points, max(p, q) + 1)
    if options.control_points is not None:
        nu, nv = options.control_points
        if nu < p + 1 or nv < q + 1:
            raise OptionsError(
                f"fitter 'approximation': option 'control_points': {nu} × {nv} control points are "
                f"too few for degrees ({p}, {q}); it needs at least {p + 1} × {q + 1}"
            )
        yield nu - p, nv - q
        return
    if options.epsilon is None:
        yield _spans_for(width, height, 2.0 * np.sqrt(width * height / n_points), limit, p, q)
        return
    cap = max((p + 1) * (q + 1), n_points // 2)
    seen: set[tuple[int, int]] = set()
    step = max(width, height)
    while True:
        spans = _spans_for(width, height, step, limit, p, q)
        if spans not in seen:
            if seen and (spans[0] + p) * (spans[1] + q) > cap:
                return
            seen.add(spans)
            yield spans
        if spans[0] + p >= limit and spans[1] + q >= limit:
            return
        step *= 0.8


@dataclass(frozen=True)
class _Constraint:
    side: Side
    curve: BSplineCurve  # local coordinates, domain [0, 1]


def _constraints(
    options: ApproximationOptions, frame: LocalFrame, extent: float
) -> list[_Constraint]:
    result = []
    p, q = options.degree_u, options.degree_v
    for side, spec in sorted(options.boundary_curves.items()):
        wanted = q if side in _ALONG_V else p
        if spec.degree != wanted:
            name = "degree_v" if side in _ALONG_V else "degree_u"
            raise OptionsError(
                f"fitter 'approximation': option 'boundary_curves': the {side} curve has degree "
                f"{spec.degree} but {name} is {wanted}; they must be equal"
            )
        local = frame.to_local(np.asarray(spec.control_points, dtype=np.float64))
        curve = BSplineCurve(spec.degree, np.asarray(spec.knots, np.float64), local)
        result.append(_Constraint(side, curve.reparameterized(0.0, 1.0)))
    ends = {c.side: (c.curve.control_points[0], c.curve.control_points[-1]) for c in result}
    corners = (("u0", 0, "v0", 0), ("u0", 1, "v1", 0), ("u1", 0, "v0", 1), ("u1", 1, "v1", 1))
    for a, ia, b, ib in corners:
        if a in ends and b in ends and np.linalg.norm(ends[a][ia] - ends[b][ib]) > 1e-9 * extent:
            raise OptionsError(
                f"fitter 'approximation': option 'boundary_curves': the {a} and {b} curves do not "
                "meet at their common corner"
            )
    return result


def _boundary_rows(
    constraints: list[_Constraint],
    knots_u: FloatArray,
    knots_v: FloatArray,
    nu: int,
    nv: int,
    channels: int,
) -> tuple[NDArray[np.bool_], FloatArray]:
    fixed = np.zeros((nu, nv), dtype=bool)
    values = np.zeros((nu, nv, channels))
    for c in constraints:
        along = knots_v if c.side in _ALONG_V else knots_u
        row = c.curve.refined(along).control_points[:, :channels]
        if c.side == "u0":
            fixed[0], values[0] = True, row
        elif c.side == "u1":
            fixed[-1], values[-1] = True, row
        elif c.side == "v0":
            fixed[:, 0], values[:, 0] = True, row
        else:
            fixed[:, -1], values[:, -1] = True, row
    return fixed, values


def _planar_net(
    constraints: list[_Constraint],
    knots: tuple[FloatArray, FloatArray],
    degrees: tuple[int, int],
    rect: tuple[float, float, float, float],
) -> FloatArray:
    """The in-plane net: affine on the rectangle, or filled from the constrained sides."""
    (ku, kv), (p, q) = knots, degrees
    gu, gv = greville_abscissae(p, ku), greville_abscissae(q, kv)
    a0, a1, b0, b1 = rect
    nu, nv = gu.shape[0], gv.shape[0]
    fixed, net = _boundary_rows(constraints, ku, kv, nu, nv, 2)
    by_side = {c.side: c.curve.control_points[:, :2] for c in constraints}

    def corner(
        first: tuple[Side, int], second: tuple[Side, int], default: tuple[float, float]
    ) -> FloatArray:
        for side, end in (first, second):
            if side in by_side:
                return np.asarray(by_side[side][end])
        return np.asarray(default)

    c00 = corner(("u0", 0), ("v0", 0), (a0, b0))
    c01 = corner(("u0", -1), ("v1", 0), (a0, b1))
    c10 = corner(("u1", 0), ("v0", -1), (a1, b0))
    c11 = corner(("u1", -1), ("v1", -1), (a1, b1))
    if "u0" not in by_side:
        net[0] = c00 + gv[:, None] * (c01 - c00)
    if "u1" not in by_side:
        net[-1] = c10 + gv[:, None] * (c11 - c10)
    if "v0" not in by_side:
        net[:, 0] = c00 + gu[:, None] * (c10 - c00)
    if "v1" not in by_side:
        net[:, -1] = c01 + gu[:, None] * (c11 - c01)
    fixed[[0, -1], :] = True
    fixed[:, [0, -1]] = True
    return fill_net(gu, gv, net, fixed)


def _plane_fit(
    local: FloatArray,
    options: ApproximationOptions,
    extent: float,
    frame: LocalFrame,
    roles: Roles,
) -> NetFit:
    p, q = options.degree_u, options.degree_v
    constraints = _constraints(options, frame, extent)
    ab = local[:, :2]
    outline = np.concatenate([ab] + [c.curve.control_points[:, :2] for c in constraints])
    a0, b0 = outline.min(axis=0)
    a1, b1 = outline.max(axis=0)
    width, height = float(a1 - a0), float(b1 - b0)
    if min(width, height) <= 1e-9 * extent:
        raise OptionsError("fitter 'approximation': the points span no area in their plane")
    lam = smoothing_weight(options.smoothing, local.shape[0], width, height)
    along_u = [c.curve.knots for c in constraints if c.side not in _ALONG_V]
    along_v = [c.curve.knots for c in constraints if c.side in _ALONG_V]

    def fit_level(tried: int, spans: tuple[int, int]) -> NetFit:
        spans_u, spans_v = spans
        ku = _inner_knots(p, spans_u, along_u)
        kv = _inner_knots(q, spans_v, along_v)
        nu, nv = ku.shape[0] - p - 1, kv.shape[0] - q - 1
        notes: list[str] = []
        if constraints:
            planar = _planar_net(constraints, (ku, kv), (p, q), (a0, a1, b0, b1))
            in_plane = planar_map((p, q), (ku, kv), planar)
            check_fold_free(in_plane, "fitter 'approximation'")
            u, v, off = invert_planar_map(in_plane, ab)
            outside = int(np.count_nonzero(off > 1e-6 * extent))
            if outside:
                notes.append(
                    f"{outside} points lie outside the region bounded by the boundary curves"
                )
            fixed, fixed_h = _boundary_rows(constraints, ku, kv, nu, nv, 3)
            fixed_h = fixed_h[..., 2:]
        else:
            gu, gv = greville_abscissae(p, ku), greville_abscissae(q, kv)
            planar = np.stack(np.meshgrid(a0 + gu * width, b0 + gv * height, indexing="ij"), axis=2)
            u = np.clip((ab[:, 0] - a0) / width, 0.0, 1.0)
            v = np.clip((ab[:, 1] - b0) / height, 0.0, 1.0)
            fixed, fixed_h = None, None
        least, exact = roles.split(u, v, local[:, 2])
        heights = solve_net(
            (p, q),
            (ku, kv),
            least.pop("u"),
            least.pop("v"),
            least.pop("values"),
            lam=lam,
            lengths=(width, height),
            fixed=fixed,
            fixed_values=fixed_h,
            exact=exact,
            **least,
        )
        net = NurbsNet(p, q, ku, kv, np.concatenate([planar, heights], axis=2))
        if constraints:
            residuals = np.linalg.norm(surface_points(net, u, v) - local, axis=1)
        else:  # the planar map is exactly affine: only the heights differ
            on_heights = surface_points(net.with_control_points(heights), u, v)
            residuals = np.abs(on_heights[:, 0] - local[:, 2])
        return NetFit(
            net,
            u,
            v,
            residuals,
            notes,
            {"control_points": [nu, nv], "smoothing_lambda": lam, "nets_tried": tried},
        )

    levels = net_levels(width, height, local.shape[0], options)
    return coarse_to_fine(levels, fit_level, _sigma_below(options.epsilon))


def _surface_lengths(net: NurbsNet) -> tuple[float, float]:
    """Mean lengths of the iso-curves of a surface along u and along v (for energy scaling)."""
    (umin, umax), (vmin, vmax) = net.domain
    grid = surface_grid(net, np.linspace(umin, umax, 24), np.linspace(vmin, vmax, 24))
    along_u = np.linalg.norm(np.diff(grid, axis=0), axis=2).sum(axis=0).mean()
    along_v = np.linalg.norm(np.diff(grid, axis=1), axis=2).sum(axis=1).mean()
    return float(along_u), float(along_v)


def _base_surface_fit(
    local: FloatArray,
    options: ApproximationOptions,
    extent: float,
    frame: LocalFrame,
    roles: Roles,
) -> NetFit:
    base = options.base_surface
    assert base is not None
    p, q = options.degree_u, options.degree_v
    shape = base.control_points.shape
    world = np.asarray(base.control_points).reshape(-1, 3)
    base_net = base.net.with_control_points(frame.to_local(world).reshape(shape))
    (umin, umax), (vmin, vmax) = base.domain
    u_raw, v_raw, _ = project_points(base_net, local)
    u = (u_raw - umin) / (umax - umin)
    v = (v_raw - vmin) / (vmax - vmin)
    width, height = _surface_lengths(base_net)
    constraints = _constraints(options, frame, extent)
    along_u = [c.curve.knots for c in constraints if c.side not in _ALONG_V]
    along_v = [c.curve.knots for c in constraints if c.side in _ALONG_V]
    lam = smoothing_weight(options.smoothing, local.shape[0], width, height)

    def fit_level(tried: int, spans: tuple[int, int]) -> NetFit:
        spans_u, spans_v = spans
        ku = _inner_knots(p, spans_u, along_u)
        kv = _inner_knots(q, spans_v, along_v)
        nu, nv = ku.shape[0] - p - 1, kv.shape[0] - q - 1
        fixed, fixed_xyz = _boundary_rows(constraints, ku, kv, nu, nv, 3)
        least, exact = roles.split(u, v, local)
        control = solve_net(
            (p, q),
            (ku, kv),
            least.pop("u"),
            least.pop("v"),
            least.pop("values"),
            exact=exact,
            **least,
            lam=lam,
            lengths=(width, height),
            fixed=fixed if constraints else None,
            fixed_values=fixed_xyz if constraints else None,
        )
        net = NurbsNet(p, q, ku, kv, control)
        residuals = np.linalg.norm(surface_points(net, u, v) - local, axis=1)
        return NetFit(
            net,
            u,
            v,
            residuals,
            [],
            {"control_points": [nu, nv], "smoothing_lambda": lam, "nets_tried": tried},
        )

    levels = net_levels(width, height, local.shape[0], options)
    return coarse_to_fine(levels, fit_level, _sigma_below(options.epsilon))


def _grid_parameters(grid: FloatArray, axis: int) -> FloatArray:
    """Averaged chord-length parameters along ``axis`` of an ordered grid of points."""
    steps = np.linalg.norm(np.diff(grid, axis=axis), axis=2)
    steps = steps if axis == 0 else steps.T  # (steps along the axis, lines)
    totals = steps.sum(axis=0)
    usable = totals > 0
    if not bool(usable.any()):
        raise DegenerateGeometryError(
            "fitter 'approximation': option 'grid_shape': the grid has no extent along an axis"
        )
    params = np.cumsum(steps[:, usable], axis=0) / totals[usable]
    mean = np.concatenate([[0.0], params.mean(axis=1)])
    mean[-1] = 1.0
    if np.any(np.diff(mean) <= 0):
        raise DegenerateGeometryError(
            "fitter 'approximation': option 'grid_shape': repeated rows or columns in the grid"
        )
    return mean


def _grid_fit(local: FloatArray, options: ApproximationOptions) -> NetFit:
    """Tensor-product least squares of an ordered grid (separable without smoothing)."""
    assert options.grid_shape is not None
    rows, columns = options.grid_shape
    if rows * columns != local.shape[0]:
        raise OptionsError(
            f"fitter 'approximation': option 'grid_shape': {rows} × {columns} does not match "
            f"{local.shape[0]} points"
        )
    p, q = options.degree_u, options.degree_v
    grid = local.reshape(rows, columns, 3)
    u_rows = _grid_parameters(grid, 0)
    v_columns = _grid_parameters(grid, 1)
    width = float(np.linalg.norm(np.diff(grid, axis=0), axis=2).sum(axis=0).mean())
    height = float(np.linalg.norm(np.diff(grid, axis=1), axis=2).sum(axis=1).mean())
    lam = smoothing_weight(options.smoothing, local.shape[0], width, height)
    u = np.repeat(u_rows, columns)
    v = np.tile(v_columns, rows)

    def fit_level(tried: int, spans: tuple[int, int]) -> NetFit:
        spans_u, spans_v = spans
        nu, nv = min(spans_u + p, rows), min(spans_v + q, columns)
        ku = approximation_knots(p, nu, u_rows)
        kv = approximation_knots(q, nv, v_columns)
        a_u, a_v = basis_matrix(p, ku, u_rows), basis_matrix(q, kv, v_columns)
        if lam > 0:
            net = solve_net((p, q), (ku, kv), u, v, local, lam=lam, lengths=(width, height))
        else:
            try:
                with single_threaded_blas():
                    left = la.cho_factor(a_u.T @ a_u)
                    right = la.cho_factor(a_v.T @ a_v)
                    # Aᵤᵀ G A_v per coordinate, as two matrix products
                    half = (a_u.T @ grid.reshape(rows, -1)).reshape(nu, columns, 3)
                    middle = np.matmul(a_v.T[None, :, :], half)
                    net = la.cho_solve(left, middle.reshape(nu, -1)).reshape(nu, nv, 3)
                    net = la.cho_solve(right, net.transpose(1, 0, 2).reshape(nv, -1))
                    net = net.reshape(nv, nu, 3).transpose(1, 0, 2)
            except la.LinAlgError as exc:
                raise DegenerateGeometryError(
                    "fitter 'approximation': the grid cannot determine the net; use fewer "
                    "control points or some smoothing"
                ) from exc
        # the surface at the grid parameters, separably: A_u · net · A_vᵀ per coordinate
        on_rows = (a_u @ net.reshape(nu, -1)).reshape(rows, nv, 3)
        fitted = np.matmul(a_v[None, :, :], on_rows).reshape(-1, 3)
        residuals = np.linalg.norm(fitted - local, axis=1)
        return NetFit(
            NurbsNet(p, q, ku, kv, np.ascontiguousarray(net)),
            u,
            v,
            residuals,
            [],
            {
                "control_points": [nu, nv],
                "smoothing_lambda": lam,
                "nets_tried": tried,
                "grid_shape": [rows, columns],
            },
        )

    levels = net_levels(width, height, local.shape[0], options)
    return coarse_to_fine(levels, fit_level, _sigma_below(options.epsilon))


def approximate_points(
    points: FloatArray,
    options: ApproximationOptions,
    frame: LocalFrame | None = None,
    roles: Roles | None = None,
) -> NetFit:
    """Fit a net to world points; the returned net is in ``frame``'s local coordinates.

    Raises:
        OptionsError: fewer points than the degrees need, or inconsistent boundary curves.
        DegenerateGeometryError: collinear points, a folding boundary, a singular system.
    """
    p, q = options.degree_u, options.degree_v
    needed = (p + 1) * (q + 1)
    if points.shape[0] < needed:
        raise OptionsError(
            f"fitter 'approximation': option 'degree_u'/'degree_v': {points.shape[0]} points "
            f"cannot determine a surface of degrees ({p}, {q}); it needs at least {needed}"
        )
    frame = frame or LocalFrame.from_points(points, "fitter 'approximation'")
    local = frame.to_local(points)
    extent = float(np.ptp(local, axis=0).max())
    if options.grid_shape is not None:
        fitted = _grid_fit(local, options)
    elif options.parameterization == "base_surface":
        fitted = _base_surface_fit(local, options, extent, frame, roles or Roles())
    else:
        fitted = _plane_fit(local, options, extent, frame, roles or Roles())
    return fitted


def unmet_note(epsilon: float, achieved: float, fitted: NetFit, n_points: int) -> str:
    """What the report says when the finest admissible net still misses ε."""
    nu, nv = fitted.net.shape
    return (
        f"ε = {epsilon:g} cannot be met: σ = {achieved:.4g} with the finest net the data support "
        f"({nu} × {nv} control points for {n_points} points; a finer net would fit noise): the "
        "points scatter about any smooth surface by more than ε"
    )


def nurbs_from_local(
    fitted: NetFit, frame: LocalFrame, name: str, kind: str | None
) -> NurbsSurface:
    """The fitted net as a world-coordinate NurbsSurface."""
    net = fitted.net
    nu, nv = net.shape
    world = frame.to_world(net.control_points.reshape(-1, 3)).reshape(nu, nv, 3)
    return NurbsSurface(
        degree_u=net.degree_u,
        degree_v=net.degree_v,
        knots_u=net.knots_u,
        knots_v=net.knots_v,
        control_points=world,
        weights=np.ones((nu, nv)),
        name=name,
        kind=kind,
    )


def fit_approximation(entities: list[Entity], options: ApproximationOptions) -> FitResult:
    """The ``approximation`` fitter: least squares with smoothing and boundary constraints."""
    points, pointset = collect_points(entities, "fitter 'approximation'")
    frame = LocalFrame.from_points(points, "fitter 'approximation'")
    weights, exact = point_roles(pointset, points.shape[0], options.weight_property,
                                 options.exact_property, "fitter 'approximation'")  # fmt: skip
    fitted = approximate_points(points, options, frame, Roles(weights, exact))
    kind = pointset.kind if pointset is not None else None
    surface = nurbs_from_local(fitted, frame, "approximation", kind)
    distances = surface_distances(surface, points, fitted.u, fitted.v)
    if options.epsilon is not None and not sigma(distances) < options.epsilon:
        fitted.notes.append(unmet_note(options.epsilon, sigma(distances), fitted, points.shape[0]))
    report = accuracy_report(
        distances,
        points,
        epsilon=options.epsilon,
        method="approximation",
        notes=fitted.notes,
        details={**fitted.details, "parameterization": options.parameterization},
    )
    return FitResult(
        surface=surface,
        report=report,
        distances=distances,
        method="approximation",
        points=points,
    )
