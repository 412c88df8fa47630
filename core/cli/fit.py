"""``geobrep fit POINTS OUT``: fit a surface to points and print its accuracy report.

Points come from a CSV file (``x,y,z`` columns, header optional; further numeric columns become
point properties) or from any registered format holding a PointSet. The surface is written to
``OUT`` in the format of its extension. A format that cannot hold NURBS gets a triangle mesh
refined until its σ and max |d| are within 2 % of the surface's (up to ``--max-triangles``); the
report then gives the accuracy of both, and ``--check`` judges the mesh, the object written::

    geobrep fit survey.csv horizon.geobrep --method hybrid --epsilon 0.5
    geobrep fit survey.csv grid.geobrep --method kriging --option variogram_model=gaussian
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from geobrep.cli.common import format_name
from geobrep.errors import FileAccessError, FormatError, OptionsError
from geobrep.model.entities import Entity, PointSet, PolyLine
from geobrep.ops.fitting import MAX_TRIANGLES

__all__ = ["add_parser", "run"]

EXIT_NOT_MET = 3


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "fit",
        help="fit a surface to points (skinning, approximation, kriging, hybrid)",
        description="Fit a surface to points and report σ, max |d| and n per subset against ε.",
    )
    parser.add_argument("points", help="points: CSV (x,y,z[,...]) or any format holding a PointSet")
    parser.add_argument("out", help="output file; its extension chooses the format")
    parser.add_argument(
        "--method", default="hybrid", help="fitter: skinning, approximation, kriging, hybrid, ..."
    )
    parser.add_argument("--epsilon", type=float, help="control error ε for the accuracy report")
    parser.add_argument(
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a fitter option (VALUE is JSON when it parses, else text); repeatable",
    )
    parser.add_argument(
        "--format",
        type=format_name("read"),
        help="input format name, when the extension is not enough",
    )
    parser.add_argument("--entity", help="name of the PointSet to fit, when the file holds several")
    parser.add_argument("--report", help="also write the report as JSON to this file")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument(
        "--check",
        action="store_true",
        help=f"exit with status {EXIT_NOT_MET} when what was written does not meet ε",
    )
    parser.add_argument(
        "--max-triangles",
        type=int,
        default=MAX_TRIANGLES,
        metavar="N",
        help="bound on the mesh written when OUT's format cannot hold NURBS "
        f"(default {MAX_TRIANGLES})",
    )
    parser.set_defaults(run=run)


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


def _options(pairs: list[str]) -> dict[str, Any]:
    options: dict[str, Any] = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise OptionsError(f"--option {pair!r}: expected KEY=VALUE")
        try:
            options[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            options[key.strip()] = value
    return options


def run(args: argparse.Namespace) -> int:
    from geobrep.ops.fitting import fit
    from geobrep.ops.io import atomic_write

    points = _load_points(Path(args.points), args.format, args.entity)
    options = _options(args.option)
    if args.epsilon is not None:
        options["epsilon"] = args.epsilon
    if args.max_triangles < 2:
        raise OptionsError(f"--max-triangles must be at least 2, got {args.max_triangles}")
    result = fit(points, method=args.method, **options)
    out = Path(args.out)
    result = result.write(out, max_triangles=args.max_triangles)
    report = result.report
    if report is not None and args.report:
        with atomic_write(args.report) as tmp:
            tmp.write_text(report.model_dump_json(indent=2), encoding="utf-8")
    if args.json:
        payload = report.model_dump(mode="json") if report is not None else None
        print(json.dumps({"output": str(out), "report": payload}, indent=2))
    else:
        print(f"{args.method} fit of {points.n_points} points -> {out}")
        if report is not None:
            print(report.to_text())
    if args.check and report is not None and report.written_passed is False:
        return EXIT_NOT_MET
    return 0
