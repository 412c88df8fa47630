"""``geobrep convert``: one file to another format, or many files into a folder.

``geobrep convert IN OUT`` converts one file (formats from the extensions);
``geobrep convert IN... --to FMT -o DIR [--jobs N]`` converts many (paths or glob patterns) to
``DIR/<stem>.<ext>``. Each file's losses are reported; the exit code is 1 if any file failed,
with every failure listed. ``--verify`` reads each written file back: a file that lacks
something its report does not list as lost fails.

A conversion is a read step and a ``convert`` step run by the pipeline executor
(:func:`geobrep.batch.conversion.convert`); the parser is derived from the ``convert``
operation (:class:`~geobrep.batch.pipeline.ConvertStep`: ``--verify``, ``--option``,
``--tessellate``) and :class:`ConvertCommand` (the files, ``--to``, ``--jobs``, ...).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Protocol

from pydantic import BaseModel, ConfigDict

from geobrep.batch.conversion import ConversionSummary, FileReport, convert
from geobrep.batch.pipeline import ConvertStep
from geobrep.cli.common import format_name, refuse_empty
from geobrep.errors import OptionsError
from geobrep.host.operations import Cli, options_from_args

__all__ = [
    "COMMAND",
    "OPERATION",
    "OPTIONS_FOR",
    "ConvertCommand",
    "ProgressBar",
    "convert_options",
    "run",
]

OPERATION = "convert"


class ConvertCommand(BaseModel):
    """The files and the command-line-only options of ``geobrep convert``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    paths: Annotated[tuple[str, ...], Cli(positional=True, nargs="+", metavar="PATH")]
    """input file(s) or glob(s), then the output file when converting one file without --to"""
    to: Annotated[str | None, Cli(parse=format_name("write"), metavar="FMT")] = None
    """target format name or extension (many files)"""
    output_dir: Annotated[str | None, Cli(flags=("-o", "--output-dir"), metavar="DIR")] = None
    """output folder (many files)"""
    jobs: Annotated[int, Cli(flags=("--jobs", "-j"), metavar="N")] = 1
    """convert N files at a time in worker processes"""
    dask: Annotated[str | None, Cli(metavar="ADDRESS")] = None
    """run on a Dask cluster, e.g. tcp://scheduler:8786"""
    format: Annotated[str | None, Cli(parse=format_name("read"), metavar="NAME")] = None
    """input format, when the extension is not enough"""
    no_progress: bool = False
    """no progress bar"""
    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the reports as JSON"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""

    def output(self) -> str | None:
        """The output file of ``IN OUT`` (None when converting into a folder)."""
        if self.to is not None or self.output_dir is not None:
            return None
        if len(self.paths) != 2:
            raise OptionsError("give IN OUT for one file, or IN... --to FMT -o DIR for many files")
        return self.paths[-1]

    def inputs(self) -> list[str]:
        """The input paths and patterns."""
        return list(self.paths[:-1] if self.output() is not None else self.paths)


def convert_options(command: ConvertCommand, given: Mapping[str, Any]) -> ConvertStep:
    """The ``convert`` step the arguments give: ``--to`` (a format name) is its format, the
    output file's name or ``{stem}.EXT`` its name."""
    from geobrep.host import registries

    output = command.output()
    to = command.to
    data: dict[str, Any] = dict(given)
    if to is not None and to in registries().formats:
        data["format"] = to
    elif to is not None:
        data["name"] = "{stem}." + to.lstrip(".")
    elif output is not None:
        data["name"] = Path(output).name.replace("{", "{{").replace("}", "}}")
    else:  # -o DIR without --to: convert() says a folder needs the target format
        data["name"] = "{stem}"
    return options_from_args(ConvertStep, data)  # type: ignore[no-any-return]


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


def run(step: ConvertStep, command: ConvertCommand) -> int:
    as_json = command.as_json
    progress = ProgressBar(enabled=not command.no_progress and not as_json and sys.stderr.isatty())
    summary = convert(
        command.inputs(),
        command.output(),
        to=command.to,
        out_dir=command.output_dir,
        jobs=command.jobs,
        client=command.dask,
        read_format=command.format,
        write_options=step.writer_options(),
        progress=progress,
        verify=step.verify,
        tessellate=step.tessellate,
    )
    _print(summary, as_json)
    if not summary.ok:
        return 1
    empty = [
        f"{r.target}: nothing read from {r.source}"
        for r in summary.converted
        if not r.entities and not r.columns
    ]
    refuse_empty(command, empty, consequence="the file holds nothing")
    return 0


def _print(summary: ConversionSummary[FileReport], as_json: bool) -> None:
    if as_json:
        print(json.dumps([r.model_dump(mode="json") for r in summary.reports], indent=2))
    else:
        print(summary.table())
    for report in summary.failed:
        print(f"geobrep: failed: {report.source}: {report.error}", file=sys.stderr)


COMMAND = ConvertCommand
OPTIONS_FOR = convert_options
