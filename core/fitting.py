"""Surface fitting: ``geobrep.fit`` and its result, the fitted surface with an accuracy report.

``fit(points, method=...)`` looks the method up among the registered fitters (the built-in
``skinning``, ``approximation``, ``kriging`` and ``hybrid`` come from the ``fit`` plugin), validates
the options with the fitter's pydantic model and returns a :class:`FitResult`::

    result = geobrep.fit(points, method="hybrid", epsilon=0.5)
    result.surface          # a NurbsSurface (or a gridded Surface for kriging)
    result.report.sigma     # sqrt(Σ d² / (n − 1)) over the point-to-surface distances
    result.report.subsets["core"].max_abs

The accuracy report follows Li et al. (2011): σ, the largest deviation and the number of points,
overall and per subset, pass/fail against the control error ε, and the points that deviate most.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, JsonValue

from geobrep.entities import Entity, NurbsSurface, PointSet, PolyLine, Surface
from geobrep.errors import EntityValidationError, OptionsError, PluginError

if TYPE_CHECKING:
    from geobrep.demo import DemoContext

__all__ = ["Deviation", "FitReport", "FitResult", "SubsetReport", "demo_stage", "fit"]


class SubsetReport(BaseModel):
    """Accuracy of a fit over a set of points: σ, max |d|, n, and pass/fail against ε."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    sigma: float
    """``sqrt(Σ dᵢ² / (n − 1))`` over the signed point-to-surface distances ``dᵢ``."""
    max_abs: float
    """Largest absolute distance."""
    n: int
    """Number of points."""
    epsilon: float | None = None
    """Control error ε the fit was asked to meet (None: no requirement)."""
    passed: bool | None = None
    """``σ < ε``, or None without ε."""


class Deviation(BaseModel):
    """One of the points farthest from the surface."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    index: int
    """Index of the point in the input."""
    point: tuple[float, float, float]
    distance: float
    """Signed distance (positive on the side the surface normal points to)."""
    subset: str = ""


class FitReport(SubsetReport):
    """The accuracy report: overall figures, the same per subset, the worst points, and notes.

    >>> report = FitReport(sigma=0.2, max_abs=0.4, n=10, epsilon=0.5, passed=True,
    ...                    subsets={"core": SubsetReport(sigma=0.0, max_abs=0.0, n=4)})
    >>> report.subsets["core"].n, report.passed
    (4, True)
    """

    method: str = ""
    subsets: dict[str, SubsetReport] = Field(default_factory=dict)
    """The same figures per subset of the data (e.g. ``"core"`` and ``"rim"``)."""
    worst: list[Deviation] = Field(default_factory=list)
    """The points with the largest absolute distances, largest first."""
    seam_gap: float | None = None
    """Largest distance between pieces along their seams, for fits made of joined pieces."""
    notes: list[str] = Field(default_factory=list)
    """What the fitter wants the user to know, e.g. that ε cannot be met and why."""
    details: dict[str, JsonValue] = Field(default_factory=dict)
    """Method-specific facts: control-net size, variogram parameters, ..."""

    def to_text(self) -> str:
        """A few lines for people: the table of σ / max |d| / n per subset, seam gap, notes."""
        eps = "" if self.epsilon is None else f" against ε = {self.epsilon:g}"
        verdict = {True: "PASSED", False: "NOT MET", None: "no ε given"}[self.passed]
        lines = [f"accuracy of the {self.method or 'fit'}{eps}: {verdict}"]
        rows = [("all", self), *self.subsets.items()]
        for name, part in rows:
            mark = "" if part.passed is None else ("  ok" if part.passed else "  > ε")
            lines.append(
                f"  {name:<6} n = {part.n:6d}   σ = {part.sigma:10.4g}   "
                f"max |d| = {part.max_abs:10.4g}{mark}"
            )
        if self.seam_gap is not None:
            lines.append(f"  seam gap {self.seam_gap:.3g}")
        if self.worst:
            top = self.worst[0]
            where = f" ({top.subset})" if top.subset else ""
            lines.append(
                f"  largest deviation {top.distance:+.4g} at point {top.index}{where} "
                f"({top.point[0]:.2f}, {top.point[1]:.2f}, {top.point[2]:.2f})"
            )
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)


@dataclass(frozen=True)
class FitResult:
    """What :func:`fit` returns: the surface, its accuracy report, and per-point distances."""

    surface: NurbsSurface | Surface
    report: FitReport | None
    """None only when a third-party fitter returned a bare entity."""
    distances: NDArray[np.float64] | None = None
    """Signed distance from every input point to the surface, in input order."""
    method: str = ""


def _as_entity(points: Any) -> Entity:
    if isinstance(points, PointSet | PolyLine):
        return points
    if isinstance(points, Entity):
        raise EntityValidationError(
            "fit",
            "points",
            f"expected an (N, 3) array, a PointSet or a PolyLine, not a {points.label}",
        )
    try:
        array = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise EntityValidationError("fit", "points", f"not an array of numbers: {exc}") from exc
    if array.ndim != 2 or array.shape[1] != 3:
        raise EntityValidationError("fit", "points", f"expected shape (N, 3), got {array.shape}")
    return PointSet(vertices=array, name="points")


def fit(
    points: ArrayLike | PointSet | PolyLine, method: str = "hybrid", **options: Any
) -> FitResult:
    """Fit a surface to points with a registered fitter.

    ``points`` is an ``(N, 3)`` array or a PointSet (skinning also takes a PolyLine whose parts are
    the sections). ``method`` is the fitter's name (``"skinning"``, ``"approximation"``,
    ``"kriging"``, ``"hybrid"`` or a plugin's); ``options`` are validated by its options model.

    Raises:
        UnknownItemError: no fitter of that name (the message lists the registered ones).
        OptionsError: a bad or unknown option, or an input type the fitter does not take.
        EntityValidationError: malformed points (wrong shape, NaN).

    >>> import geobrep
    >>> result = fit(geobrep.datasets.scattered_points(), method="approximation", epsilon=0.5)
    >>> result.report.passed, result.surface.type
    (True, 'NurbsSurface')
    """
    from geobrep.plugins import registries

    entity = _as_entity(points)
    spec = registries().fitters.get(method)
    kind = type(entity).__name__
    if spec.input_types and kind not in spec.input_types:
        raise OptionsError(f"{spec.label}: takes {', '.join(spec.input_types)}, not a {kind}")
    validated = spec.validate_options(options)
    result = spec.function([entity], validated)
    if isinstance(result, FitResult):
        return result
    if isinstance(result, NurbsSurface | Surface):
        return FitResult(surface=result, report=None, method=method)
    raise PluginError(
        f"{spec.label} returned a {type(result).__name__}, not a FitResult or surface"
    )


def demo_stage(ctx: DemoContext) -> None:
    """Demo: fit the built-in scattered points with the hybrid method and report the accuracy."""
    from geobrep import datasets
    from geobrep.io import write

    points = datasets.scattered_points()
    result = fit(points, method="hybrid", epsilon=0.5)
    surface = result.surface
    entities: list[Entity] = [surface, points]
    if isinstance(surface, NurbsSurface):
        entities.append(surface.tessellate(resolution=300).replace(name=f"{surface.name} mesh"))
    path = ctx.output / "fitted_surface.geobrep"
    write(entities, path)
    report = result.report
    assert report is not None
    shape = "x".join(str(s) for s in surface.shape) if isinstance(surface, NurbsSurface) else "-"
    ctx.lines.append(
        f"fit: hybrid NURBS fit of {points.n_points} survey points -> {path.name} "
        f"({shape} control points)"
    )
    ctx.lines.extend("  " + line for line in report.to_text().splitlines())
    ctx.summary["fit"] = {"file": str(path), **report.model_dump(mode="json")}
