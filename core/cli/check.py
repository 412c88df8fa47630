"""``geobrep check FILE... [--checks a,b] [--tolerance T] [--json] [--defects OUT]``.

Each file is read as it holds the model (no on-read repairs) and inspected
(:func:`geobrep.inspect`); the exit code is 0 when every file is clean and 3 when defects were
found (as ``fit --check`` does), 1 on an error, 2 on a usage error. ``--defects`` writes the
defects of every file as entities (points, edges, triangles, coloured by check) to a file of
any writable format (``.vtp``, ``.gpkg``, ``.geobrep``, ...). Progress (a line per file and
per check) goes to stderr on a terminal or once the work is long, so ``--json`` output on
stdout stays clean (:class:`~geobrep.cli.common.ProgressLines`). The options are those of the
``check`` operation (:class:`~geobrep.batch.pipeline.CheckStep`).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict

from geobrep.batch.pipeline import CheckStep
from geobrep.cli.common import ProgressLines, format_name, progress_mode, read_input
from geobrep.host.operations import Cli

__all__ = ["COMMAND", "DESCRIPTION", "EXIT_DEFECTS", "OPERATION", "CheckCommand", "run"]

OPERATION = "check"
EXIT_DEFECTS = 3
DESCRIPTION = (
    "Inspect each FILE as written (no on-read repairs): colocated and isolated vertices, "
    "degenerate, duplicated and inverted elements, non-manifold edges and vertices, "
    "orientation, self-intersections and crossings, T-junctions and gaps, and the B-Rep "
    "topology. Exit 0 when clean, 3 when defects were found."
)


class CheckCommand(BaseModel):
    """The files and the command-line-only options of ``geobrep check``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    files: Annotated[tuple[str, ...], Cli(positional=True, metavar="FILE", nargs="+")]
    """models to inspect (any readable format)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the reports as JSON (a list, one per file)"""
    defects: Annotated[str | None, Cli(metavar="OUT")] = None
    """write the defects as entities to OUT (.vtp, .gpkg, .geobrep, ...)"""
    progress: Annotated[bool, Cli(flags=("--progress",))] = False
    """a progress line per file and check on stderr even when the work is short and stderr
    is no terminal"""
    no_progress: Annotated[bool, Cli(flags=("--no-progress",))] = False
    """no progress lines (default: on a terminal, or once the work has run 2 s)"""


COMMAND = CheckCommand


def run(options: CheckStep, args: CheckCommand) -> int:
    from geobrep.host import registries
    from geobrep.model.scene import Scene
    from geobrep.ops.inspection import inspect
    from geobrep.ops.io import write

    known = registries().checks
    unknown = [n for n in options.checks or () if n != "all" and n not in known]
    if unknown:
        print(
            f"geobrep check: error: unknown check {unknown[0]!r}; checks: "
            + ", ".join(known.names()),
            file=sys.stderr,
        )
        return 2
    reports: list[dict[str, Any]] = []
    layers = []
    found = 0
    lines = ProgressLines("check", progress_mode(args.progress, args.no_progress))
    for number, path in enumerate(args.files, start=1):
        begin = time.perf_counter()
        scene = read_input(args, path, format=args.format, repair=False)
        lines.line(
            f"file {number}/{len(args.files)} {path} read {time.perf_counter() - begin:.2f} s"
        )
        report = inspect(
            scene, options.checks, options.tolerance, progress=lines.step(path, "check")
        )
        found += report.n_defects
        if args.as_json:
            reports.append({"file": path, **report.model_dump(mode="json")})
        else:
            print(f"{path}:")
            print("  " + report.table().replace("\n", "\n  "))
        stem = Path(path).stem
        layers += [
            e.model_copy(update={"name": f"{stem}.{e.name}", "id": None})
            for e in report.to_scene().entities
        ]
    if args.defects is not None:
        written = write(Scene(entities=layers), args.defects)
        if not args.as_json:
            print(f"defects: {len(layers)} layer(s) -> {written}")
    if args.as_json:
        print(json.dumps(reports, indent=2))
    if found and options.on_defects != "continue":
        return EXIT_DEFECTS
    return 0
