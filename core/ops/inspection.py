"""Inspecting a model: the registered checks run on a scene, one report section per check.

Each check is a :class:`~geobrep.host.registry.CheckSpec` of the ``checks`` registry (the
built-in ones come from :mod:`geobrep.plugins.checks`; plugins add more through the
``geobrep_register_checks`` hook). :func:`inspect` validates what it is asked, runs the checks
and gathers their :class:`Defect` lists into an :class:`InspectionReport`: typed, JSON-ready
(``report.model_dump_json()``, schema ``schemas/inspection.schema.json``), printable as a
table, and viewable as a defect layer (:meth:`InspectionReport.to_scene`).

>>> import geobrep
>>> report = geobrep.inspect(geobrep.datasets.faulted_layer_cake())
>>> report.ok
True
"""

from __future__ import annotations

import difflib
import math
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from geobrep.errors import GeobrepError, OptionsError
from geobrep.model.entities import Entity

if TYPE_CHECKING:
    from geobrep.host.registry import CheckSpec
    from geobrep.model.scene import Scene

__all__ = [
    "CHECK_COLOURS",
    "CheckContext",
    "CheckSection",
    "Defect",
    "InspectionReport",
    "Progress",
    "check_names",
    "inspect",
]

Element = Literal[
    "vertex", "edge", "triangle", "face", "tet", "segment", "patch", "arc", "corner", "block"
]
Point = tuple[float, float, float]

Progress = Callable[[str, int, int, float], None]
"""``progress(step, done, total, seconds)``: called after each check (or repair action)."""

#: Defects listed per section by default (the count is always complete).
MAX_LISTED = 1000

#: Colours of the defect layers, cycled over the checks of a report (RGB, 0-255).
CHECK_COLOURS: tuple[tuple[int, int, int], ...] = (
    (228, 26, 28),
    (55, 126, 184),
    (77, 175, 74),
    (152, 78, 163),
    (255, 127, 0),
    (166, 86, 40),
    (247, 129, 191),
    (153, 153, 153),
    (255, 255, 51),
    (27, 158, 119),
    (117, 112, 179),
    (102, 166, 30),
)


class Defect(BaseModel):
    """One defect: where it is and which elements it involves.

    ``entity`` names the entity (its name, else its label) and ``entity_id`` its scene id;
    ``element`` says what ``ids`` number (vertices, edges as vertex pairs flattened, triangles,
    tets, patches, blocks ...); ``other_*`` name the second entity and its elements for defects
    between two (a crossing, a T-junction). ``location`` is a point of the defect in model
    coordinates; ``points`` its shape for the defect layer (1 point, 2 for an edge, 3 for a
    triangle); ``value`` a measure (a distance, an area, a volume) described by ``message``.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    entity: str
    entity_id: int | None = None
    element: Element
    ids: tuple[int, ...] = ()
    location: Point
    other_entity: str | None = None
    other_entity_id: int | None = None
    other_ids: tuple[int, ...] = ()
    value: float | None = None
    message: str = ""
    points: tuple[Point, ...] = ()


class CheckSection(BaseModel):
    """The result of one check: how many defects it found and (up to a limit) which."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    check: str
    title: str = ""
    family: str = ""
    count: int = Field(ge=0)
    defects: tuple[Defect, ...] = ()
    seconds: float = 0.0
    repairs: str | None = None

    @property
    def truncated(self) -> bool:
        """Fewer defects are listed than were found."""
        return len(self.defects) < self.count


class InspectionReport(BaseModel):
    """What :func:`geobrep.inspect` found: one :class:`CheckSection` per check run."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    tolerance: float | None = None
    tolerance_source: str = ""
    entities: int = 0
    sections: tuple[CheckSection, ...] = ()
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """No check found any defect."""
        return all(section.count == 0 for section in self.sections)

    @property
    def n_defects(self) -> int:
        return sum(section.count for section in self.sections)

    def counts(self) -> dict[str, int]:
        """``{check name: defect count}``."""
        return {section.check: section.count for section in self.sections}

    def section(self, check: str) -> CheckSection:
        """The section of the check called ``check``."""
        for item in self.sections:
            if item.check == check:
                return item
        raise KeyError(f"no section {check!r} in this report; sections: {list(self.counts())}")

    def table(self) -> str:
        """A readable table: one row per check with its count and first defect."""
        rows = [("check", "defects", "first at")]
        for item in self.sections:
            first = ""
            if item.defects:
                d = item.defects[0]
                x, y, z = d.location
                first = f"{d.entity} {d.element} {list(d.ids)[:4]} ({x:.6g}, {y:.6g}, {z:.6g})"
            rows.append((item.check, str(item.count), first))
        widths = [max(len(row[k]) for row in rows) for k in range(2)]
        lines = [f"{a:<{widths[0]}}  {b:>{widths[1]}}  {c}".rstrip() for a, b, c in rows]
        lines.insert(1, "-" * max(len(line) for line in lines))
        tolerance = (
            f"tolerance {self.tolerance:.3g} ({self.tolerance_source})"
            if self.tolerance is not None
            else "no tolerance used"
        )
        verdict = "clean" if self.ok else f"{self.n_defects} defect(s)"
        lines.append(f"{verdict}; {self.entities} entities; {tolerance}; {self.seconds:.2f} s")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()

    def to_scene(self) -> Scene:
        """The defects as entities: per check, a PointSet of locations, a PolyLine of defective
        edges and a Surface of defective triangles (each coloured: ``metadata["colour"]``, and a
        ``check`` property naming its check by number, ``metadata["checks"]`` lists the names).
        """
        from geobrep.model.scene import Scene

        entities: list[Entity] = []
        names = [item.check for item in self.sections]
        for number, item in enumerate(self.sections):
            if item.defects:
                colour = CHECK_COLOURS[number % len(CHECK_COLOURS)]
                entities.extend(_defect_entities(item, number, colour, names))
        return Scene(entities=entities)


def _defect_entities(
    item: CheckSection, number: int, colour: tuple[int, int, int], names: list[str]
) -> list[Entity]:
    from geobrep.model.entities import PointSet, PolyLine, Surface

    metadata: dict[str, Any] = {
        "check": item.check,
        "colour": "#{:02x}{:02x}{:02x}".format(*colour),
        "checks": names,
    }
    out: list[Entity] = []
    locations = np.array([d.location for d in item.defects], dtype=np.float64)
    out.append(
        PointSet(
            name=f"{item.check}.points",
            kind="defects",
            vertices=locations,
            point_data={"check": np.full(len(locations), number, dtype=np.int32)},
            metadata=metadata,
        )
    )
    edges = [d.points for d in item.defects if len(d.points) == 2]
    if edges:
        vertices = np.array(edges, dtype=np.float64).reshape(-1, 3)
        out.append(
            PolyLine(
                name=f"{item.check}.edges",
                kind="defects",
                vertices=vertices,
                indices=np.arange(vertices.shape[0], dtype=np.int64),
                part_offsets=np.arange(0, vertices.shape[0] + 1, 2, dtype=np.int64),
                closed=np.zeros(len(edges), dtype=np.bool_),
                cell_data={"check": np.full(len(edges), number, dtype=np.int32)},
                metadata=metadata,
            )
        )
    triangles = [d.points for d in item.defects if len(d.points) == 3]
    if triangles:
        vertices = np.array(triangles, dtype=np.float64).reshape(-1, 3)
        out.append(
            Surface(
                name=f"{item.check}.triangles",
                kind="defects",
                vertices=vertices,
                faces=np.arange(vertices.shape[0], dtype=np.int64).reshape(-1, 3),
                cell_data={"check": np.full(len(triangles), number, dtype=np.int32)},
                metadata=metadata,
            )
        )
    return out


@dataclass
class CheckContext:
    """What the checks of one inspection share.

    ``tolerance`` is the tolerance asked for (``None``: follow the data's precision);
    the first check that needs one records the value it used in ``tolerance_used`` and where
    it came from in ``tolerance_source``. ``cache`` holds results several checks reuse (welded
    vertices, edge tables), keyed by the check code's own names.
    """

    tolerance: float | None = None
    tolerance_used: float | None = None
    tolerance_source: str = ""
    cache: dict[str, Any] = field(default_factory=dict)


def check_names(*, defaults_only: bool = False) -> list[str]:
    """The names of the registered checks (only those run by default, if asked)."""
    from geobrep.host import registries

    return [c.name for c in registries().checks if c.default or not defaults_only]


def _chosen(checks: str | Iterable[str] | None) -> list[CheckSpec]:
    from geobrep.host import registries

    registry = registries().checks
    if checks is None:
        return [spec for spec in registry if spec.default]
    names = [checks] if isinstance(checks, str) else list(checks)
    if isinstance(checks, str) and "," in checks:
        names = [part.strip() for part in checks.split(",") if part.strip()]
    if not names:
        raise OptionsError("checks: the list of checks is empty (give None to run the defaults)")
    chosen: list[CheckSpec] = []
    for name in names:
        if not isinstance(name, str):
            raise OptionsError(f"checks: {name!r} is not a check name")
        if name == "all":
            chosen.extend(spec for spec in registry if spec not in chosen)
            continue
        if name not in registry:
            close = difflib.get_close_matches(name, registry.names(), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise OptionsError(
                f"checks: unknown check {name!r}{hint}; checks: {', '.join(registry.names())}"
            )
        spec = registry.get(name)
        if spec not in chosen:
            chosen.append(spec)
    return chosen


def _checked_tolerance(tolerance: float | None) -> float | None:
    if tolerance is None:
        return None
    if isinstance(tolerance, bool) or not isinstance(tolerance, int | float):
        raise OptionsError(f"tolerance: expected a number, got {type(tolerance).__name__}")
    if not math.isfinite(tolerance) or tolerance < 0.0:
        raise OptionsError(f"tolerance: must be a finite number ≥ 0, got {tolerance!r}")
    return float(tolerance)


def _as_inspected_scene(data: Any) -> Scene:
    from geobrep.model.scene import Scene

    if isinstance(data, Scene):
        scene = data
    elif isinstance(data, Entity):
        scene = Scene(entities=[data])
    elif isinstance(data, Iterable) and not isinstance(data, str | bytes):
        items = list(data)
        if not all(isinstance(item, Entity) for item in items):
            raise OptionsError("inspect: expected a Scene, an entity or entities")
        scene = Scene(entities=items)
    else:
        raise OptionsError(
            f"inspect: expected a Scene, an entity or entities, not {type(data).__name__}"
        )
    if not scene.entities:
        raise OptionsError("inspect: the scene is empty (it holds no entity to inspect)")
    return scene


def _run(spec: CheckSpec, scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    try:
        found = spec.function(scene, options, context)
    except GeobrepError:
        raise
    except Exception as exc:  # plugin code: say which check failed
        raise GeobrepError(f"{spec.label} failed: {type(exc).__name__}: {exc}") from exc
    defects = list(found)
    for defect in defects:
        if not isinstance(defect, Defect):
            raise GeobrepError(f"{spec.label} returned {type(defect).__name__}, not a Defect")
    return defects


def inspect(
    scene_or_entity: Scene | Entity | Sequence[Entity],
    checks: str | Iterable[str] | None = None,
    tolerance: float | None = None,
    *,
    options: Mapping[str, Mapping[str, Any]] | None = None,
    max_listed: int = MAX_LISTED,
    progress: Progress | None = None,
) -> InspectionReport:
    """Run ``checks`` (names, ``"all"``, or ``None`` for the default checks) on a scene.

    ``tolerance`` (model units) is the distance under which two points count as one — colocated
    vertices, T-junctions, gaps —; by default it follows the data's own precision (the
    builder's rule, see docs/inspection.md). ``options`` maps a check name to its options
    (validated by the check's options model). Each section lists up to ``max_listed`` defects;
    its ``count`` is always the full number. ``progress(check, done, total, seconds)`` is
    called after each check (the command line's progress lines).

    Errors: :class:`~geobrep.errors.OptionsError` for an unknown check, a bad tolerance or
    options, or an empty scene.
    """
    started = time.perf_counter()
    scene = _as_inspected_scene(scene_or_entity)
    context = CheckContext(tolerance=_checked_tolerance(tolerance))
    chosen = _chosen(checks)
    per_check = dict(options or {})
    unknown = sorted(set(per_check) - {spec.name for spec in chosen})
    if unknown:
        raise OptionsError(f"options: given for checks not run: {', '.join(unknown)}")
    if max_listed < 0:
        raise OptionsError(f"max_listed: must be ≥ 0, got {max_listed}")
    sections = []
    for done, spec in enumerate(chosen, start=1):
        validated = spec.validate_options(per_check.get(spec.name))
        begin = time.perf_counter()
        defects = _run(spec, scene, validated, context)
        if progress is not None:
            progress(spec.name, done, len(chosen), time.perf_counter() - begin)
        sections.append(
            CheckSection(
                check=spec.name,
                title=spec.title or spec.description,
                family=spec.family,
                count=len(defects),
                defects=tuple(defects[:max_listed]),
                seconds=time.perf_counter() - begin,
                repairs=spec.repairs,
            )
        )
    return InspectionReport(
        tolerance=context.tolerance_used,
        tolerance_source=context.tolerance_source,
        entities=len(scene.entities),
        sections=tuple(sections),
        seconds=time.perf_counter() - started,
    )
