"""``geobrep run pipeline.yaml``: run a pipeline file over its inputs.

``geobrep run pipeline.yaml`` runs the steps on every input of the pipeline; ``FILE...`` replaces
its inputs and ``-o DIR`` its output folder; ``--jobs N`` runs N inputs at a time in worker
processes and ``--dask ADDRESS`` on a Dask cluster. ``--check`` only validates the pipeline
(every plugin and option) and lists the inputs. The exit code is 1 if any input failed, with
every failure listed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from geobrep.cli.convert import ProgressBar

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "run",
        description="Run the steps of a pipeline file (YAML or JSON) on each of its inputs. "
        "Every plugin and option is checked before any file is read; a failing input fails "
        "alone and leaves no outputs.",
    )
    parser.add_argument("pipeline", help="the pipeline file (.yaml, .yml or .json)")
    parser.add_argument(
        "inputs",
        nargs="*",
        metavar="FILE",
        help="input files or globs, instead of the pipeline's inputs",
    )
    parser.add_argument(
        "-o", "--output-dir", metavar="DIR", help="instead of the pipeline's output"
    )
    parser.add_argument(
        "--jobs", "-j", type=int, default=1, metavar="N", help="run N inputs at a time in processes"
    )
    parser.add_argument(
        "--dask", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://scheduler:8786"
    )
    parser.add_argument(
        "--check",
        action="store_true",
        help="validate the pipeline and list the inputs; run nothing",
    )
    parser.add_argument(
        "--allow-empty",
        action="store_true",
        help="write results with nothing in them (by default such an input fails)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the reports as JSON")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.batch.conversion import expand
    from geobrep.batch.pipeline import Pipeline
    from geobrep.batch.pipeline_run import run_pipeline

    pipeline = Pipeline.load(args.pipeline).check()
    if args.allow_empty:
        pipeline = pipeline.allowing_empty()
    inputs = list(args.inputs) or None
    if args.check:
        base = pipeline.base_dir or Path.cwd()
        patterns = inputs or [str(base / item) for item in pipeline.inputs]
        sources = expand(patterns)
        kinds = ", ".join(step.kind for step in pipeline.step_list)
        print(f"{args.pipeline}: valid; steps: {kinds}")
        for source in sources:
            print(f"  {source}{'' if source.exists() else '  (missing)'}")
        return 0
    progress = ProgressBar(enabled=not args.no_progress and not args.json and sys.stderr.isatty())
    summary = run_pipeline(
        pipeline,
        inputs=inputs,
        output=args.output_dir,
        jobs=args.jobs,
        client=args.dask,
        progress=progress,
    )
    if args.json:
        print(json.dumps([r.model_dump(mode="json") for r in summary.reports], indent=2))
    else:
        print(summary.table())
    for report in summary.failed:
        print(f"geobrep: failed: {report.source}: {report.error}", file=sys.stderr)
    return 0 if summary.ok else 1
