"""Penalised, constrained least squares for control nets.

Minimise ``Σ wᵢ (B c − y)ᵢ² + λ cᵀ K c`` over the free control points, with the fixed ones (boundary
curves, a skinned core) held at given values. The normal matrix is symmetric positive definite
and banded (row-major nets couple rows ``i`` and ``i ± p``), so it is factored by a banded
Cholesky after dropping the fixed unknowns.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache
from typing import Any

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray

__all__ = ["single_threaded_blas", "solve_penalised"]


@cache
def _blas_controller() -> Any:
    try:
        from threadpoolctl import ThreadpoolController  # type: ignore[import-untyped]
    except ImportError:  # optional: without it BLAS keeps its own thread count
        return None
    return ThreadpoolController()


@contextmanager
def single_threaded_blas() -> Iterator[None]:
    """Run BLAS/LAPACK on one thread inside the block.

    Banded and batched small factorisations gain nothing from BLAS threads, and on a busy
    machine OpenBLAS thread hand-offs can make them a thousand times slower.
    """
    controller = _blas_controller()
    if controller is None:
        yield
        return
    with controller.limit(limits=1, user_api="blas"):
        yield


def _factor_spd(matrix: sp.csr_matrix, what: str) -> Callable[[FloatArray], FloatArray]:
    """Factor an SPD sparse matrix (banded Cholesky when the band is narrow, else sparse LU)."""
    n = matrix.shape[0]
    coo = matrix.tocoo()
    band = int(np.abs(coo.row - coo.col).max(initial=0))
    singular = (
        f"{what}: the least-squares system is singular (too few points for the control net, or "
        "points on a line); use fewer control points or more smoothing"
    )
    if band * n <= 60_000_000:
        upper = coo.row <= coo.col
        banded = np.zeros((band + 1, n))
        banded[band + coo.row[upper] - coo.col[upper], coo.col[upper]] = coo.data[upper]
        try:
            with single_threaded_blas():
                factor = la.cholesky_banded(banded, lower=False, check_finite=False)
        except la.LinAlgError as exc:
            raise DegenerateGeometryError(singular) from exc
        if not np.all(factor[band] > 1e-12 * np.abs(factor[band]).max(initial=0.0)):
            raise DegenerateGeometryError(singular)

        def solve_banded(rhs: FloatArray) -> FloatArray:
            with single_threaded_blas():
                return np.asarray(la.cho_solve_banded((factor, False), rhs, check_finite=False))

        return solve_banded
    lu = spla.splu(matrix.tocsc())

    def solve(rhs: FloatArray) -> FloatArray:
        solution = np.asarray(lu.solve(np.asarray(rhs, dtype=np.float64)))
        if not np.isfinite(solution).all():
            raise DegenerateGeometryError(singular)
        return solution

    return solve


def _drop_met(
    a_free: sp.csr_matrix, t: FloatArray, targets: FloatArray, what: str
) -> tuple[sp.csr_matrix, FloatArray]:
    """The exact conditions that involve a free control point; the others must already hold.

    A point whose control points are all held fixed (inside a fixed block, such as a skinned
    core that was corrected to pass through it) constrains nothing, and is met or contradicts.
    """
    involved = np.asarray(abs(a_free).sum(axis=1)).ravel() > 0
    if bool(involved.all()):
        return a_free, t
    tolerance = 1e-6 * max(1.0, float(np.abs(targets).max(initial=0.0)))
    miss = np.abs(t[~involved]).max(initial=0.0)
    if miss > tolerance:
        rows = np.flatnonzero(~involved)
        raise DegenerateGeometryError(
            f"{what}: {rows.size} point(s) to interpolate exactly (the first is exact point "
            f"{int(rows[0])}) depend only on fixed control points, which miss them by up to "
            f"{miss:.3g}; give them as free data or fix fewer control points"
        )
    return sp.csr_matrix(a_free[involved]), t[involved]


def solve_penalised(
    normal: sp.csr_matrix,
    rhs: FloatArray,
    *,
    penalty: sp.csr_matrix | None = None,
    smoothing: float = 0.0,
    fixed: NDArray[np.bool_] | None = None,
    fixed_values: FloatArray | None = None,
    equality: tuple[sp.csr_matrix, FloatArray] | None = None,
    what: str = "fit",
) -> FloatArray:
    """Control values ``(n, k)`` from the normal equations ``(N + λK) c = r`` with constraints.

    ``normal`` and ``rhs`` are ``Bᵀ W B`` and ``Bᵀ W y`` (see
    :func:`~geobrep.plugins.fit._design.normal_equations`); ``fixed`` marks control points held at
    ``fixed_values`` (rows of an ``(n, k)`` array); ``equality = (A, t)`` adds exact conditions
    ``A c = t`` (points the surface must pass through), solved through the Schur complement.

    >>> import numpy as np, scipy.sparse as sp
    >>> solve_penalised(sp.csr_matrix(np.eye(2) * 4.0), np.array([[4.0], [8.0]])).ravel().tolist()
    [1.0, 2.0]
    """
    y = rhs.reshape(rhs.shape[0], -1)
    n = normal.shape[0]
    matrix = sp.csr_matrix(normal)
    if penalty is not None and smoothing > 0:
        matrix = sp.csr_matrix(matrix + smoothing * penalty)
    solution = np.zeros((n, y.shape[1]))
    is_fixed = np.zeros(n, dtype=bool) if fixed is None else fixed.reshape(-1)
    free = np.flatnonzero(~is_fixed)
    known = np.zeros((0, y.shape[1]))
    if is_fixed.any():
        assert fixed_values is not None
        known = fixed_values.reshape(n, -1)[is_fixed]
        solution[is_fixed] = known
    if free.size == 0:
        return solution
    fixed_index = np.flatnonzero(is_fixed)
    reduced = sp.csr_matrix(matrix[free][:, free])
    reduced_rhs = y[free] - (matrix[free][:, fixed_index] @ known if fixed_index.size else 0.0)
    solve = _factor_spd(reduced, what)
    free_solution = solve(reduced_rhs)
    if equality is not None and equality[0].shape[0]:
        a_all, targets = equality
        a_all = sp.csr_matrix(a_all)
        t = targets.reshape(targets.shape[0], -1) - (
            a_all[:, fixed_index] @ known if fixed_index.size else 0.0
        )
        a_free, t = _drop_met(a_all[:, free], t, targets, what)
        if a_free.shape[0] == 0:
            solution[free] = free_solution
            return solution
        y_mat = solve(a_free.T.toarray())  # (n_free, k)
        schur = np.asarray(a_free @ y_mat)
        try:
            mu = np.linalg.solve(schur, np.asarray(a_free @ free_solution) - t)
        except np.linalg.LinAlgError as exc:
            raise DegenerateGeometryError(
                f"{what}: the points to interpolate exactly cannot all be met by this net (two "
                "of them share the same control points); use a finer net"
            ) from exc
        free_solution = free_solution - y_mat @ mu
        miss = np.abs(np.asarray(a_free @ free_solution) - t).max(initial=0.0)
        if miss > 1e-6 * max(1.0, float(np.abs(t).max(initial=0.0))):
            raise DegenerateGeometryError(
                f"{what}: the points to interpolate exactly cannot all be met by this net "
                f"(residual {miss:.3g}); use a finer net"
            )
    solution[free] = free_solution
    return solution
