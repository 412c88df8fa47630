"""Planar parameter maps: the in-plane part ``(a(u, v), b(u, v))`` of a fitted surface.

Scattered points are parameterised by projection onto their best-fit plane. Without constraints
the map is affine (the net sits on the Greville abscissae of a rectangle). When boundary curves
or a skinned core are prescribed, their rows of the net are fixed and the rest of the net is the
discrete harmonic fill of those rows: smooth, and exactly affine where the fixed rows allow it.
Points are then parameterised by inverting the map (Newton, vectorised), and the map is checked
for folds.

>>> import numpy as np
>>> g = np.linspace(0.0, 1.0, 4)
>>> net = np.zeros((4, 4, 2)); fixed = np.zeros((4, 4), bool)
>>> fixed[[0, -1], :] = True; fixed[:, [0, -1]] = True
>>> net[..., 0], net[..., 1] = np.meshgrid(3 * g, 2 * g, indexing="ij")
>>> filled = fill_net(g, g, np.where(fixed[..., None], net, 0.0), fixed)
>>> bool(np.allclose(filled, net))
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import NurbsNet, surface_derivatives
from geobrep.plugins.fit._bending import laplacian_matrix

__all__ = ["check_fold_free", "fill_net", "piecewise_linear", "planar_map"]


def fill_net(
    gu: FloatArray, gv: FloatArray, values: FloatArray, fixed: NDArray[np.bool_]
) -> FloatArray:
    """Harmonic fill: the free nodes of ``values (nu, nv, k)`` solve the Laplace equation.

    Every boundary node must be fixed. ``gu``, ``gv`` are the node positions (Greville abscissae).
    """
    nu, nv = fixed.shape
    border = np.zeros_like(fixed)
    border[[0, -1], :] = True
    border[:, [0, -1]] = True
    if not bool(fixed[border].all()):
        raise ValueError("fill_net: every boundary node must be fixed")
    flat_fixed = fixed.reshape(-1)
    free = np.flatnonzero(~flat_fixed)
    result = values.reshape(nu * nv, -1).copy()
    if free.size == 0:
        return result.reshape(values.shape)
    lap = laplacian_matrix(gu, gv)
    known = np.flatnonzero(flat_fixed)
    system = sp.csc_matrix(lap[free][:, free])
    rhs = -(lap[free][:, known] @ result[known])
    solution = spla.spsolve(system, rhs)
    result[free] = np.asarray(solution).reshape(free.size, -1)
    return result.reshape(values.shape)


def piecewise_linear(g: FloatArray, breaks: FloatArray, positions: FloatArray) -> FloatArray:
    """Points at parameters ``g`` on the polyline through ``positions (k, d)`` at ``breaks``."""
    return np.column_stack(
        [np.interp(g, breaks, positions[:, axis]) for axis in range(positions.shape[1])]
    )


def planar_map(
    degrees: tuple[int, int], knots: tuple[FloatArray, FloatArray], planar: FloatArray
) -> NurbsNet:
    """The in-plane net ``planar (nu, nv, 2)`` as a net of three channels (zero heights)."""
    lifted = np.concatenate([planar, np.zeros((*planar.shape[:2], 1))], axis=2)
    return NurbsNet(degrees[0], degrees[1], knots[0], knots[1], lifted)


def check_fold_free(
    net: NurbsNet,
    label: str,
    per_span: int = 3,
    skip: tuple[tuple[float, float], tuple[float, float]] | None = None,
) -> None:
    """Raise if the planar map (the first two channels of ``net``) folds over anywhere.

    The map's Jacobian must keep its sign on a sample grid of every knot span; ``skip =
    ((u0, u1), (v0, v1))`` leaves out a parameter box (a patch that is never inverted).
    """
    planar = planar_map(
        (net.degree_u, net.degree_v), (net.knots_u, net.knots_v), net.control_points[..., :2]
    )
    samples = []
    for degree, knots, n in (
        (net.degree_u, net.knots_u, net.shape[0]),
        (net.degree_v, net.knots_v, net.shape[1]),
    ):
        breaks = np.unique(knots[degree : n + 1])
        steps = (np.arange(per_span) + 0.5) / per_span
        samples.append((breaks[:-1, None] + np.diff(breaks)[:, None] * steps).reshape(-1))
    uu, vv = np.meshgrid(samples[0], samples[1], indexing="ij")
    d = surface_derivatives(planar, uu.reshape(-1), vv.reshape(-1), order=1)
    jac = d[:, 1, 0, 0] * d[:, 0, 1, 1] - d[:, 1, 0, 1] * d[:, 0, 1, 0]
    if skip is not None:
        (u0, u1), (v0, v1) = skip
        inside = (uu.reshape(-1) > u0) & (uu.reshape(-1) < u1)
        inside &= (vv.reshape(-1) > v0) & (vv.reshape(-1) < v1)
        jac = jac[~inside]
    if not bool(np.all(jac > 0)):
        bad = int(np.count_nonzero(jac <= 0))
        raise DegenerateGeometryError(
            f"{label}: the planar parameter map folds over at {bad} of {jac.size} samples (the "
            "prescribed boundary is too irregular for a single patch); give a simpler boundary or "
            "a base surface"
        )
