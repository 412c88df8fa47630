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

A format that cannot hold a NURBS surface (anything but ``.geobrep``) gets a triangle mesh instead.
:meth:`FitResult.tessellated` makes that mesh fine enough that its σ and max |d| over the same
points are within 2 % of the surface's, and :meth:`FitResult.write` writes what the format holds;
both fill ``report.written`` with the accuracy of the mesh, which is what ``report.written_passed``
(and ``geobrep fit --check``) judge.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, JsonValue

from geobrep.errors import EntityValidationError, OptionsError, PluginError
from geobrep.geometry.arrays import FloatArray
from geobrep.model.entities import Entity, NurbsSurface, PointSet, PolyLine, Surface

if TYPE_CHECKING:
    from geobrep.demo import DemoContext

__all__ = [
    "MAX_TRIANGLES",
    "WITHIN",
    "Deviation",
    "FitReport",
    "FitResult",
    "SubsetReport",
    "WrittenAccuracy",
    "demo_stage",
    "fit",
]


#: Relative agreement of a written mesh's σ and max |d| with the fitted surface's.
WITHIN = 0.02
#: Default bound on the triangles of a mesh written in place of a NURBS surface.
MAX_TRIANGLES = 1_000_000
#: Below this fraction of the surface's diagonal, σ and max |d| agree whatever ``within`` says
#: (a surface through its points has σ ≈ 0, which no mesh matches to 2 %).
_AGREEMENT_FLOOR = 1e-6
#: Chordal tolerance (fraction of the diagonal) of the first tessellation tried.
_FIRST_TOLERANCE = 1e-3


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

    @classmethod
    def from_distances(cls, distances: ArrayLike, epsilon: float | None = None) -> SubsetReport:
        """σ, max |d| and n of signed distances, and ``σ < ε`` when ``epsilon`` is given.

        >>> SubsetReport.from_distances([0.3, -0.4], epsilon=0.5).sigma
        0.5
        """
        d = np.asarray(distances, dtype=np.float64).reshape(-1)
        value = _sigma(d)
        return SubsetReport(
            sigma=value,
            max_abs=float(np.abs(d).max(initial=0.0)),
            n=int(d.shape[0]),
            epsilon=epsilon,
            passed=None if epsilon is None else bool(value < epsilon),
        )


def _sigma(distances: FloatArray) -> float:
    n = distances.shape[0]
    if n == 0:
        return 0.0
    return float(np.sqrt(np.sum(distances**2) / max(n - 1, 1)))


class Deviation(BaseModel):
    """One of the points farthest from the surface."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    index: int
    """Index of the point in the input."""
    point: tuple[float, float, float]
    distance: float
    """Signed distance (positive on the side the surface normal points to)."""
    subset: str = ""


def _worst(
    distances: FloatArray,
    points: FloatArray,
    labels: NDArray[np.str_] | None = None,
    count: int = 10,
) -> list[Deviation]:
    order = np.argsort(-np.abs(distances), kind="stable")[:count]
    return [
        Deviation(
            index=int(i),
            point=(float(points[i, 0]), float(points[i, 1]), float(points[i, 2])),
            distance=float(distances[i]),
            subset=str(labels[i]) if labels is not None else "",
        )
        for i in order
    ]


def _rows(overall: SubsetReport, subsets: Mapping[str, SubsetReport]) -> list[str]:
    lines = []
    for name, part in [("all", overall), *subsets.items()]:
        mark = "" if part.passed is None else ("  ok" if part.passed else "  > ε")
        lines.append(
            f"  {name:<6} n = {part.n:6d}   σ = {part.sigma:10.4g}   "
            f"max |d| = {part.max_abs:10.4g}{mark}"
        )
    return lines


def _verdict(passed: bool | None) -> str:
    return {True: "PASSED", False: "NOT MET", None: "no ε given"}[passed]


def _change(value: float, reference: float) -> str:
    if reference == 0.0 or abs(value - reference) > 10.0 * abs(reference):
        return f"{value - reference:+.3g}"
    return f"{100.0 * (value - reference) / reference:+.2f} %"


class WrittenAccuracy(SubsetReport):
    """The accuracy of the triangle mesh written (or returned) in place of the fitted surface.

    The same signed point-to-surface distances (exact to the triangles) over the same points as
    the report, so σ, max |d| and ``passed`` compare one to one with the surface's.
    """

    subsets: dict[str, SubsetReport] = Field(default_factory=dict)
    """The same figures per subset of the data, as in the report."""
    worst: list[Deviation] = Field(default_factory=list)
    """The points farthest from the mesh, largest first."""
    n_vertices: int
    n_triangles: int
    within: float = WITHIN
    """The mesh was refined until its σ and max |d| were within this fraction of the surface's."""
    floor: float = 0.0
    """Differences below this (1e-6 × the surface's diagonal) agree whatever ``within`` says: a
    surface through its points has σ ≈ 0, which no mesh matches to 2 %."""
    agrees: bool
    """σ and max |d| are within ``within`` of the surface's (or differ by at most ``floor``);
    False when ``max_triangles`` stopped the refinement first."""
    max_triangles: int = MAX_TRIANGLES
    """The bound on the mesh size the refinement kept to."""
    rounds: int = 1
    """Tessellations made (each samples the surface twice as densely as the one before)."""
    notes: list[str] = Field(default_factory=list)

    def to_text(self, surface: SubsetReport) -> str:
        """The mesh's table and how far its σ and max |d| are from ``surface``'s."""
        eps = "" if self.epsilon is None else f" against ε = {self.epsilon:g}"
        lines = [
            f"accuracy of the mesh written ({self.n_vertices} vertices, {self.n_triangles} "
            f"triangles){eps}: {_verdict(self.passed)}",
            *_rows(self, self.subsets),
            f"  σ {_change(self.sigma, surface.sigma)}, max |d| "
            f"{_change(self.max_abs, surface.max_abs)} from the fitted surface's "
            f"({'within' if self.agrees else 'NOT within'} {100 * self.within:g} % or "
            f"{self.floor:.2g} after {self.rounds} tessellation{'s' if self.rounds > 1 else ''})",
        ]
        if self.worst:
            top = self.worst[0]
            where = f" ({top.subset})" if top.subset else ""
            lines.append(f"  largest deviation {top.distance:+.4g} at point {top.index}{where}")
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)


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
    written: WrittenAccuracy | None = None
    """The accuracy of the mesh written or returned in place of the fitted NURBS surface (None:
    the surface itself was written, or nothing was tessellated)."""

    @property
    def written_passed(self) -> bool | None:
        """Pass/fail of what was written: the mesh's when a mesh replaced the surface."""
        return self.passed if self.written is None else self.written.passed

    def to_text(self) -> str:
        """A few lines for people: the table of σ / max |d| / n per subset, seam gap, notes, and
        the same for the mesh written in place of the surface."""
        eps = "" if self.epsilon is None else f" against ε = {self.epsilon:g}"
        lines = [f"accuracy of the {self.method or 'fit'}{eps}: {_verdict(self.passed)}"]
        lines.extend(_rows(self, self.subsets))
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
        if self.written is not None:
            lines.append(self.written.to_text(self))
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
    points: NDArray[np.float64] | None = None
    """The points the distances were measured from, ``(n, 3)`` in input order."""
    subsets: Mapping[str, NDArray[np.bool_]] = field(default_factory=dict)
    """The masks over ``points`` of the report's subsets (e.g. ``"core"`` and ``"rim"``)."""
    written: Surface | None = None
    """The mesh that stands for a NURBS ``surface`` in a format that cannot hold one (set by
    :meth:`tessellated` and :meth:`write`); its accuracy is ``report.written``."""
    written_distances: NDArray[np.float64] | None = None
    """Signed distance from every point to ``written``, in input order."""

    def tessellated(
        self, *, within: float = WITHIN, max_triangles: int = MAX_TRIANGLES
    ) -> FitResult:
        """This result with ``written``: a mesh of the NURBS surface as accurate as the surface.

        The first mesh follows the knot lines to a chordal tolerance of 1e-3 × the diagonal;
        while its σ or max |d| over the points differs from the surface's by more than
        ``within`` (relative; or by more than 1e-6 × the diagonal), the surface is sampled twice
        as densely per direction, up to ``max_triangles``. ``report.written`` holds the mesh's
        accuracy (``agrees`` False, with a note, when the bound stopped the refinement). A
        gridded surface (kriging) is already what is written: it comes back unchanged.

        Raises:
            OptionsError: ``within`` is not positive or ``max_triangles`` is below 2.
        """
        if not within > 0:
            raise OptionsError(f"within must be > 0, got {within}")
        if max_triangles < 2:
            raise OptionsError(f"max_triangles must be at least 2, got {max_triangles}")
        if not isinstance(self.surface, NurbsSurface):
            return self
        if self.report is None or self.points is None:
            mesh = self.surface.tessellate(tolerance=self._first_tolerance())
            return dataclasses.replace(self, written=_capped(self.surface, mesh, max_triangles))
        mesh, distances, rounds, agrees = self._refine(within, max_triangles)
        written = self._accuracy(mesh, distances, within, max_triangles, rounds, agrees)
        return dataclasses.replace(
            self,
            written=mesh,
            written_distances=distances,
            report=self.report.model_copy(update={"written": written}),
        )

    def write(
        self,
        path: str | PathLike[str],
        *,
        format: str | None = None,
        within: float = WITHIN,
        max_triangles: int = MAX_TRIANGLES,
        **options: Any,
    ) -> FitResult:
        """Write the fitted surface to ``path`` as the format holds it; returns what was written.

        A format that cannot hold a NURBS surface gets the mesh of :meth:`tessellated` (its
        accuracy in ``report.written``); ``format`` and ``options`` are :func:`geobrep.write`'s.
        """
        from geobrep.host import registries
        from geobrep.ops.io import write

        target = Path(path)
        held = registries().formats.choose_writer(target, format).capabilities.entity_types
        result = self
        entity: Entity = self.surface
        if isinstance(self.surface, NurbsSurface) and held and "NurbsSurface" not in held:
            result = self.tessellated(within=within, max_triangles=max_triangles)
            assert result.written is not None
            entity = result.written
        write(entity, target, format=format, **options)
        return result

    def _first_tolerance(self) -> float | None:
        bounds = self.surface.bounds
        return _FIRST_TOLERANCE * float(bounds.diagonal) if bounds is not None else None

    def _agreement_floor(self) -> float:
        bounds = self.surface.bounds
        return _AGREEMENT_FLOOR * float(bounds.diagonal) if bounds is not None else 0.0

    def _refine(self, within: float, max_triangles: int) -> tuple[Surface, FloatArray, int, bool]:
        from geobrep.geometry.distance import mesh_distances

        surface = self.surface
        report = self.report
        assert isinstance(surface, NurbsSurface)
        assert report is not None
        assert self.points is not None
        floor = self._agreement_floor()
        mesh = _capped(
            surface, surface.tessellate(tolerance=self._first_tolerance()), max_triangles
        )
        rounds = 1
        while True:
            distances = mesh_distances(mesh, self.points)
            measured = SubsetReport.from_distances(distances)
            agrees = all(
                abs(value - reference) <= max(within * reference, floor)
                for value, reference in (
                    (measured.sigma, report.sigma),
                    (measured.max_abs, report.max_abs),
                )
            )
            shape = _grid_shape(mesh)
            finer = _within_bound((2 * shape[0] - 1, 2 * shape[1] - 1), max_triangles)
            if agrees or finer[0] * finer[1] <= shape[0] * shape[1]:
                return mesh, distances, rounds, agrees
            mesh = surface.tessellate(resolution=finer)
            rounds += 1

    def _accuracy(
        self,
        mesh: Surface,
        distances: FloatArray,
        within: float,
        max_triangles: int,
        rounds: int,
        agrees: bool,
    ) -> WrittenAccuracy:
        report = self.report
        assert report is not None
        assert self.points is not None
        epsilon = report.epsilon
        overall = SubsetReport.from_distances(distances, epsilon)
        labels: NDArray[np.str_] | None = None
        if self.subsets:
            labels = np.full(distances.shape[0], "", dtype=object)
            for name, mask in reversed(list(self.subsets.items())):
                labels[mask] = name
        notes = []
        if not agrees:
            notes.append(
                f"the mesh's σ / max |d| are not within {100 * within:g} % of the surface's at "
                f"the bound of {max_triangles} triangles (max_triangles, --max-triangles); "
                "raise it for a finer mesh"
            )
        return WrittenAccuracy(
            **overall.model_dump(),
            subsets={
                name: SubsetReport.from_distances(distances[mask], epsilon)
                for name, mask in self.subsets.items()
            },
            worst=_worst(distances, self.points, labels),
            n_vertices=mesh.n_vertices,
            n_triangles=int(mesh.n_faces),
            within=within,
            floor=self._agreement_floor(),
            agrees=agrees,
            max_triangles=max_triangles,
            rounds=rounds,
            notes=notes,
        )


def _grid_shape(mesh: Surface) -> tuple[int, int]:
    shape = mesh.metadata.get("grid_shape")
    assert isinstance(shape, list)
    mu, mv = shape
    assert isinstance(mu, int)
    assert isinstance(mv, int)
    return mu, mv


def _within_bound(shape: tuple[int, int], max_triangles: int) -> tuple[int, int]:
    """The grid ``shape`` shrunk (keeping its proportions) to at most ``max_triangles``."""
    mu, mv = shape
    if 2 * (mu - 1) * (mv - 1) <= max_triangles:
        return mu, mv
    scale = float(np.sqrt(max_triangles / (2.0 * (mu - 1) * (mv - 1))))
    nu, nv = max(1, int((mu - 1) * scale)), max(1, int((mv - 1) * scale))
    while 2 * nu * nv > max_triangles:
        nu, nv = (nu - 1, nv) if nu >= nv else (nu, nv - 1)
    return nu + 1, nv + 1


def _capped(surface: NurbsSurface, mesh: Surface, max_triangles: int) -> Surface:
    if mesh.n_faces <= max_triangles:
        return mesh
    return surface.tessellate(resolution=_within_bound(_grid_shape(mesh), max_triangles))


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
    points: ArrayLike | PointSet | PolyLine,
    method: str = "hybrid",
    *,
    markers: Any = None,
    marker_surface: str | None = None,
    marker_weight: float | str | None = None,
    **options: Any,
) -> FitResult:
    """Fit a surface to points with a registered fitter.

    ``points`` is an ``(N, 3)`` array or a PointSet (skinning also takes a PolyLine whose parts are
    the sections). ``method`` is the fitter's name (``"skinning"``, ``"approximation"``,
    ``"kriging"``, ``"hybrid"`` or a plugin's); ``options`` are validated by its options model.

    ``markers`` (a Well, wells, or a Scene's wells) adds the well markers that name
    ``marker_surface`` (their ``surface``, or their name) to the points, placed on the wells'
    paths at their MD; ``marker_weight`` weighs them in a least-squares fit (a number) or makes
    them hard data the surface passes through (``"hard"``; kriging honours data exactly anyway).
    The report then has the subset ``markers`` and each marker's misfit in
    ``details["markers"]``.

    Raises:
        UnknownItemError: no fitter of that name (the message lists the registered ones).
        OptionsError: a bad or unknown option, or an input type the fitter does not take.
        EntityValidationError: malformed points (wrong shape, NaN).

    >>> import geobrep
    >>> result = fit(geobrep.datasets.scattered_points(), method="approximation", epsilon=0.5)
    >>> result.report.passed, result.surface.type
    (True, 'NurbsSurface')
    """
    from geobrep.host import registries

    entity = _as_entity(points)
    spec = registries().fitters.get(method)
    found = None
    if markers is not None:
        from geobrep.ops._fit_markers import join_markers, picks

        found = picks(markers, marker_surface)
        assert isinstance(entity, PointSet | PolyLine)
        first = int(entity.vertices.shape[0])
        entity, options = join_markers(entity, found, marker_weight, spec, options)
    elif marker_surface is not None or marker_weight is not None:
        raise OptionsError("marker_surface and marker_weight need markers")
    kind = type(entity).__name__
    if spec.input_types and kind not in spec.input_types:
        raise OptionsError(f"{spec.label}: takes {', '.join(spec.input_types)}, not a {kind}")
    validated = spec.validate_options(options)
    result = spec.function([entity], validated)
    assert isinstance(entity, PointSet | PolyLine)
    vertices = np.asarray(entity.vertices, dtype=np.float64)
    if isinstance(result, FitResult):
        known = result.distances
        if result.points is None and known is not None and known.shape[0] == vertices.shape[0]:
            result = dataclasses.replace(result, points=vertices)
        if found is not None:
            from geobrep.ops._fit_markers import marker_report

            result = marker_report(result, found, first)
        return result
    if isinstance(result, NurbsSurface | Surface):
        return FitResult(surface=result, report=None, method=method, points=vertices)
    raise PluginError(
        f"{spec.label} returned a {type(result).__name__}, not a FitResult or surface"
    )


def demo_stage(ctx: DemoContext) -> None:
    """Demo: fit the built-in scattered points with the hybrid method, write the surface with a
    mesh of it, and report the accuracy of both."""
    from geobrep import datasets
    from geobrep.ops.io import write

    points = datasets.scattered_points()
    result = fit(points, method="hybrid", epsilon=0.5).tessellated()
    surface = result.surface
    entities: list[Entity] = [surface, points]
    if result.written is not None:  # as accurate as the surface (report.written says how much)
        entities.append(result.written.replace(name=f"{surface.name} mesh"))
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
