"""Closest-point projection onto a NURBS surface, and inversion of planar parameter maps.

Both are Newton iterations run on all points at once (Piegl & Tiller §6.1): the loop is over
iterations, never over points. Starting parameters come from the nearest sample of a grid laid
over every knot span (a k-d tree query), or from the caller (a fitter knows its data parameters).

>>> import numpy as np
>>> from geobrep.model.entities import NurbsSurface
>>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
>>> plate = NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
...                      control_points=net)
>>> u, v, d = project_points(plate, np.array([[0.25, 0.5, 2.0]]))
>>> float(u[0]), float(v[0]), float(d[0])
(0.25, 0.5, 2.0)
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from geobrep import NurbsSurface
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import NurbsNet, surface_derivatives, surface_grid, surface_points

__all__ = ["initial_parameters", "invert_planar_map", "project_points"]


def _net(surface: NurbsSurface | NurbsNet) -> NurbsNet:
    return surface.net if isinstance(surface, NurbsSurface) else surface


def _domain(net: NurbsNet) -> tuple[float, float, float, float]:
    (umin, umax), (vmin, vmax) = net.domain
    return umin, umax, vmin, vmax


def _samples(degree: int, knots: FloatArray, n_ctrl: int, per_span: int) -> FloatArray:
    breaks = np.unique(knots[degree : n_ctrl + 1])
    steps = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    inner = (breaks[:-1, None] + np.diff(breaks)[:, None] * steps).reshape(-1)
    return np.concatenate([inner, breaks[-1:]])


def initial_parameters(
    surface: NurbsSurface | NurbsNet, points: FloatArray, per_span: int = 4, channels: int = 3
) -> tuple[FloatArray, FloatArray]:
    """Parameters of the grid sample nearest to each point (``channels`` = 2 compares x, y only)."""
    net = _net(surface)
    u = _samples(net.degree_u, net.knots_u, net.shape[0], per_span)
    v = _samples(net.degree_v, net.knots_v, net.shape[1], per_span)
    grid = surface_grid(net, u, v)
    tree = cKDTree(grid.reshape(-1, 3)[:, :channels])
    _, index = tree.query(points[:, :channels])
    iu, iv = np.divmod(np.asarray(index, dtype=np.int64), v.shape[0])
    return u[iu], v[iv]


def project_points(
    surface: NurbsSurface | NurbsNet,
    points: FloatArray,
    u0: FloatArray | None = None,
    v0: FloatArray | None = None,
    iterations: int = 40,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Closest points on the surface: parameters ``(u, v)`` and signed distances.

    The sign is that of ``(P - S) · (S_u × S_v)``: positive on the side the normal points to.
    Each iteration takes a damped Newton step (Gauss-Newton where the Hessian is not positive
    definite) and halves it until the distance decreases, so degenerate spots (poles, collapsed
    edges) do not trap a point. Parameters are clamped to the domain, so points beyond an edge
    project onto it.
    """
    net = _net(surface)
    pts = np.asarray(points, dtype=np.float64)
    if u0 is None or v0 is None:
        u0, v0 = initial_parameters(net, pts)
    u = np.array(u0, dtype=np.float64)
    v = np.array(v0, dtype=np.float64)
    umin, umax, vmin, vmax = _domain(net)
    flat = net.control_points.reshape(-1, net.channels)
    scale = float(np.ptp(flat[:, :3], axis=0).max()) or 1.0
    active = np.arange(pts.shape[0])
    for _ in range(iterations):
        if active.size == 0:
            break
        d = surface_derivatives(net, u[active], v[active], order=2)
        s, su, sv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1]
        suu, suv, svv = d[:, 2, 0], d[:, 1, 1], d[:, 0, 2]
        target = pts[active]
        r = s - target
        before = np.einsum("ij,ij->i", r, r)
        f = np.einsum("ij,ij->i", r, su)
        g = np.einsum("ij,ij->i", r, sv)
        a11 = np.einsum("ij,ij->i", su, su)
        a12 = np.einsum("ij,ij->i", su, sv)
        a22 = np.einsum("ij,ij->i", sv, sv)
        j11 = a11 + np.einsum("ij,ij->i", r, suu)
        j12 = a12 + np.einsum("ij,ij->i", r, suv)
        j22 = a22 + np.einsum("ij,ij->i", r, svv)
        newton = (j11 > 0) & (j11 * j22 - j12 * j12 > 1e-12 * (a11 * a22 + 1e-300))
        j11 = np.where(newton, j11, a11)
        j12 = np.where(newton, j12, a12)
        j22 = np.where(newton, j22, a22)
        damping = 1e-9 * (a11 + a22) + 1e-300
        j11, j22 = j11 + damping, j22 + damping
        det = j11 * j22 - j12 * j12
        du = -(j22 * f - j12 * g) / det
        dv = -(j11 * g - j12 * f) / det
        step = np.ones(active.size)
        pending = np.arange(active.size)
        new_u = u[active].copy()
        new_v = v[active].copy()
        for _ in range(8):
            cu = np.clip(u[active[pending]] + step[pending] * du[pending], umin, umax)
            cv = np.clip(v[active[pending]] + step[pending] * dv[pending], vmin, vmax)
            trial = surface_points(net, cu, cv) - target[pending]
            better = np.einsum("ij,ij->i", trial, trial) <= before[pending]
            new_u[pending[better]] = cu[better]
            new_v[pending[better]] = cv[better]
            pending = pending[~better]
            if pending.size == 0:
                break
            step[pending] *= 0.5
        moved = np.sqrt((new_u - u[active]) ** 2 * a11 + (new_v - v[active]) ** 2 * a22)
        u[active], v[active] = new_u, new_v
        active = active[moved > 1e-15 * scale]
    d = surface_derivatives(net, u, v, order=1)
    foot, su, sv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1]
    normal = np.cross(su, sv)
    length = np.linalg.norm(normal, axis=1)
    normal = normal / np.where(length > 0, length, 1.0)[:, None]
    offset = pts - foot
    distance = np.linalg.norm(offset, axis=1)
    sign = np.where(np.einsum("ij,ij->i", offset, normal) < 0, -1.0, 1.0)
    return u, v, sign * distance


def invert_planar_map(
    planar_map: NurbsNet,
    targets: FloatArray,
    u0: FloatArray | None = None,
    v0: FloatArray | None = None,
    iterations: int = 40,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Parameters ``(u, v)`` where the map's first two coordinates reach ``targets (m, 2)``.

    ``planar_map`` is a net of three channels whose first two are the map. Returns the
    parameters and the remaining planar distance (non-zero for targets outside the mapped
    region, which are clamped to the domain).
    """
    net = planar_map
    pts = np.asarray(targets, dtype=np.float64)[:, :2]
    if u0 is None or v0 is None:
        u0, v0 = initial_parameters(net, np.column_stack([pts, np.zeros(len(pts))]), channels=2)
    u = np.array(u0, dtype=np.float64)
    v = np.array(v0, dtype=np.float64)
    umin, umax, vmin, vmax = _domain(net)
    scale = float(np.ptp(net.control_points.reshape(-1, 3)[:, :2], axis=0).max()) or 1.0
    active = np.arange(pts.shape[0])
    for _ in range(iterations):
        if active.size == 0:
            break
        d = surface_derivatives(net, u[active], v[active], order=1)
        r = pts[active] - d[:, 0, 0, :2]
        xu, yu = d[:, 1, 0, 0], d[:, 1, 0, 1]
        xv, yv = d[:, 0, 1, 0], d[:, 0, 1, 1]
        det = xu * yv - xv * yu
        det = np.where(np.abs(det) > 1e-300, det, 1e-300)
        du = (yv * r[:, 0] - xv * r[:, 1]) / det
        dv = (-yu * r[:, 0] + xu * r[:, 1]) / det
        new_u = np.clip(u[active] + du, umin, umax)
        new_v = np.clip(v[active] + dv, vmin, vmax)
        moved = np.hypot(
            (new_u - u[active]) * np.hypot(xu, yu), (new_v - v[active]) * np.hypot(xv, yv)
        )
        u[active], v[active] = new_u, new_v
        active = active[moved > 1e-15 * scale]
    d = surface_derivatives(net, u, v, order=0)
    residual = np.linalg.norm(pts - d[:, 0, 0, :2], axis=1)
    return u, v, residual
