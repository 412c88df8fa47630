"""Vectorised B-spline and NURBS evaluation (pure numpy): basis functions, surfaces, tessellation.

Every function works on many parameters at once: the loops run over the degree only, never over
points. The algorithms are those of Piegl & Tiller, *The NURBS Book* (A2.1-A2.3, A3.5-A3.6,
A4.3-A4.4), rewritten for arrays of parameters.

>>> import numpy as np
>>> knots = np.array([0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0])
>>> spans = find_spans(2, knots, np.array([0.25, 1.0]))
>>> basis_functions(2, knots, spans, np.array([0.25, 1.0])).round(4).tolist()
[[0.25, 0.625, 0.125], [0.0, 0.0, 1.0]]

The surface evaluators take a :class:`NurbsNet`: degrees, knot vectors, control net and weights
checked once and carried together.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import comb

import numpy as np
from numpy.typing import ArrayLike

from geobrep.errors import EntityValidationError
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = [
    "NurbsNet",
    "Tessellation",
    "basis_derivatives",
    "basis_functions",
    "basis_matrix",
    "find_spans",
    "greville_abscissae",
    "surface_derivatives",
    "surface_grid",
    "surface_points",
    "tessellate",
]


#: Points evaluated per block, so that gathered control points stay within a few tens of MB.
_BLOCK = 1 << 15


@dataclass(frozen=True, eq=False)
class NurbsNet:
    """A tensor-product NURBS net: what the surface evaluators take, validated once.

    ``control_points`` is ``(nu, nv, c)``: ``c = 3`` coordinates for a surface (a non-rational
    net may carry any number of channels for :func:`surface_points`, e.g. heights or a planar
    map); ``weights`` is ``(nu, nv)`` and positive, or ``None`` for a B-spline net; the knot
    vectors hold ``nu + degree_u + 1`` and ``nv + degree_v + 1`` non-decreasing values.

    >>> k = np.array([0.0, 0.0, 1.0, 1.0])
    >>> plate = NurbsNet(1, 1, k, k, np.zeros((2, 2, 3)))
    >>> plate.shape, plate.domain, plate.is_rational
    ((2, 2), ((0.0, 1.0), (0.0, 1.0)), False)
    >>> NurbsNet(1, 1, k[1:], k, np.zeros((2, 2, 3)))
    Traceback (most recent call last):
    ...
    geobrep.errors.EntityValidationError: NurbsNet: knots_u: has 3 values; ... need 4
    """

    degree_u: int
    degree_v: int
    knots_u: FloatArray
    knots_v: FloatArray
    control_points: FloatArray
    weights: FloatArray | None = None

    def __post_init__(self) -> None:
        for name in ("knots_u", "knots_v", "control_points", "weights"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, np.asarray(value, dtype=np.float64))
        net = self.control_points
        if net.ndim != 3 or net.shape[2] < 1:
            raise EntityValidationError(
                "NurbsNet", "control_points", f"expected shape (nu, nv, c), got {net.shape}"
            )
        for axis, degree, count, knots in (
            ("u", self.degree_u, net.shape[0], self.knots_u),
            ("v", self.degree_v, net.shape[1], self.knots_v),
        ):
            _check_knots(axis, degree, count, knots)
        if self.weights is not None:
            if self.weights.shape != net.shape[:2]:
                raise EntityValidationError(
                    "NurbsNet",
                    "weights",
                    f"shape {self.weights.shape} does not match the net {net.shape[:2]}",
                )
            if self.weights.size and not bool(self.weights.min() > 0):
                raise EntityValidationError("NurbsNet", "weights", "must be positive")

    @property
    def shape(self) -> tuple[int, int]:
        """Control-net size ``(nu, nv)``."""
        return int(self.control_points.shape[0]), int(self.control_points.shape[1])

    @property
    def channels(self) -> int:
        """Values per control point (3 for a surface)."""
        return int(self.control_points.shape[2])

    @property
    def is_rational(self) -> bool:
        """Whether the weights differ (equal weights evaluate as a B-spline net)."""
        w = self.weights
        return w is not None and w.size > 0 and not bool(np.all(w == w.flat[0]))

    @property
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Parameter domain ``((u_min, u_max), (v_min, v_max))``."""
        nu, nv = self.shape
        return (
            (float(self.knots_u[self.degree_u]), float(self.knots_u[nu])),
            (float(self.knots_v[self.degree_v]), float(self.knots_v[nv])),
        )

    @property
    def centre(self) -> FloatArray:
        """Centre of the control net's bounding box (evaluate about it: UTM-scale precision)."""
        flat = self.control_points.reshape(-1, self.channels)
        return np.asarray(0.5 * (flat.min(axis=0) + flat.max(axis=0)), dtype=np.float64)

    def with_control_points(self, control_points: ArrayLike) -> NurbsNet:
        """The same degrees, knots and weights with another control net (of the same size)."""
        return replace(self, control_points=np.asarray(control_points, dtype=np.float64))

    def _homogeneous(self) -> tuple[FloatArray, bool]:
        """The net to contract: ``[w x, w y, w z, w]`` when rational, else the plain net."""
        if not self.is_rational:
            return self.control_points, False
        assert self.weights is not None
        w = self.weights[..., None]
        return np.concatenate([self.control_points * w, w], axis=-1), True


def _check_knots(axis: str, degree: int, count: int, knots: FloatArray) -> None:
    """Raise unless ``knots`` is a non-decreasing vector for ``count`` control points."""
    if degree < 0:
        raise EntityValidationError("NurbsNet", f"degree_{axis}", f"must be >= 0, got {degree}")
    if count < degree + 1:
        raise EntityValidationError(
            "NurbsNet", "control_points", f"{count} rows along {axis} need degree <= {count - 1}"
        )
    if knots.ndim != 1 or knots.shape[0] != count + degree + 1:
        raise EntityValidationError(
            "NurbsNet",
            f"knots_{axis}",
            f"has {knots.shape[0] if knots.ndim == 1 else knots.shape} values; {count} control "
            f"points of degree {degree} need {count + degree + 1}",
        )
    if np.any(np.diff(knots) < 0):
        raise EntityValidationError("NurbsNet", f"knots_{axis}", "must be non-decreasing")


def find_spans(degree: int, knots: FloatArray, params: ArrayLike) -> IntArray:
    """Knot span index of every parameter: ``knots[s] <= t < knots[s + 1]`` (A2.1, vectorised).

    The end of the domain belongs to the last non-empty span; parameters outside the domain get
    the first or last span (evaluation then extrapolates the end polynomial pieces).
    """
    t = np.asarray(params, dtype=np.float64)
    n_ctrl = knots.shape[0] - degree - 1
    spans = np.searchsorted(knots, t, side="right").astype(np.int64) - 1
    # A parameter equal to the domain end, or inside a run of repeated end knots, belongs to the
    # last non-empty span.
    last = int(np.searchsorted(knots, knots[n_ctrl], side="left")) - 1
    return np.clip(spans, degree, max(degree, min(last, n_ctrl - 1)))


def basis_functions(
    degree: int, knots: FloatArray, spans: IntArray, params: ArrayLike
) -> FloatArray:
    """Non-zero basis functions ``N[s-p .. s]`` at each parameter: ``(m, degree + 1)`` (A2.2)."""
    t = np.asarray(params, dtype=np.float64).reshape(-1)
    m = t.shape[0]
    values = np.zeros((m, degree + 1))
    values[:, 0] = 1.0
    left = np.empty((m, degree + 1))
    right = np.empty((m, degree + 1))
    for j in range(1, degree + 1):
        left[:, j] = t - knots[spans + 1 - j]
        right[:, j] = knots[spans + j] - t
        saved = np.zeros(m)
        for r in range(j):
            temp = values[:, r] / (right[:, r + 1] + left[:, j - r])
            values[:, r] = saved + right[:, r + 1] * temp
            saved = left[:, j - r] * temp
        values[:, j] = saved
    return values


def basis_derivatives(
    degree: int, knots: FloatArray, spans: IntArray, params: ArrayLike, order: int
) -> FloatArray:
    """Basis functions and their derivatives up to ``order``: shape ``(m, order + 1, degree + 1)``.

    ``result[:, k, r]`` is the k-th derivative of ``N[s - p + r]`` (A2.3, vectorised); derivatives
    above the degree are zero.
    """
    t = np.asarray(params, dtype=np.float64).reshape(-1)
    m, p = t.shape[0], degree
    ndu = np.zeros((m, p + 1, p + 1))  # upper triangle: basis values; lower: knot differences
    ndu[:, 0, 0] = 1.0
    left = np.empty((m, p + 1))
    right = np.empty((m, p + 1))
    for j in range(1, p + 1):
        left[:, j] = t - knots[spans + 1 - j]
        right[:, j] = knots[spans + j] - t
        saved = np.zeros(m)
        for r in range(j):
            ndu[:, j, r] = right[:, r + 1] + left[:, j - r]
            temp = ndu[:, r, j - 1] / ndu[:, j, r]
            ndu[:, r, j] = saved + right[:, r + 1] * temp
            saved = left[:, j - r] * temp
        ndu[:, j, j] = saved
    result = np.zeros((m, order + 1, p + 1))
    result[:, 0, :] = ndu[:, :, p]
    top = min(order, p)
    for r in range(p + 1):
        a = np.zeros((m, 2, p + 1))
        a[:, 0, 0] = 1.0
        s1, s2 = 0, 1
        for k in range(1, top + 1):
            d = np.zeros(m)
            rk, pk = r - k, p - k
            if r >= k:
                a[:, s2, 0] = a[:, s1, 0] / ndu[:, pk + 1, rk]
                d = a[:, s2, 0] * ndu[:, rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[:, s2, j] = (a[:, s1, j] - a[:, s1, j - 1]) / ndu[:, pk + 1, rk + j]
                d = d + a[:, s2, j] * ndu[:, rk + j, pk]
            if r <= pk:
                a[:, s2, k] = -a[:, s1, k - 1] / ndu[:, pk + 1, r]
                d = d + a[:, s2, k] * ndu[:, r, pk]
            result[:, k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, top + 1):
        result[:, k, :] *= factor
        factor *= p - k
    return result


def basis_matrix(
    degree: int, knots: FloatArray, params: ArrayLike, derivative: int = 0
) -> FloatArray:
    """Dense collocation matrix ``B[i, j] = N_j^(derivative)(t_i)``: shape ``(m, n_ctrl)``.

    For curve interpolation and small systems; the fitters build sparse matrices from
    :func:`basis_functions` directly.
    """
    t = np.asarray(params, dtype=np.float64).reshape(-1)
    n_ctrl = knots.shape[0] - degree - 1
    spans = find_spans(degree, knots, t)
    if derivative == 0:
        values = basis_functions(degree, knots, spans, t)
    else:
        values = basis_derivatives(degree, knots, spans, t, derivative)[:, derivative, :]
    matrix = np.zeros((t.shape[0], n_ctrl))
    columns = spans[:, None] - degree + np.arange(degree + 1)
    np.put_along_axis(matrix, columns, values, axis=1)
    return matrix


def greville_abscissae(degree: int, knots: FloatArray) -> FloatArray:
    """Greville abscissae: the mean of ``degree`` consecutive interior knots per control point."""
    n_ctrl = knots.shape[0] - degree - 1
    if degree == 0:
        return np.asarray(knots[:n_ctrl], dtype=np.float64)
    windows = np.lib.stride_tricks.sliding_window_view(knots[1:-1], degree)
    return np.asarray(windows[:n_ctrl].mean(axis=1), dtype=np.float64)


def surface_points(net: NurbsNet, u: ArrayLike, v: ArrayLike) -> FloatArray:
    """Surface points at parameter pairs ``(u[i], v[i])``: shape ``(m, 3)`` (A3.5/A4.3).

    A non-rational net may have any number of channels ``(nu, nv, c)``; the result is ``(m, c)``.

    >>> import numpy as np
    >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1.0; net[:, 1, 1] = 1.0
    >>> k = np.array([0.0, 0.0, 1.0, 1.0])
    >>> surface_points(NurbsNet(1, 1, k, k, net), [0.25], [0.5]).tolist()
    [[0.25, 0.5, 0.0]]
    """
    uu = np.asarray(u, dtype=np.float64).reshape(-1)
    vv = np.asarray(v, dtype=np.float64).reshape(-1)
    degree_u, degree_v, knots_u, knots_v = net.degree_u, net.degree_v, net.knots_u, net.knots_v
    points, rational = net._homogeneous()
    channels = points.shape[-1] - (1 if rational else 0)
    out = np.empty((uu.shape[0], channels))
    ar_u = np.arange(degree_u + 1)
    ar_v = np.arange(degree_v + 1)
    width = (degree_u + 1) * (degree_v + 1)
    for start in range(0, uu.shape[0], _BLOCK):
        bu, bv = uu[start : start + _BLOCK], vv[start : start + _BLOCK]
        m = bu.shape[0]
        su = find_spans(degree_u, knots_u, bu)
        sv = find_spans(degree_v, knots_v, bv)
        nu = basis_functions(degree_u, knots_u, su, bu)
        nv = basis_functions(degree_v, knots_v, sv, bv)
        iu = (su[:, None] - degree_u + ar_u)[:, :, None]
        iv = (sv[:, None] - degree_v + ar_v)[:, None, :]
        gathered = points[iu, iv].reshape(m, width, points.shape[-1])  # (m, (p+1)(q+1), c)
        products = (nu[:, :, None] * nv[:, None, :]).reshape(m, width)
        values = np.einsum("mi,mik->mk", products, gathered)
        out[start : start + _BLOCK] = values[:, :-1] / values[:, -1:] if rational else values
    return out


def surface_derivatives(net: NurbsNet, u: ArrayLike, v: ArrayLike, order: int = 1) -> FloatArray:
    """Partial derivatives ``SKL[:, k, l] = ∂^(k+l) S / ∂u^k ∂v^l`` for ``k + l <= order``.

    Shape ``(m, order + 1, order + 1, 3)``; entries with ``k + l > order`` are zero (A3.6/A4.4).
    """
    uu = np.asarray(u, dtype=np.float64).reshape(-1)
    vv = np.asarray(v, dtype=np.float64).reshape(-1)
    degree_u, degree_v, knots_u, knots_v = net.degree_u, net.degree_v, net.knots_u, net.knots_v
    points, rational = net._homogeneous()
    m = uu.shape[0]
    du, dv = min(order, degree_u), min(order, degree_v)
    out = np.zeros((m, order + 1, order + 1, 3))
    ar_u = np.arange(degree_u + 1)
    ar_v = np.arange(degree_v + 1)
    for start in range(0, m, _BLOCK):
        sl = slice(start, start + _BLOCK)
        bu, bv = uu[sl], vv[sl]
        su = find_spans(degree_u, knots_u, bu)
        sv = find_spans(degree_v, knots_v, bv)
        nu = basis_derivatives(degree_u, knots_u, su, bu, du)
        nv = basis_derivatives(degree_v, knots_v, sv, bv, dv)
        iu = (su[:, None] - degree_u + ar_u)[:, :, None]
        iv = (sv[:, None] - degree_v + ar_v)[:, None, :]
        gathered = points[iu, iv]
        # homogeneous derivatives A[k, l] (with the weight as the last channel when rational)
        hom = np.einsum("mki,mlj,mijc->mklc", nu, nv, gathered)
        block = np.zeros((bu.shape[0], order + 1, order + 1, 3))
        if not rational:
            for k in range(du + 1):
                for j in range(min(dv, order - k) + 1):
                    block[:, k, j] = hom[:, k, j]
        else:
            a, w = hom[..., :3], hom[..., 3]
            for k in range(order + 1):
                for ll in range(order - k + 1):
                    value = a[:, k, ll] if k <= du and ll <= dv else np.zeros((bu.shape[0], 3))
                    for j in range(1, ll + 1):
                        if j <= dv:
                            value = value - comb(ll, j) * w[:, 0, j, None] * block[:, k, ll - j]
                    for i in range(1, k + 1):
                        if i <= du:
                            value = value - comb(k, i) * w[:, i, 0, None] * block[:, k - i, ll]
                        inner = np.zeros((bu.shape[0], 3))
                        for j in range(1, ll + 1):
                            if i <= du and j <= dv:
                                inner = (
                                    inner + comb(ll, j) * w[:, i, j, None] * block[:, k - i, ll - j]
                                )
                        value = value - comb(k, i) * inner
                    block[:, k, ll] = value / w[:, 0, 0, None]
        out[sl] = block
    return out


def surface_grid(net: NurbsNet, u: ArrayLike, v: ArrayLike) -> FloatArray:
    """Surface points on the tensor grid ``u × v``: shape ``(len(u), len(v), 3)``.

    Evaluated in two passes (first along u, then along v), so the cost is
    ``O(len(u) · nv + len(u) · len(v))`` multiplications per basis function.
    """
    uu = np.asarray(u, dtype=np.float64).reshape(-1)
    vv = np.asarray(v, dtype=np.float64).reshape(-1)
    degree_u, degree_v, knots_u, knots_v = net.degree_u, net.degree_v, net.knots_u, net.knots_v
    points, rational = net._homogeneous()
    su = find_spans(degree_u, knots_u, uu)
    sv = find_spans(degree_v, knots_v, vv)
    nu = basis_functions(degree_u, knots_u, su, uu)
    nv = basis_functions(degree_v, knots_v, sv, vv)
    iu = su[:, None] - degree_u + np.arange(degree_u + 1)
    iv = sv[:, None] - degree_v + np.arange(degree_v + 1)
    along_u = np.einsum("ai,aijc->ajc", nu, points[iu])  # (mu, nv, c)
    out = np.empty((uu.shape[0], vv.shape[0], 3))
    rows = max(1, _BLOCK // max(1, vv.shape[0]))
    for start in range(0, uu.shape[0], rows):
        block = np.einsum("bj,abjc->abc", nv, along_u[start : start + rows][:, iv])
        out[start : start + rows] = block[..., :3] / block[..., 3:] if rational else block
    return out


class Tessellation:
    """A triangulated parameter grid of a NURBS surface (what :func:`tessellate` returns).

    ``vertices (len(u) · len(v), 3)`` in u-major order (vertex ``i · len(v) + j`` is
    ``S(u[i], v[j])``), ``faces (F, 3)`` oriented along ``S_u × S_v``, the grid parameters, and the
    largest midpoint deviation measured between the mesh and the surface.
    """

    __slots__ = ("deviation", "faces", "u", "v", "vertices")

    def __init__(
        self, vertices: FloatArray, faces: IntArray, u: FloatArray, v: FloatArray, deviation: float
    ) -> None:
        self.vertices = vertices
        self.faces = faces
        self.u = u
        self.v = v
        self.deviation = deviation


def _grid_faces(mu: int, mv: int) -> IntArray:
    i, j = np.meshgrid(np.arange(mu - 1), np.arange(mv - 1), indexing="ij")
    a = (i * mv + j).reshape(-1)
    b = a + mv  # (i + 1, j)
    c = b + 1  # (i + 1, j + 1)
    d = a + 1  # (i, j + 1)
    return np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])], axis=0).astype(
        np.int64
    )


def _span_samples(degree: int, knots: FloatArray, density: float) -> FloatArray:
    """Parameters on every knot line, each span split into ``ceil(density · length)`` parts."""
    n_ctrl = knots.shape[0] - degree - 1
    breaks = np.unique(knots[degree : n_ctrl + 1])
    lengths = np.diff(breaks)
    parts = np.maximum(1, np.ceil(density * lengths / lengths.sum() - 1e-9)).astype(np.int64)
    starts = np.repeat(breaks[:-1], parts)
    fractions = (np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)) / np.repeat(
        parts, parts
    )
    return np.concatenate([starts + fractions * np.repeat(lengths, parts), breaks[-1:]])


def _midpoint_deviation(net: NurbsNet, u: FloatArray, v: FloatArray, grid: FloatArray) -> float:
    """Largest distance between the surface and the mesh at cell centres and edge midpoints."""
    um, vm = 0.5 * (u[:-1] + u[1:]), 0.5 * (v[:-1] + v[1:])
    centre = surface_grid(net, um, vm)
    mesh_centre = 0.5 * (grid[:-1, :-1] + grid[1:, 1:])  # midpoint of each cell's diagonal
    along_u = surface_grid(net, um, v)
    along_v = surface_grid(net, u, vm)
    errors = (
        np.linalg.norm(centre - mesh_centre, axis=-1).max(initial=0.0),
        np.linalg.norm(along_u - 0.5 * (grid[:-1] + grid[1:]), axis=-1).max(initial=0.0),
        np.linalg.norm(along_v - 0.5 * (grid[:, :-1] + grid[:, 1:]), axis=-1).max(initial=0.0),
    )
    return float(max(errors))


def tessellate(
    net: NurbsNet,
    resolution: int | tuple[int, int] | None = None,
    tolerance: float | None = None,
    max_vertices: int = 4_000_000,
) -> Tessellation:
    """Triangulate a NURBS surface on a parameter grid.

    ``resolution`` gives the number of samples per direction (uniform in the parameter domain);
    ``tolerance`` instead refines a grid that keeps every knot line (and samples long spans more
    densely than short ones) until the mesh deviates from the surface by at most ``tolerance``
    at cell centres and edge midpoints (capped at ``max_vertices``). With neither, every knot
    span is split into 4 on average.
    """
    degree_u, degree_v, knots_u, knots_v = net.degree_u, net.degree_v, net.knots_u, net.knots_v
    nu_ctrl, nv_ctrl = net.shape
    domain_u, domain_v = net.domain
    if resolution is not None:
        ru, rv = (resolution, resolution) if isinstance(resolution, int) else resolution
        if ru < 2 or rv < 2:
            raise ValueError(f"resolution must be at least 2 per direction, got {resolution}")
        u = np.linspace(*domain_u, ru)
        v = np.linspace(*domain_v, rv)
        grid = surface_grid(net, u, v)
    else:
        # samples per whole parameter range; every knot span gets at least one
        spans_u = np.unique(knots_u[degree_u : nu_ctrl + 1]).shape[0] - 1
        spans_v = np.unique(knots_v[degree_v : nv_ctrl + 1]).shape[0] - 1
        density_u, density_v = (4.0 * spans_u, 4.0 * spans_v) if tolerance is None else (1.0, 1.0)
        while True:
            u = _span_samples(degree_u, knots_u, density_u)
            v = _span_samples(degree_v, knots_v, density_v)
            grid = surface_grid(net, u, v)
            if tolerance is None:
                break
            deviation = _midpoint_deviation(net, u, v, grid)
            if deviation <= tolerance:
                break
            # the chordal deviation of a smooth surface falls with the square of the step
            factor = max(2.0, min(8.0, 1.2 * np.sqrt(deviation / tolerance)))
            if (factor * density_u + spans_u + 1) * (
                factor * density_v + spans_v + 1
            ) > max_vertices:
                break
            density_u, density_v = density_u * factor, density_v * factor
    deviation = _midpoint_deviation(net, u, v, grid)
    faces = _grid_faces(u.shape[0], v.shape[0])
    return Tessellation(grid.reshape(-1, 3), faces, u, v, deviation)
