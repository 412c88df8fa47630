"""``geobrep convert``: one file to another format, or many files into a folder.

``geobrep convert IN OUT`` converts one file (formats from the extensions);
``geobrep convert IN... --to FMT -o DIR [--jobs N]`` converts many (paths or glob patterns) to
``DIR/<stem>.<ext>``. Each file's losses are reported; the exit code is 1 if any file failed,
with every failure listed. ``--verify`` reads each written file back: a file that lacks
something its report does not list as lost fails.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Protocol

from geobrep.batch.conversion import ConversionSummary, FileReport, convert
from geobrep.cli.common import add_allow_empty, format_name, refuse_empty
from geobrep.errors import OptionsError

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "convert",
        help="convert files between formats",
        description="Convert one file (IN OUT), or many files into a folder "
        "(IN... --to FMT -o DIR). What the target format cannot hold is reported per file.",
    )
    parser.add_argument(
        "paths",
        nargs="+",
        metavar="PATH",
        help="input file(s) or glob(s), then the output file when converting one file without --to",
    )
    parser.add_argument(
        "--to",
        type=format_name("write"),
        metavar="FMT",
        help="target format name or extension (many files)",
    )
    parser.add_argument("-o", "--output-dir", metavar="DIR", help="output folder (many files)")
    parser.add_argument(
        "--jobs",
        "-j",
        type=int,
        default=1,
        metavar="N",
        help="convert N files at a time in worker processes",
    )
    parser.add_argument(
        "--dask", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://scheduler:8786"
    )
    parser.add_argument(
        "--format",
        dest="read_format",
        type=format_name("read"),
        metavar="NAME",
        help="input format, when the extension is not enough",
    )
    parser.add_argument(
        "--verify",
        action="store_true",
        help="read each written file back; a file missing what its report keeps fails",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the reports as JSON")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


class Reported(Protocol):
    """What the progress bar shows of a report (a conversion's or a pipeline's)."""

    @property
    def source(self) -> Path: ...

    @property
    def status(self) -> str: ...


class ProgressBar:
    """A one-line progress bar on stderr (only drawn on a terminal unless forced)."""

    def __init__(self, enabled: bool, width: int = 30) -> None:
        self.enabled = enabled
        self.width = width

    def __call__(self, report: Reported, done: int, total: int) -> None:
        if not self.enabled:
            return
        filled = int(self.width * done / max(total, 1))
        mark = "FAILED" if report.status == "failed" else "ok"
        name = report.source.name[-40:]
        sys.stderr.write(
            f"\r[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} {mark:6} {name:40}"
        )
        if done == total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def run(args: argparse.Namespace) -> int:
    paths: list[str] = list(args.paths)
    output = None
    if args.to is None and args.output_dir is None:
        if len(paths) != 2:
            raise OptionsError("give IN OUT for one file, or IN... --to FMT -o DIR for many files")
        output = paths.pop()
    progress = ProgressBar(enabled=not args.no_progress and not args.json and sys.stderr.isatty())
    summary = convert(
        paths,
        output,
        to=args.to,
        out_dir=args.output_dir,
        jobs=args.jobs,
        client=args.dask,
        read_format=args.read_format,
        progress=progress,
        verify=args.verify,
    )
    _print(summary, args.json)
    if not summary.ok:
        return 1
    empty = [
        f"{r.target}: nothing read from {r.source}" for r in summary.converted if not r.entities
    ]
    refuse_empty(args, empty, consequence="the file holds nothing")
    return 0


def _print(summary: ConversionSummary[FileReport], as_json: bool) -> None:
    if as_json:
        print(json.dumps([r.model_dump(mode="json") for r in summary.reports], indent=2))
    else:
        print(summary.table())
    for report in summary.failed:
        print(f"geobrep: failed: {report.source}: {report.error}", file=sys.stderr)
