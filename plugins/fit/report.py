"""The accuracy report of a fit: ``σ = sqrt(Σ dᵢ² / (n − 1))`` over point-to-surface distances.

σ, max |d| and n overall and per subset (core, rim, ...), pass/fail against the control error ε,
and the points with the largest deviations (Li et al. 2011, eq. 3).

>>> import numpy as np
>>> report = accuracy_report(np.array([0.1, -0.2, 0.2, 0.0]), np.zeros((4, 3)), epsilon=0.5,
...                          subsets={"core": np.array([True, True, False, False])})
>>> round(report.sigma, 4), report.passed, report.subsets["core"].n
(0.1732, True, 2)
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry.arrays import FloatArray
from geobrep.plugins import Deviation, FitReport, SubsetReport

__all__ = ["accuracy_report", "sigma"]


def sigma(distances: FloatArray) -> float:
    """``sqrt(Σ d² / (n − 1))`` (``n`` for a single point, 0 for none)."""
    n = distances.shape[0]
    if n == 0:
        return 0.0
    return float(np.sqrt(np.sum(distances**2) / max(n - 1, 1)))


def _subset(distances: FloatArray, epsilon: float | None) -> SubsetReport:
    return SubsetReport.from_distances(distances, epsilon)


def accuracy_report(
    distances: FloatArray,
    points: FloatArray,
    *,
    epsilon: float | None,
    method: str = "",
    subsets: Mapping[str, NDArray[np.bool_]] | None = None,
    labels: NDArray[np.str_] | None = None,
    n_worst: int = 10,
    seam_gap: float | None = None,
    notes: list[str] | None = None,
    details: dict[str, object] | None = None,
) -> FitReport:
    """Build a :class:`~geobrep.ops.fitting.FitReport` from signed distances ``(n,)``.

    ``subsets`` maps a name to a boolean mask over the points; ``labels`` (optional) names the
    subset of each point in the list of largest deviations.
    """
    d = np.asarray(distances, dtype=np.float64)
    overall = _subset(d, epsilon)
    parts = {name: _subset(d[mask], epsilon) for name, mask in (subsets or {}).items()}
    worst_index = np.argsort(-np.abs(d), kind="stable")[:n_worst]
    worst = [
        Deviation(
            index=int(i),
            point=(float(points[i, 0]), float(points[i, 1]), float(points[i, 2])),
            distance=float(d[i]),
            subset=str(labels[i]) if labels is not None else "",
        )
        for i in worst_index
    ]
    all_notes = list(notes or [])
    if epsilon is not None and not overall.passed and not any("ε" in note for note in all_notes):
        all_notes.append(
            f"σ = {overall.sigma:.4g} does not meet ε = {epsilon:g}; the largest deviations are "
            f"listed under 'worst'"
        )
    return FitReport(
        method=method,
        sigma=overall.sigma,
        max_abs=overall.max_abs,
        n=overall.n,
        epsilon=epsilon,
        passed=overall.passed,
        subsets=parts,
        worst=worst,
        seam_gap=seam_gap,
        notes=all_notes,
        details=dict(details or {}),
    )
