"""``geobrep repair IN OUT [--actions weld,orient] [--tolerance T]``: mend a model.

The options are those of the ``repair`` operation (:class:`~geobrep.batch.pipeline.RepairStep`,
the pipeline step's body); the parser is derived from it and :class:`RepairCommand`.
"""

from __future__ import annotations

import time
from typing import Annotated

from geobrep.batch.pipeline import RepairStep
from geobrep.cli.common import ProgressLines, progress_mode, read_input
from geobrep.cli.operation import SceneCommand
from geobrep.host.operations import Cli

__all__ = ["COMMAND", "DESCRIPTION", "OPERATION", "RepairCommand", "run"]

OPERATION = "repair"
DESCRIPTION = (
    "Read IN as the file holds it (no on-read repairs), mend what inspection finds (weld "
    "colocated vertices, drop degenerate, duplicated and isolated elements, split T-junctions, "
    "orient patches and blocks) and write OUT; prints what each action did (progress lines on "
    "stderr on a terminal or when the work is long)."
)


class RepairCommand(SceneCommand):
    """The files and the command-line-only options of ``geobrep repair``."""

    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the repair report as JSON"""
    progress: Annotated[bool, Cli(flags=("--progress",))] = False
    """a progress line per step (inspection, each action, writing) on stderr even when the work
    is short and stderr is no terminal"""
    no_progress: Annotated[bool, Cli(flags=("--no-progress",))] = False
    """no progress lines (default: on a terminal, or once the work has run 2 s)"""


COMMAND = RepairCommand


def run(options: RepairStep, args: RepairCommand) -> int:
    from geobrep.ops.io import write
    from geobrep.ops.repairing import repair

    lines = ProgressLines("repair", progress_mode(args.progress, args.no_progress))
    begin = time.perf_counter()
    scene = read_input(args, args.input, format=args.format, repair=False)
    lines.line(f"{args.input} read {time.perf_counter() - begin:.2f} s")
    repaired, report = repair(
        scene, options.actions, options.tolerance, progress=lines.step(args.input)
    )
    begin = time.perf_counter()
    path = write(repaired, args.output, format=args.output_format)
    lines.line(f"{path} written {time.perf_counter() - begin:.2f} s")
    if args.as_json:
        print(report.model_dump_json(indent=2))
        return 0
    print(f"{args.input} -> {path}: {report.total} change(s)")
    for action in report.actions:
        if action.count:
            print(f"  {action.action}: {action.count}")
    for check, before in report.before.items():
        if before:
            print(f"  {check}: {before} -> {report.after.get(check, 0)} defect(s)")
    return 0
