"""``geobrep fit POINTS OUT``: fit a surface to points and print its accuracy report.

Points come from a CSV file (``x,y,z`` columns, header optional; further numeric columns become
point properties) or from any registered format holding a PointSet. The surface is written to
``OUT`` in the format of its extension (as a triangle mesh when that format cannot hold NURBS)::

    geobrep fit survey.csv horizon.geobrep --method hybrid --epsilon 0.5
    geobrep fit survey.csv grid.geobrep --method kriging --option variogram_model=gaussian
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from geobrep.entities import Entity, NurbsSurface, PointSet, PolyLine
from geobrep.errors import FileAccessError, FormatError, OptionsError
from geobrep.properties import Property

__all__ = ["add_parser", "read_points_csv", "run"]

EXIT_NOT_MET = 3
_SPLIT = re.compile(r"[,;\s]+")


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
    parser.add_argument("--format", help="input format name, when the extension is not enough")
    parser.add_argument("--entity", help="name of the PointSet to fit, when the file holds several")
    parser.add_argument("--report", help="also write the report as JSON to this file")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument(
        "--check",
        action="store_true",
        help=f"exit with status {EXIT_NOT_MET} when the report does not meet ε",
    )
    parser.set_defaults(run=run)


def _numbers(line: str) -> list[str]:
    return [token for token in _SPLIT.split(line.strip()) if token]


def read_points_csv(path: Path) -> PointSet:
    """Points from a delimited text file: x, y, z (and more numeric columns as properties).

    A first line that is not numeric is a header; columns named x, y, z (any case) are used when
    present, otherwise the first three. Raises FormatError with the line of the first bad row.
    """
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise FileAccessError(f"cannot be read ({exc.strerror or exc})", path) from exc
    lines = [(number, line) for number, line in enumerate(text.splitlines(), 1) if line.strip()]
    lines = [(n, line) for n, line in lines if not line.lstrip().startswith("#")]
    if not lines:
        raise FormatError("no points in the file", path)
    header: list[str] | None = None
    first = _numbers(lines[0][1])
    try:
        [float(token) for token in first]
    except ValueError:
        header = [token.strip().strip('"').lower() for token in first]
        lines = lines[1:]
    if not lines:
        raise FormatError("the file has a header but no points", path)
    width = len(_numbers(lines[0][1]))
    joined = "\n".join(line for _, line in lines)
    try:
        rows = np.array(_SPLIT.split(joined.strip()), dtype=np.float64)
        if rows.size != len(lines) * width:
            raise ValueError("ragged rows")
        rows = rows.reshape(len(lines), width)
    except ValueError:
        for number, line in lines:
            tokens = _numbers(line)
            if len(tokens) != width:
                raise FormatError(
                    f"expected {width} values, found {len(tokens)}", path, number
                ) from None
            try:
                [float(token) for token in tokens]
            except ValueError as exc:
                raise FormatError(f"not a number: {exc}", path, number) from None
        raise FormatError("cannot parse the points", path) from None
    if width < 3:
        raise FormatError(f"need x, y, z columns, found {width}", path, lines[0][0])
    names = header if header is not None and len(header) == width else None
    if names is not None and {"x", "y", "z"} <= set(names):
        xyz = [names.index("x"), names.index("y"), names.index("z")]
    else:
        xyz = [0, 1, 2]
    bad = ~np.isfinite(rows[:, xyz]).all(axis=1)
    if bad.any():
        number = lines[int(np.argmax(bad))][0]
        raise FormatError("coordinates must be finite (NaN or inf found)", path, number)
    extra = {}
    for column in range(width):
        if column in xyz:
            continue
        name = names[column] if names is not None else f"column_{column + 1}"
        extra[name] = Property(values=rows[:, column])
    return PointSet(vertices=rows[:, xyz], point_data=extra, name=path.stem)


def _load_points(path: Path, fmt: str | None, entity: str | None) -> PointSet | PolyLine:
    from geobrep.io import read
    from geobrep.plugins import registries

    if not path.exists():
        raise FileAccessError("no such file", path)
    claimed = registries().formats.for_extension(path.suffix) if path.suffix else []
    if fmt is None and not claimed and path.suffix.lower() in (".csv", ".txt", ".xyz", ".dat"):
        return read_points_csv(path)
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
    from geobrep.fitting import fit
    from geobrep.io import atomic_write, write
    from geobrep.plugins import registries

    points = _load_points(Path(args.points), args.format, args.entity)
    options = _options(args.option)
    if args.epsilon is not None:
        options["epsilon"] = args.epsilon
    result = fit(points, method=args.method, **options)
    out = Path(args.out)
    surface: Entity = result.surface
    writer = registries().formats.choose_writer(out)
    types = writer.capabilities.entity_types
    if isinstance(surface, NurbsSurface) and types and "NurbsSurface" not in types:
        surface = surface.tessellate(tolerance=1e-3 * float(surface.bounds.diagonal))  # type: ignore[union-attr]
    write(surface, out)
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
    if args.check and report is not None and report.passed is False:
        return EXIT_NOT_MET
    return 0
