"""Sparse design (collocation) matrices of B-spline curves and tensor-product surfaces.

Row ``i`` holds the basis functions (or a derivative of them) at data parameter ``i``; a cubic
surface has 16 non-zeros per row, so the matrices are built straight into CSR form from the
vectorised basis of :mod:`geobrep.geometry.nurbs` without any per-point Python work.

:func:`normal_equations` goes one step further for least squares: it never forms the design
matrix. Points are grouped by knot cell, every cell's ``(p+1)(q+1)``-square Gram block is one
batched matrix product, and the blocks are summed into the sparse normal matrix.

>>> import numpy as np
>>> knots = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
>>> curve_design_matrix(2, knots, np.array([0.0, 0.5, 1.0])).toarray().tolist()
[[1.0, 0.0, 0.0], [0.25, 0.5, 0.25], [0.0, 0.0, 1.0]]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import basis_derivatives, basis_functions, find_spans

__all__ = ["curve_design_matrix", "normal_equations", "surface_design_matrix"]


def _basis(
    degree: int, knots: FloatArray, params: FloatArray, derivative: int
) -> tuple[NDArray[np.int64], FloatArray]:
    spans = find_spans(degree, knots, params)
    if derivative == 0:
        return spans, basis_functions(degree, knots, spans, params)
    return spans, basis_derivatives(degree, knots, spans, params, derivative)[:, derivative, :]


def curve_design_matrix(
    degree: int, knots: FloatArray, params: FloatArray, derivative: int = 0
) -> sp.csr_matrix:
    """``(m, n_ctrl)`` CSR matrix of the basis functions (or a derivative) at ``params``."""
    t = np.asarray(params, dtype=np.float64).reshape(-1)
    n_ctrl = knots.shape[0] - degree - 1
    spans, values = _basis(degree, knots, t, derivative)
    columns = spans[:, None] - degree + np.arange(degree + 1)
    indptr = np.arange(0, t.shape[0] * (degree + 1) + 1, degree + 1)
    matrix = sp.csr_matrix(
        (values.reshape(-1), columns.reshape(-1), indptr), shape=(t.shape[0], n_ctrl)
    )
    matrix.has_sorted_indices = True
    return matrix


def surface_design_matrix(
    degree_u: int,
    degree_v: int,
    knots_u: FloatArray,
    knots_v: FloatArray,
    u: FloatArray,
    v: FloatArray,
    derivative: tuple[int, int] = (0, 0),
) -> sp.csr_matrix:
    """``(m, nu · nv)`` CSR matrix; column ``i · nv + j`` is control point ``(i, j)``.

    ``derivative=(k, l)`` gives ``∂^(k+l) / ∂u^k ∂v^l`` of the basis instead of its values.
    """
    uu = np.asarray(u, dtype=np.float64).reshape(-1)
    vv = np.asarray(v, dtype=np.float64).reshape(-1)
    m = uu.shape[0]
    nu = knots_u.shape[0] - degree_u - 1
    nv = knots_v.shape[0] - degree_v - 1
    su, bu = _basis(degree_u, knots_u, uu, derivative[0])
    sv, bv = _basis(degree_v, knots_v, vv, derivative[1])
    rows_u = su[:, None] - degree_u + np.arange(degree_u + 1)
    cols_v = sv[:, None] - degree_v + np.arange(degree_v + 1)
    values = (bu[:, :, None] * bv[:, None, :]).reshape(m, -1)
    columns = (rows_u[:, :, None] * nv + cols_v[:, None, :]).reshape(m, -1)
    width = (degree_u + 1) * (degree_v + 1)
    indptr = np.arange(0, m * width + 1, width)
    matrix = sp.csr_matrix((values.reshape(-1), columns.reshape(-1), indptr), shape=(m, nu * nv))
    matrix.has_sorted_indices = True
    return matrix


#: Points per batched block when forming cell Gram matrices (bounds the padding memory).
_CELL_CHUNK = 32


def normal_equations(
    degree_u: int,
    degree_v: int,
    knots_u: FloatArray,
    knots_v: FloatArray,
    u: FloatArray,
    v: FloatArray,
    values: FloatArray,
    weights: FloatArray | None = None,
) -> tuple[sp.csr_matrix, FloatArray]:
    """``(Bᵀ W B, Bᵀ W y)`` of the surface design matrix ``B`` without forming ``B``.

    ``values`` is ``(m,)`` or ``(m, k)``; the right-hand side has shape ``(nu · nv, k)``.

    >>> import numpy as np
    >>> k = np.array([0.0, 0.0, 1.0, 1.0])
    >>> N, r = normal_equations(1, 1, k, k, np.array([0.0, 1.0]), np.array([0.0, 1.0]),
    ...                         np.array([2.0, 3.0]))
    >>> N.toarray().diagonal().tolist(), r[:, 0].tolist()
    ([1.0, 0.0, 0.0, 1.0], [2.0, 0.0, 0.0, 3.0])
    """
    uu = np.asarray(u, dtype=np.float64).reshape(-1)
    vv = np.asarray(v, dtype=np.float64).reshape(-1)
    y = np.asarray(values, dtype=np.float64).reshape(uu.shape[0], -1)
    m, k = y.shape
    nu = knots_u.shape[0] - degree_u - 1
    nv = knots_v.shape[0] - degree_v - 1
    su, bu = _basis(degree_u, knots_u, uu, 0)
    sv, bv = _basis(degree_v, knots_v, vv, 0)
    width = (degree_u + 1) * (degree_v + 1)
    cell = (su - degree_u) * nv + (sv - degree_v)  # index of the cell's first control point
    order = np.argsort(cell, kind="stable")
    cells, starts, counts = np.unique(cell[order], return_index=True, return_counts=True)
    group = np.repeat(np.arange(cells.shape[0]), counts)
    rank = np.arange(m) - starts[group]
    # split crowded cells into blocks of at most _CELL_CHUNK points
    blocks_per_cell = (counts + _CELL_CHUNK - 1) // _CELL_CHUNK
    first_block = np.r_[0, np.cumsum(blocks_per_cell)[:-1]]
    block = first_block[group] + rank // _CELL_CHUNK
    slot = rank % _CELL_CHUNK
    n_blocks = int(blocks_per_cell.sum())
    rows = np.zeros((n_blocks, min(_CELL_CHUNK, int(counts.max(initial=1))), width + k))
    scale = np.ones(m) if weights is None else np.sqrt(np.asarray(weights, np.float64)[order])
    rows[block, slot, :width] = (bu[order][:, :, None] * bv[order][:, None, :]).reshape(
        m, width
    ) * scale[:, None]
    rows[block, slot, width:] = y[order] * scale[:, None]
    gram = np.matmul(rows.transpose(0, 2, 1)[:, :width, :], rows)  # (n_blocks, width, width + k)
    block_cell = np.repeat(cells, blocks_per_cell)
    local = (np.arange(degree_u + 1)[:, None] * nv + np.arange(degree_v + 1)).reshape(-1)
    index = block_cell[:, None] + local[None, :]
    n = nu * nv
    normal = sp.csr_matrix(
        (
            gram[:, :, :width].reshape(-1),
            (
                np.broadcast_to(index[:, :, None], (n_blocks, width, width)).reshape(-1),
                np.broadcast_to(index[:, None, :], (n_blocks, width, width)).reshape(-1),
            ),
        ),
        shape=(n, n),
    )
    rhs = np.zeros((n, k))
    flat_index = index.reshape(-1)
    for column in range(k):
        rhs[:, column] = np.bincount(
            flat_index, gram[:, :, width + column].reshape(-1), minlength=n
        )
    return normal, rhs
