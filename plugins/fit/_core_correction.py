"""Points inside the skinned core of the hybrid fit: a correction of the core that keeps it exact.

The skinned core interpolates its rows, so its net has no freedom left: a point that is not a core
point but lies inside the core's patch (a well marker, hard data, a rim point inside the core
outline) cannot pull it. The correction gives the net that freedom and uses it without moving a
skinned point:

1. knots are inserted at the points' core parameters and at the midpoints of the knot spans
   about them (in u and in v; the surface is unchanged), so the refined space holds splines that
   vanish at every skinned point but not at these points;
2. a height correction ``δ`` on the refined net minimises ``λ · E(δ) + Σ wᵢ (δ(uᵢ, vᵢ) − rᵢ)²``
   (``E`` the bending energy, ``rᵢ`` the height misfit of the soft points) subject to
   ``δ = 0`` at every skinned point and ``δ = rⱼ`` at the hard points, solved as one sparse KKT
   system (the skinned points make it definite: no affine correction vanishes on them).

Only the heights move, so the in-plane map, and with it every point's parameters, stays the same;
the corrected core is the fixed block of the rim fit as before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import NurbsNet, greville_abscissae, surface_points
from geobrep.plugins.fit._approximation import smoothing_weight
from geobrep.plugins.fit._bending import bending_matrix
from geobrep.plugins.fit._design import normal_equations, surface_design_matrix
from geobrep.plugins.fit._domain_map import planar_map
from geobrep.plugins.fit._knots import insert_knots
from geobrep.plugins.fit._projection import invert_planar_map
from geobrep.plugins.fit._skinning import SkinnedNet

__all__ = ["CoreCorrection", "correct_core", "inside_core", "on_core_points"]

#: Core parameters closer than this share one inserted knot.
_KNOT_MERGE = 1e-6


@dataclass(frozen=True)
class CoreCorrection:
    """The corrected core and what the correction did."""

    skinned: SkinnedNet
    """The core on the refined net with corrected heights (same point parameters)."""
    inserted: tuple[int, int]
    """Knots inserted in u and in v."""
    max_correction: float
    """Largest height change of a control point."""
    max_misfit: float = 0.0
    """Largest height misfit of the points before the correction."""


def inside_core(skinned: SkinnedNet, local: FloatArray) -> tuple[NDArray[np.bool_], FloatArray]:
    """Which points ``(m, 3)`` lie over the core's patch, and their core parameters ``(m, 2)``."""
    net = skinned.net
    xy = net.control_points[..., :2].reshape(-1, 2)
    scale = float(np.ptp(xy, axis=0).max()) if xy.size else 1.0
    inside = np.zeros(local.shape[0], dtype=bool)
    params = np.zeros((local.shape[0], 2))
    # the patch lies in the convex hull of its control points: only points in their box can be on it
    margin = 1e-9 * (scale or 1.0)
    near = np.flatnonzero(
        np.all(
            (local[:, :2] >= xy.min(axis=0) - margin) & (local[:, :2] <= xy.max(axis=0) + margin),
            axis=1,
        )
    )
    if near.size == 0:
        return inside, params
    flat = planar_map(
        (net.degree_u, net.degree_v), (net.knots_u, net.knots_v), net.control_points[..., :2]
    )
    u, v, residual = invert_planar_map(flat, local[near, :2])
    inside[near] = residual <= 1e-9 * (scale or 1.0)
    params[near] = np.column_stack([u, v])
    return inside, params


#: Spans on either side of a point's span that are halved as well (the correction's room).
NEIGHBOUR_SPANS = 1


def _new_knots(knots: FloatArray, degree: int, params: FloatArray) -> FloatArray:
    """The points' parameters and the midpoints of the spans about them, unless knots already
    (one per cluster)."""
    breaks = np.unique(knots)
    span = np.clip(np.searchsorted(breaks, params, side="right") - 1, 0, breaks.size - 2)
    offsets = np.arange(-NEIGHBOUR_SPANS, NEIGHBOUR_SPANS + 1)
    around = np.unique(np.clip(span[:, None] + offsets[None, :], 0, breaks.size - 2))
    midpoints = 0.5 * (breaks[around] + breaks[around + 1])
    params = np.concatenate([params, midpoints])
    inner = np.sort(params[(params > knots[degree]) & (params < knots[-degree - 1])])
    if inner.size == 0:
        return inner
    keep = np.r_[True, np.diff(inner) > _KNOT_MERGE]
    inner = inner[keep]
    nearest = np.abs(inner[:, None] - np.unique(knots)[None, :]).min(axis=1)
    return np.asarray(inner[nearest > _KNOT_MERGE], dtype=np.float64)


def _refine(net: NurbsNet, new_u: FloatArray, new_v: FloatArray) -> NurbsNet:
    p, q = net.degree_u, net.degree_v
    points = net.control_points
    nu, nv, c = points.shape
    ku, kv = net.knots_u, net.knots_v
    if new_u.size:
        ku, flat = insert_knots(p, ku, points.reshape(nu, nv * c), new_u)
        points = flat.reshape(-1, nv, c)
        nu = points.shape[0]
    if new_v.size:
        turned = points.transpose(1, 0, 2).reshape(nv, nu * c)
        kv, flat = insert_knots(q, kv, turned, new_v)
        points = flat.reshape(-1, nu, c).transpose(1, 0, 2)
    return NurbsNet(p, q, ku, kv, np.ascontiguousarray(points))


def on_core_points(
    core: FloatArray, points: FloatArray, hard: NDArray[np.bool_], label: str
) -> NDArray[np.bool_]:
    """Which points ``(m, 3)`` lie on a skinned point of ``core (n, 3)`` in map view (world x,
    y): they need no correction, and hard data among them must be at the core point's height.

    Raises:
        DegenerateGeometryError: a hard point lies on a core point at another height.
    """
    size = float(np.ptp(core[:, :2], axis=0).max()) or 1.0
    distance, nearest = cKDTree(core[:, :2]).query(points[:, :2])
    on_core = np.asarray(distance <= 1e-9 * size)
    apart = np.abs(points[:, 2] - core[nearest, 2])
    clash = on_core & hard & (apart > 1e-9 * max(size, float(np.ptp(core[:, 2]))))
    if clash.any():
        first = int(np.flatnonzero(clash)[0])
        x, y, z = points[first]
        raise DegenerateGeometryError(
            f"{label}: {int(clash.sum())} hard point(s) inside the skinned core cannot be met "
            f"without moving a core point: the point at x = {x:.3f}, y = {y:.3f}, z = {z:.3f} "
            f"lies on a core point {apart[first]:.4g} above or below it; remove the duplicate "
            "or flag it as a core point"
        )
    return on_core


def correct_core(
    skinned: SkinnedNet,
    params: FloatArray,
    heights: FloatArray,
    hard: NDArray[np.bool_],
    weights: FloatArray | None,
    smoothing: float,
    label: str,
) -> CoreCorrection:
    """The core corrected to meet the hard points and approach the soft ones (see module doc).

    ``params`` are the points' core parameters ``(m, 2)`` (from :func:`inside_core`), ``heights``
    their local heights, ``weights`` the soft points' misfit weights (None: 1), ``smoothing`` the
    dimensionless bending weight of the soft fit.

    Raises:
        DegenerateGeometryError: a hard point cannot be met without moving a skinned point (it
            lies on one at another height, or two hard points coincide).
    """
    net = skinned.net
    p, q = net.degree_u, net.degree_v
    refined = _refine(
        net,
        _new_knots(net.knots_u, p, params[:, 0]),
        _new_knots(net.knots_v, q, params[:, 1]),
    )
    ku, kv = refined.knots_u, refined.knots_v
    nu, nv = refined.shape
    u_core, v_core = skinned.point_parameters()
    u, v = params[:, 0], params[:, 1]
    misfit = heights - surface_points(refined, u, v)[:, 2]
    scale = max(1.0, float(np.abs(refined.control_points[..., 2]).max()))
    # bending energy on the net laid out at its physical size (the core's mean side lengths)
    xy = refined.control_points[..., :2]
    length_u = float(np.linalg.norm(xy[-1] - xy[0], axis=1).mean()) or 1.0
    length_v = float(np.linalg.norm(xy[:, -1] - xy[:, 0], axis=1).mean()) or 1.0
    energy = bending_matrix(
        greville_abscissae(p, ku) * length_u, greville_abscissae(q, kv) * length_v
    )
    soft = ~hard
    hessian = sp.csr_matrix(energy / max(float(np.abs(energy.diagonal()).max()), 1e-300))
    gradient = np.zeros(nu * nv)
    if soft.any():
        lam = smoothing_weight(smoothing, int(soft.sum()), length_u, length_v)
        normal, rhs = normal_equations(
            p, q, ku, kv, u[soft], v[soft], misfit[soft], None if weights is None else weights[soft]
        )
        hessian = sp.csr_matrix(lam * energy + normal)
        gradient = rhs[:, 0]
    blocks = [surface_design_matrix(p, q, ku, kv, u_core, v_core)]
    if hard.any():
        blocks.append(surface_design_matrix(p, q, ku, kv, u[hard], v[hard]))
    constraints = sp.vstack(blocks, format="csr")
    targets = np.r_[np.zeros(u_core.shape[0]), misfit[hard]]
    kkt = sp.bmat([[hessian, constraints.T], [constraints, None]], format="csc")
    unmet = (
        f"{label}: {int(hard.sum())} hard point(s) inside the skinned core cannot be met without "
        "moving a core point (one lies on a core point at another height, or two coincide); "
        "remove the duplicate or flag it as a core point"
    )
    try:
        solution = spla.splu(kkt).solve(np.r_[gradient, targets])
    except RuntimeError as exc:  # an exactly singular KKT matrix
        raise DegenerateGeometryError(unmet) from exc
    delta = solution[: nu * nv]
    if not np.isfinite(delta).all():
        raise DegenerateGeometryError(unmet)
    miss = np.abs(constraints @ delta - targets).max(initial=0.0)
    if miss > 1e-9 * scale:
        raise DegenerateGeometryError(f"{unmet} (residual {miss:.3g})")
    points = refined.control_points.copy()
    points[..., 2] += delta.reshape(nu, nv)
    corrected = refined.with_control_points(points)
    return CoreCorrection(
        SkinnedNet(corrected, skinned.row_parameters, skinned.section_parameters),
        (nu - net.shape[0], nv - net.shape[1]),
        float(np.abs(delta).max(initial=0.0)),
        float(np.abs(misfit).max(initial=0.0)),
    )
