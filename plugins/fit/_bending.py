"""Bending (thin-plate) energy of a control net, and the discrete Laplacian that fills planar nets.

The energy ``∫∫ h_aa² + 2 h_ab² + h_bb² da db`` is discretised on the control net, with the
control points placed at their Greville abscissae scaled to physical lengths: second divided
differences along each direction and mixed first differences across, weighted by the area each
node or cell stands for. Linear functions have zero energy, and the weights make the energy
independent of how finely the net is laid out.

>>> import numpy as np
>>> g = np.linspace(0.0, 10.0, 6)
>>> K = bending_matrix(g, g)
>>> plane = (2.0 * g[:, None] + 3.0 * g[None, :]).reshape(-1)
>>> float(abs(plane @ (K @ plane)))
0.0
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from geobrep.geometry.arrays import FloatArray

__all__ = ["bending_matrix", "dual_widths", "laplacian_matrix", "second_difference"]


def dual_widths(g: FloatArray) -> FloatArray:
    """Length each node of a 1D grid stands for (half the distance to each neighbour)."""
    if g.shape[0] == 1:
        return np.ones(1)
    gaps = np.diff(g)
    return np.asarray(0.5 * (np.r_[0.0, gaps] + np.r_[gaps, 0.0]))


def second_difference(g: FloatArray) -> sp.csr_matrix:
    """``(n - 2, n)`` second divided differences on the non-uniform grid ``g``."""
    n = g.shape[0]
    if n < 3:
        return sp.csr_matrix((0, n))
    left = g[1:-1] - g[:-2]
    right = g[2:] - g[1:-1]
    scale = 2.0 / (left + right)
    rows = np.repeat(np.arange(n - 2), 3)
    cols = (np.arange(n - 2)[:, None] + np.arange(3)).reshape(-1)
    vals = np.column_stack([scale / left, -scale * (1.0 / left + 1.0 / right), scale / right])
    return sp.csr_matrix((vals.reshape(-1), (rows, cols)), shape=(n - 2, n))


def _first_difference(g: FloatArray) -> sp.csr_matrix:
    n = g.shape[0]
    if n < 2:
        return sp.csr_matrix((0, n))
    inv = 1.0 / np.diff(g)
    rows = np.repeat(np.arange(n - 1), 2)
    cols = (np.arange(n - 1)[:, None] + np.arange(2)).reshape(-1)
    vals = np.column_stack([-inv, inv]).reshape(-1)
    return sp.csr_matrix((vals, (rows, cols)), shape=(n - 1, n))


def bending_matrix(gu: FloatArray, gv: FloatArray) -> sp.csr_matrix:
    """Symmetric ``(nu · nv)²`` matrix ``K`` with ``cᵀ K c`` the bending energy of net ``c``.

    ``gu``, ``gv`` are the physical positions of the control rows and columns (Greville abscissae
    times the parameter-to-length scale); node ``(i, j)`` is entry ``i · nv + j``.
    """
    nu, nv = gu.shape[0], gv.shape[0]
    wu, wv = dual_widths(gu), dual_widths(gv)
    eye_u, eye_v = sp.identity(nu, format="csr"), sp.identity(nv, format="csr")
    parts = []
    d_uu = sp.kron(second_difference(gu), eye_v, format="csr")
    if d_uu.shape[0]:
        parts.append((d_uu, np.outer(wu[1:-1], wv).reshape(-1)))
    d_vv = sp.kron(eye_u, second_difference(gv), format="csr")
    if d_vv.shape[0]:
        parts.append((d_vv, np.outer(wu, wv[1:-1]).reshape(-1)))
    d_uv = sp.kron(_first_difference(gu), _first_difference(gv), format="csr")
    if d_uv.shape[0]:
        parts.append((d_uv, 2.0 * np.outer(np.diff(gu), np.diff(gv)).reshape(-1)))
    total = sp.csr_matrix((nu * nv, nu * nv))
    for operator, weights in parts:
        total = total + operator.T @ sp.diags(weights) @ operator
    return sp.csr_matrix(total)


def laplacian_matrix(gu: FloatArray, gv: FloatArray) -> sp.csr_matrix:
    """Five-point Laplacian on the non-uniform net ``gu × gv`` (rows of boundary nodes are empty).

    It is exact for linear functions, so a net whose boundary is a planar parallelogram is filled
    with the affine map.
    """
    nu, nv = gu.shape[0], gv.shape[0]

    def padded(g: FloatArray) -> sp.csr_matrix:
        inner = second_difference(g)
        return sp.vstack(
            [sp.csr_matrix((1, g.shape[0])), inner, sp.csr_matrix((1, g.shape[0]))], format="csr"
        )

    lu, lv = padded(gu), padded(gv)
    interior_u = np.zeros(nu)
    interior_u[1:-1] = 1.0
    interior_v = np.zeros(nv)
    interior_v[1:-1] = 1.0
    mask_v, mask_u = sp.diags(interior_v), sp.diags(interior_u)
    return sp.csr_matrix(sp.kron(lu, mask_v) + sp.kron(mask_u, lv))
