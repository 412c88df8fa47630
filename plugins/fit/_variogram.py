"""Variogram models, the experimental variogram, and model fitting.

Models follow PyKrige's definitions and parameters, so its users get the same numbers:
``γ(h) = nugget + psill · f(h / range)`` with ``psill = sill − nugget`` and

* spherical: ``f = 1.5 t − 0.5 t³`` for ``t < 1``, else 1 (``t = h / range``);
* exponential: ``f = 1 − exp(−3 h / range)``;
* gaussian: ``f = 1 − exp(−(7 h / (4 range))²)``;
* matern: ``f = 1 − 2^(1−ν)/Γ(ν) · x^ν K_ν(x)``, ``x = √(2ν) · 3 h / range`` (ν = 0.5: the
  exponential).

The covariance used by the kriging systems is ``C(h) = sill − γ(h)``, with ``C(0) = sill``.

>>> model = Variogram("spherical", sill=2.0, range=10.0, nugget=0.5)
>>> model.semivariance(np.array([0.0, 5.0, 20.0])).round(4).tolist()
[0.0, 1.5312, 2.0]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import optimize, special
from scipy.spatial.distance import pdist

from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray

__all__ = [
    "MODELS",
    "Variogram",
    "experimental_variogram",
    "fit_variogram",
    "variogram_from_options",
]

MODELS = ("spherical", "exponential", "gaussian", "matern")


def _structure(model: str, h: FloatArray, range_: float, nu: float) -> FloatArray:
    """``f(h)``: the normalised structured part, 0 at 0 and 1 at infinity."""
    if model == "spherical":
        t = np.minimum(h / range_, 1.0)
        return np.asarray(1.5 * t - 0.5 * t**3)
    if model == "exponential":
        return np.asarray(1.0 - np.exp(-h / (range_ / 3.0)))
    if model == "gaussian":
        return np.asarray(1.0 - np.exp(-(h**2) / (range_ * 4.0 / 7.0) ** 2))
    if model == "matern":
        x = np.sqrt(2.0 * nu) * h / (range_ / 3.0)
        with np.errstate(invalid="ignore", over="ignore"):
            corr = (2.0 ** (1.0 - nu) / special.gamma(nu)) * x**nu * special.kv(nu, x)
        corr = np.where(x > 0, corr, 1.0)
        corr = np.where(np.isfinite(corr), corr, 0.0)
        return np.asarray(1.0 - corr)
    raise OptionsError(f"unknown variogram model {model!r}; use one of {', '.join(MODELS)}")


def _correlation(model: str, h: FloatArray, range_: float, nu: float) -> FloatArray:
    """``1 − f(h)``, computed in place in one new array (the covariance is ``psill`` times it)."""
    out = np.empty(np.shape(h))
    if model == "spherical":
        t = np.minimum(h, range_) / range_
        np.multiply(t, t, out=out)  # 1 − 1.5 t + 0.5 t³ = 1 − t (1.5 − 0.5 t²)
        out *= -0.5
        out += 1.5
        out *= t
        return np.subtract(1.0, out, out=out)
    if model == "exponential":
        np.multiply(h, -3.0 / range_, out=out)
        return np.exp(out, out=out)
    if model == "gaussian":
        np.multiply(h, h, out=out)
        out *= -1.0 / (range_ * 4.0 / 7.0) ** 2
        return np.exp(out, out=out)
    out[...] = 1.0 - _structure(model, h, range_, nu)
    return out


@dataclass(frozen=True)
class Variogram:
    """A bounded variogram: ``model``, total ``sill``, ``range``, ``nugget`` (Matérn ``nu``)."""

    model: str
    sill: float
    range: float
    nugget: float = 0.0
    nu: float = 1.5

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise OptionsError(
                f"option 'variogram_model': unknown model {self.model!r}; "
                f"use one of {', '.join(MODELS)}"
            )
        if not (self.range > 0 and np.isfinite(self.range)):
            raise OptionsError(
                f"option 'variogram_parameters': range must be > 0, got {self.range}"
            )
        if not (0 <= self.nugget <= self.sill) or not np.isfinite(self.sill):
            raise OptionsError(
                "option 'variogram_parameters': need 0 ≤ nugget ≤ sill, got "
                f"sill {self.sill}, nugget {self.nugget}"
            )
        if self.sill <= 0:
            raise OptionsError("option 'variogram_parameters': sill must be > 0")
        if self.model == "matern" and not self.nu > 0:
            raise OptionsError(f"option 'variogram_parameters': nu must be > 0, got {self.nu}")

    @property
    def psill(self) -> float:
        """Partial sill ``sill − nugget``."""
        return self.sill - self.nugget

    def semivariance(self, h: FloatArray) -> FloatArray:
        """``γ(h)``, zero at ``h = 0`` (the nugget is a jump just after zero)."""
        value = self.nugget + self.psill * _structure(self.model, h, self.range, self.nu)
        return np.asarray(np.where(h > 0, value, 0.0))

    def covariance(self, h: FloatArray, exact_at: float | None = None) -> FloatArray:
        """``C(h) = sill − γ(h)`` for ``h > 0``; ``sill − nugget`` at 0 unless ``h <= exact_at``.

        The data-to-data matrix and exact-valued kriging use ``C(0) = sill`` (``exact_at`` ≥ 0);
        without it a target on a datum sees only the structured part (PyKrige's
        ``exact_values=False``).
        """
        value = _correlation(self.model, h, self.range, self.nu)
        value *= self.psill
        if exact_at is not None:
            value = np.where(h <= exact_at, self.sill, value)
        return np.asarray(value)

    def as_dict(self) -> dict[str, float | str]:
        out: dict[str, float | str] = {
            "model": self.model,
            "sill": self.sill,
            "range": self.range,
            "nugget": self.nugget,
        }
        if self.model == "matern":
            out["nu"] = self.nu
        return out


def variogram_from_options(
    model: str, parameters: Mapping[str, float] | Sequence[float]
) -> Variogram:
    """A Variogram from PyKrige-style parameters: a dict or ``[sill, range, nugget]``."""
    if isinstance(parameters, Mapping):
        nugget = float(parameters.get("nugget", 0.0))
        if "sill" in parameters:
            sill = float(parameters["sill"])
        else:
            sill = float(parameters["psill"]) + nugget
        return Variogram(
            model, sill, float(parameters["range"]), nugget, float(parameters.get("nu", 1.5))
        )
    sill, range_, nugget = (float(x) for x in parameters)
    return Variogram(model, sill, range_, nugget)


def experimental_variogram(
    xy: FloatArray,
    z: FloatArray,
    nlags: int = 12,
    max_lag: float | None = None,
    max_pairs: int = 3_000_000,
    seed: int = 0,
) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
    """Binned semivariance ``½ mean (zᵢ − zⱼ)²``: mean lag, semivariance and pair count per bin.

    All pairs are used up to ``max_pairs`` (a seeded random subset beyond); bins are equal
    widths up to ``max_lag`` (half the largest distance by default). Empty bins are dropped.
    """
    n = xy.shape[0]
    if n * (n - 1) // 2 <= max_pairs:
        distance = pdist(xy)
        squared = pdist(z[:, None], "sqeuclidean")
    else:
        rng = np.random.default_rng(seed)
        i = rng.integers(0, n, max_pairs)
        j = rng.integers(0, n, max_pairs)
        keep = i != j
        i, j = i[keep], j[keep]
        distance = np.linalg.norm(xy[i] - xy[j], axis=1)
        squared = (z[i] - z[j]) ** 2
    if max_lag is None:
        max_lag = 0.5 * float(distance.max(initial=0.0))
    if not max_lag > 0:
        raise DegenerateGeometryError("kriging: all points share one location")
    edges = np.linspace(0.0, max_lag, nlags + 1)
    which = np.searchsorted(edges, distance, side="right") - 1
    inside = (which >= 0) & (which < nlags) & (distance > 0)
    counts = np.bincount(which[inside], minlength=nlags)
    sum_d = np.bincount(which[inside], distance[inside], minlength=nlags)
    sum_g = np.bincount(which[inside], 0.5 * squared[inside], minlength=nlags)
    used = counts > 0
    return sum_d[used] / counts[used], sum_g[used] / counts[used], counts[used].astype(np.int64)


def fit_variogram(
    lags: FloatArray,
    semivariance: FloatArray,
    counts: NDArray[np.int64],
    model: str,
    *,
    weight: bool = False,
    nu: float = 1.5,
) -> Variogram:
    """Weighted least-squares fit of ``model`` to an experimental variogram.

    Cressie's criterion (relative misfit per bin, weighted by the pair counts) with a robust
    soft-L1 loss as PyKrige uses; ``weight`` further favours short lags.

    Raises:
        DegenerateGeometryError: the values do not vary (zero semivariance everywhere).
    """
    top = float(semivariance.max(initial=0.0))
    if not top > 0:
        raise DegenerateGeometryError("kriging: the values do not vary; nothing to krige")
    span = float(lags.max())
    w = np.sqrt(counts / counts.max())
    if weight:
        w = w / (1.0 + np.exp(np.clip(10.0 * (lags / span - 0.7), -50, 50)))

    def residuals(params: FloatArray) -> FloatArray:
        # Cressie's weighted least squares: relative misfit, weighted by the pair counts
        psill, range_, nugget = params
        model_values = nugget + psill * _structure(model, lags, range_, nu)
        return np.asarray(w * (semivariance / np.maximum(model_values, 1e-12 * top) - 1.0))

    start = np.array([top, 0.5 * span, 0.1 * float(semivariance.min())])
    lower = np.array([1e-9 * top, 1e-3 * span, 0.0])
    upper = np.array([10.0 * top, 10.0 * span, top])
    start = np.clip(start, lower + 1e-12 * top, upper - 1e-12 * top)
    result = optimize.least_squares(residuals, start, bounds=(lower, upper), loss="soft_l1")
    psill, range_, nugget = (float(x) for x in result.x)
    return Variogram(model, psill + nugget, range_, nugget, nu)
