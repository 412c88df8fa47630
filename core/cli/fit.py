"""``geobrep fit POINTS OUT``: fit a surface to points and print its accuracy report.

Points come from a CSV file (``x,y,z`` columns, header optional; further numeric columns become
point properties) or from any registered format holding a PointSet. The surface is written to
``OUT`` in the format of its extension. A format that cannot hold NURBS gets a triangle mesh
refined until its σ and max |d| are within 2 % of the surface's (up to ``--max-triangles``); the
report then gives the accuracy of both, and ``--check`` judges the mesh, the object written::

    geobrep fit survey.csv horizon.geobrep --method hybrid --epsilon 0.5
    geobrep fit survey.csv grid.geobrep --method kriging --option variogram_model=gaussian
    geobrep fit survey.csv top.geobrep --markers w1.wl w2.dev --marker-surface Top \\
        --marker-weight hard

``--markers`` reads wells from any readable files (GOCAD .wl, deviation tables, .geobrep...; the
reader a pipeline's fit step shares, :func:`geobrep.batch.operations.read_wells`); their markers
that name ``--marker-surface`` join the points (see :func:`geobrep.fit`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict

from geobrep.batch.operations import fit_markers
from geobrep.batch.pipeline import FitStep
from geobrep.cli.common import format_name
from geobrep.errors import FileAccessError, FormatError, OptionsError
from geobrep.host.operations import Cli
from geobrep.model.entities import Entity, PointSet, PolyLine

__all__ = ["COMMAND", "DESCRIPTION", "EXIT_NOT_MET", "OPERATION", "FitCommand", "run"]

OPERATION = "fit"
DESCRIPTION = "Fit a surface to points and report σ, max |d| and n per subset against ε."
EXIT_NOT_MET = 3


class FitCommand(BaseModel):
    """The files and command-line-only options of ``geobrep fit``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    points_file: Annotated[str, Cli(positional=True, metavar="points")]
    """points: CSV (x,y,z[,...]) or any format holding a PointSet"""
    out: Annotated[str, Cli(positional=True)]
    """output file; its extension chooses the format"""
    epsilon: float | None = None
    """control error ε for the accuracy report (the fitter option epsilon)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format name, when the extension is not enough"""
    report: str | None = None
    """also write the report as JSON to this file"""
    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the report as JSON"""


def _load_points(path: Path, fmt: str | None, entity: str | None) -> PointSet | PolyLine:
    from geobrep.ops.io import read

    if not path.exists():
        raise FileAccessError("no such file", path)
    scene = read(path, format=fmt)
    candidates: list[Entity] = [e for e in scene.entities if isinstance(e, PointSet | PolyLine)]
    if entity is not None:
        candidates = [e for e in candidates if e.name == entity]
    if not candidates:
        which = f" named {entity!r}" if entity else ""
        raise FormatError(f"the file holds no PointSet or PolyLine{which}", path)
    if len(candidates) > 1 and entity is None:
        names = ", ".join(repr(e.name) for e in candidates)
        raise OptionsError(f"{path}: several point entities ({names}); choose one with --entity")
    chosen = candidates[0]
    assert isinstance(chosen, PointSet | PolyLine)
    return chosen


def run(step: FitStep, args: FitCommand) -> int:
    from geobrep.ops.fitting import fit
    from geobrep.ops.io import atomic_write

    entity = step.points[0] if step.points else None
    points = _load_points(Path(args.points_file), args.format, entity)
    options: dict[str, Any] = dict(step.options)
    if args.epsilon is not None:
        options["epsilon"] = args.epsilon
    result = fit(points, method=step.method, **fit_markers(step, None), **options)
    out = Path(args.out)
    result = result.write(out, max_triangles=step.max_triangles)
    report = result.report
    if report is not None and args.report:
        with atomic_write(args.report) as tmp:
            tmp.write_text(report.model_dump_json(indent=2), encoding="utf-8")
    if args.as_json:
        payload = report.model_dump(mode="json") if report is not None else None
        print(json.dumps({"output": str(out), "report": payload}, indent=2))
    else:
        print(f"{step.method} fit of {points.n_points} points -> {out}")
        if report is not None:
            print(report.to_text())
    if step.check_epsilon and report is not None and report.written_passed is False:
        return EXIT_NOT_MET
    return 0


COMMAND = FitCommand
