"""Format conversion for one file or thousands: honest about losses, isolated per file.

:func:`convert` reads each input through the format registry, writes it in the target format
(atomically: a failure never leaves a partial file) and returns a :class:`ConversionSummary`
with one :class:`FileReport` per input: what the target format could not hold (from its
:class:`~geobrep.host.registry.FormatCapabilities`), or why the file failed. A corrupt file fails
alone; the rest are converted. ``jobs=N`` converts in N processes; ``client=`` runs the same
per-file work on a Dask cluster (a ``dask.distributed.Client`` or a scheduler address).

>>> import geobrep, tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> source = geobrep.write(geobrep.datasets.faulted_layer_cake(), folder / "cake.geobrep")
>>> summary = convert(source, folder / "cake.ply")
>>> summary.ok, summary.reports[0].lost[0]
(True, '7 Block entities dropped (format holds PointSet, PolyLine, Surface)')
"""

from __future__ import annotations

import glob
import multiprocessing
import multiprocessing.connection
import re
import signal
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.connection import Connection
from multiprocessing.context import DefaultContext
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, Literal, TypeVar

from pydantic import BaseModel, ConfigDict

from geobrep.batch.outputs import OutputFolder, check_file_name, contained
from geobrep.errors import FileAccessError, FormatError, GeobrepError, OptionsError, import_optional
from geobrep.host.capabilities import (
    format_losses,
    has_geometry,
    restrict_scene,
)
from geobrep.host.registry import FormatCapabilities, FormatSpec
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

if TYPE_CHECKING:
    from geobrep.batch.pipeline import Pipeline

__all__ = [
    "ConversionSummary",
    "FileReport",
    "PipelineFileReport",
    "PipelineSummary",
    "StepReport",
    "WorkerDiedError",
    "conversion_pipeline",
    "convert",
    "convert_file",
    "convert_one",
    "demo_stage",
    "expand",
    "file_losses",
    "run_each",
    "verify_read_back",
    "verify_written",
    "worker_failure",
]

PathArg = str | PathLike[str]
Progress = Callable[["FileReport", int, int], None]
R = TypeVar("R")


class FileReport(BaseModel):
    """The outcome of converting one file."""

    model_config = ConfigDict(frozen=True)

    source: Path
    target: Path | None = None
    status: Literal["converted", "failed"]
    lost: tuple[str, ...] = ()
    """What the target format could not hold (empty: nothing was dropped)."""
    error: str | None = None
    entities: int = 0
    columns: int = 0
    """Stratigraphic columns (groups) written: a horizon stack holds no entities."""
    seconds: float = 0.0


class StepReport(BaseModel):
    """What one pipeline step did to one input."""

    model_config = ConfigDict(frozen=True)

    step: int
    """The step's number, counted from 1 (0: the implicit read when the pipeline has none)."""
    kind: str
    entities: int = 0
    """Entities in the scene after the step."""
    columns: int = 0
    """Stratigraphic columns in the scene after the step (groups of kind
    ``stratigraphic_column``)."""
    seconds: float = 0.0
    notes: tuple[str, ...] = ()
    """What the step wants known: fit accuracy, octree size, what an output format drops."""


class PipelineFileReport(BaseModel):
    """The outcome of one input of a pipeline: its outputs, or the step that failed and why."""

    model_config = ConfigDict(frozen=True)

    source: Path
    status: Literal["done", "failed"]
    outputs: tuple[Path, ...] = ()
    error: str | None = None
    failed_step: int | None = None
    steps: tuple[StepReport, ...] = ()
    lost: tuple[str, ...] = ()
    """What the output formats could not hold, per output file."""
    seconds: float = 0.0


Report = TypeVar("Report", bound=FileReport | PipelineFileReport)


class PipelineSummary(BaseModel, Generic[Report]):
    """Every input's report, in input order: the one summary of :func:`convert` (its reports
    are :class:`FileReport`) and of :func:`geobrep.batch.pipeline_run.run_pipeline`
    (:class:`PipelineFileReport`). ``ConversionSummary`` is this type.

    >>> PipelineSummary(reports=()).table().splitlines()[-1]
    '0 done, 0 failed'
    """

    model_config = ConfigDict(frozen=True)

    reports: tuple[Report, ...]

    @property
    def ok(self) -> bool:
        """True when every input went through."""
        return all(r.status != "failed" for r in self.reports)

    @property
    def failed(self) -> tuple[Report, ...]:
        """The reports of the inputs that failed."""
        return tuple(r for r in self.reports if r.status == "failed")

    @property
    def done(self) -> tuple[Report, ...]:
        """The reports of the inputs whose outputs were written."""
        return tuple(r for r in self.reports if r.status != "failed")

    @property
    def converted(self) -> tuple[Report, ...]:
        """The same as :attr:`done` (the files written)."""
        return self.done

    def table(self) -> str:
        """A plain-text table: one row per input, then the totals.

        >>> ConversionSummary(reports=(FileReport(source="a.ts", status="failed", error="bad"),
        ...     )).table().splitlines()[-1]
        '0 converted, 1 failed'
        """
        if any(isinstance(r, FileReport) for r in self.reports):
            rows = [("status", "source", "target", "notes")]
            for r in self.reports:
                if isinstance(r, FileReport):
                    notes = r.error if r.error else ("; ".join(r.lost) or "nothing lost")
                    rows.append((r.status, str(r.source), str(r.target or "-"), notes or ""))
            return report_table(rows, f"{len(self.done)} converted, {len(self.failed)} failed")
        rows = [("status", "source", "outputs", "notes")]
        for r in self.reports:
            if isinstance(r, PipelineFileReport):
                outputs = ", ".join(p.name for p in r.outputs) or "-"
                notes = r.error or "; ".join(n for s in r.steps for n in s.notes) or ""
                rows.append((r.status, str(r.source), outputs, notes))
        return report_table(rows, f"{len(self.done)} done, {len(self.failed)} failed")


ConversionSummary = PipelineSummary
"""The summary of :func:`convert`: the same type as a pipeline's."""


def report_table(rows: Sequence[tuple[str, str, str, str]], totals: str) -> str:
    """Rows of four cells as aligned text (the last cell free-form), then a totals line."""
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    lines = [
        "  ".join(cell.ljust(width) for cell, width in zip(row[:3], widths, strict=True))
        + "  "
        + row[3]
        for row in rows
    ]
    return "\n".join([*lines, totals])


def expand(inputs: PathArg | Iterable[PathArg]) -> list[Path]:
    """Paths from paths and glob patterns, in the order given (each pattern sorted).

    A pattern matching nothing stays as given, so it is reported as a missing file.
    """
    items = [inputs] if isinstance(inputs, str | PathLike) else list(inputs)
    paths: list[Path] = []
    for item in items:
        text = str(item)
        if glob.has_magic(text):
            matches = sorted(glob.glob(text, recursive=True))
            paths.extend(Path(m) for m in matches) if matches else paths.append(Path(text))
        else:
            paths.append(Path(text))
    return paths


def conversion_pipeline(
    read_format: str | None = None,
    write_format: str | None = None,
    name: str = "{stem}",
    write_options: dict[str, Any] | None = None,
    verify: bool = False,
    tessellate: bool = False,
) -> Pipeline:
    """The pipeline a conversion is: a ``read`` step, then a ``convert`` step (a write).

    >>> [step.kind for step in conversion_pipeline(write_format="vtu").step_list]
    ['read', 'convert']
    """
    from geobrep.batch.pipeline import ConvertStep, Pipeline, ReadStep

    write_step = ConvertStep(
        format=write_format,
        name=name,
        options=dict(write_options or {}),
        verify=verify,
        tessellate=tessellate,
        allow_empty=True,  # convert writes what it read; the command line refuses it (exit 4)
    )
    return Pipeline(steps=(ReadStep(format=read_format), write_step))


def convert_one(pipeline: Pipeline, source: Path, target: Path, contain: bool = True) -> FileReport:
    """Run a conversion pipeline (:func:`conversion_pipeline`) on one file, as a FileReport.

    It runs through the pipeline executor (:func:`geobrep.batch.pipeline_run.run_steps`);
    never raises: a failure is a report with ``error`` set.
    """
    from geobrep.batch.pipeline_run import run_steps

    report, error = run_steps(pipeline, source, (target,), contain=contain)
    if report.status == "failed":
        return FileReport(
            source=source,
            target=target,
            status="failed",
            error=error or report.error,
            seconds=report.seconds,
        )
    prefix = f"{target.name}: "
    return FileReport(
        source=source,
        target=target,
        status="converted",
        lost=tuple(loss.removeprefix(prefix) for loss in report.lost),
        entities=report.steps[-1].entities if report.steps else 0,
        columns=report.steps[-1].columns if report.steps else 0,
        seconds=report.seconds,
    )


def _literal(name: str) -> str:
    """A file name as a name pattern that gives itself (braces doubled)."""
    return name.replace("{", "{{").replace("}", "}}")


def convert_file(
    source: Path,
    target: Path,
    read_format: str | None = None,
    write_format: str | None = None,
    write_options: dict[str, Any] | None = None,
    verify: bool = False,
    out_dir: Path | None = None,
    tessellate: bool = False,
) -> FileReport:
    """Convert one file; never raises: a failure is a report with ``error`` set.

    ``verify`` reads the written file back: anything missing that the report does not list
    as lost makes the file fail. With ``out_dir``, ``target`` must resolve inside that folder
    when it is written (see :func:`geobrep.batch.outputs.contained`).
    """
    if out_dir is not None and target.parent.resolve() != out_dir.resolve():
        started = time.perf_counter()
        try:
            contained(target, out_dir)
        except GeobrepError as exc:
            return _failed(source, target, str(exc), started)
    pipeline = conversion_pipeline(
        read_format, write_format, _literal(target.name), write_options, verify, tessellate
    )
    return convert_one(pipeline, source, target, contain=out_dir is not None)


def file_losses(scene: Scene, spec: FormatSpec, target: Path) -> list[str]:
    """What ``target``, written by ``spec``, cannot hold of ``scene`` (the sentences of a report;
    see :func:`geobrep.host.capabilities.format_losses`)."""
    return format_losses(scene, spec, target)


def verify_written(scene: Scene, target: Path, format_name: str, lost: Sequence[str]) -> None:
    """Read ``target`` back; raise :class:`FormatError` unless it holds what ``scene`` held,
    less what ``lost`` reports (see :func:`verify_read_back`)."""
    from geobrep.host import registries

    spec = registries().formats.get(format_name)
    try:
        back = read(target, format=spec.name)
    except GeobrepError as exc:
        raise FormatError(f"verify: the written file cannot be read back: {exc}") from exc
    problems = verify_read_back(scene, back, spec.capabilities, lost)
    if problems:
        raise FormatError(
            f"verify: {target.name} read back differs from the report: "
            + "; ".join(problems[:5])
            + (f" (and {len(problems) - 5} more)" if len(problems) > 5 else "")
        )


def verify_read_back(
    written: Scene, back: Scene, caps: FormatCapabilities, lost: Sequence[str]
) -> list[str]:
    """What ``back`` (a file read back) lacks of ``written`` that ``lost`` does not explain.

    Compared, as far as ``caps`` holds them: the entities of each type, and per entity its
    vertex and cell counts, name, id and property names. Empty when the report is true.

    >>> import geobrep
    >>> scene = geobrep.datasets.faulted_layer_cake()
    >>> caps = geobrep.plugins.registries().formats.get("native").capabilities
    >>> verify_read_back(scene, scene, caps, [])
    []
    """
    kept = restrict_scene(written, caps).entities
    dropped = {
        match.group(1)
        for sentence in lost
        if (match := re.match(r"\d+ (\w+) entities dropped", sentence)) is not None
    }
    kept = tuple(e for e in kept if e.type not in dropped)
    problems: list[str] = []
    merged = len(kept) > 1 and not caps.multiple_entities
    if merged:
        if len(back.entities) != 1:
            problems.append(f"{len(kept)} entities merged into one: {len(back.entities)} read")
        return problems
    for type_name in sorted({e.type for e in kept} | {e.type for e in back.entities}):
        want = [e for e in kept if e.type == type_name]
        got = [e for e in back.entities if e.type == type_name]
        if len(want) != len(got):
            problems.append(f"{len(got)} {type_name} entities read, {len(want)} written")
            continue
        for entity, other in zip(want, got, strict=True):
            problems.extend(_entity_problems(entity, other, caps, lost))
    return problems


def _entity_problems(
    entity: Any, other: Any, caps: FormatCapabilities, lost: Sequence[str]
) -> list[str]:
    where = entity.label
    problems = []
    if has_geometry(entity) or has_geometry(other):
        if other.n_points != entity.n_points and not _points_said(where, other.n_points, lost):
            problems.append(f"{where}: {other.n_points} points read, {entity.n_points} written")
        if other.n_cells != entity.n_cells:
            problems.append(f"{where}: {other.n_cells} cells read, {entity.n_cells} written")
    if caps.names and other.name != entity.name:
        problems.append(f"{where}: read back named {other.name!r}")
    if caps.ids and other.id != entity.id:
        problems.append(f"{where}: read back with id {other.id}")
    for field, able in (("point_data", caps.point_data), ("cell_data", caps.cell_data)):
        missing = sorted(
            name
            for name in set(getattr(entity, field)) - set(getattr(other, field))
            if not any(name in sentence for sentence in lost)  # reported: renamed, split
        )
        if able and missing:
            problems.append(f"{where}: {field} {', '.join(missing)} not read back")
    return problems


def _points_said(where: str, n_points: int, lost: Sequence[str]) -> bool:
    """Whether the report says ``where`` reads back as ``n_points`` points (a writer that
    copies shared vertices, such as a Model3d's TFACEs, says so)."""
    said = re.compile(rf"^{re.escape(where)}: .*\b{n_points} points read back\b")
    return any(said.search(sentence) for sentence in lost)


def _failed(source: Path, target: Path | None, error: str, started: float) -> FileReport:
    return FileReport(
        source=source,
        target=target,
        status="failed",
        error=error,
        seconds=time.perf_counter() - started,
    )


def _targets(
    sources: Sequence[Path],
    output: Path | None,
    to: str | None,
    out_dir: Path | None,
) -> tuple[list[Path | str], Path | None]:
    """Where each source goes, or why it cannot go (its name clashes with an earlier one, or
    its path resolves outside the output folder); and the output folder (None: one file)."""
    if out_dir is None and output is not None and (to is not None or output.is_dir()):
        out_dir = output
        output = None
    if output is not None:
        if len(sources) != 1:
            raise OptionsError(
                f"{len(sources)} inputs need an output folder (out_dir=...) and a format (to=...)"
            )
        return [output], None
    if out_dir is None:
        raise OptionsError("give an output file, or out_dir=... with to=... for many files")
    if to is None:
        raise OptionsError("converting into a folder needs the target format: to='vtu'")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileAccessError(
            f"cannot create the output folder ({exc.strerror or exc})", out_dir
        ) from exc
    from geobrep.host import registries

    formats = registries().formats
    if to in formats:  # a format name: its first extension
        spec = formats.get(to)
        extension = spec.extensions[0] if spec.extensions else f".{spec.name}"
    else:  # an extension (`ml`, `.vtu`): kept as given, so `ml` writes a Model3d, not a TSurf
        extension = "." + to.lstrip(".").lower()
        check_file_name("x" + extension)  # an extension, never a path
        formats.choose_writer(Path(f"x{extension}"))
    folder = OutputFolder(out_dir)
    targets: list[Path | str] = []
    seen: set[Path] = set()
    for source in sources:
        try:
            target = folder.target(source.name.split(".")[0] + extension)
        except GeobrepError as exc:
            targets.append(str(exc))
            continue
        targets.append("another input has the same output name" if target in seen else target)
        seen.add(target)
    return targets, out_dir


def convert(
    inputs: PathArg | Iterable[PathArg],
    output: PathArg | None = None,
    *,
    to: str | None = None,
    out_dir: PathArg | None = None,
    jobs: int = 1,
    client: Any = None,
    read_format: str | None = None,
    write_options: dict[str, Any] | None = None,
    progress: Progress | None = None,
    verify: bool = False,
    tessellate: bool = False,
) -> ConversionSummary[FileReport]:
    """Convert files; returns the per-file reports (it never stops at a bad file).

    ``convert("in.ts", "out.vtu")`` converts one file; ``convert(["a/*.ts"], out_dir="out",
    to="vtu", jobs=4)`` converts many (paths or glob patterns), each to ``out/<stem>.vtu``.
    ``to`` names a registered format (or an extension); ``jobs`` runs that many worker
    processes; ``client`` (a ``dask.distributed.Client`` or a scheduler address such as
    ``"tcp://scheduler:8786"``) runs the files on a Dask cluster instead. ``progress(report,
    done, total)`` is called as each file finishes. ``verify=True`` reads each written file
    back and fails the file when something is missing that its report does not list as lost
    (see :func:`verify_read_back`); ``tessellate=True`` writes NURBS surfaces as meshes when
    the format cannot hold them (otherwise they are reported lost).

    Each file goes through the pipeline executor: the conversion is a ``read`` step and a
    ``convert`` step (:func:`conversion_pipeline`; ``geobrep run`` with those two steps writes
    the same files).

    Raises:
        OptionsError: contradictory arguments (several inputs and one output file, no format).
    """
    if jobs < 1:
        raise OptionsError(f"jobs must be at least 1, got {jobs}")
    sources = expand(inputs)
    target_dir = None if out_dir is None else Path(out_dir)
    targets, folder = _targets(sources, None if output is None else Path(output), to, target_dir)
    write_format = None
    if to is not None:
        from geobrep.host import registries

        formats = registries().formats
        write_format = to if to in formats else None
    work = [(s, t) for s, t in zip(sources, targets, strict=True) if isinstance(t, Path)]
    results: dict[int, FileReport] = {}
    total = len(sources)
    for index, (source, target) in enumerate(zip(sources, targets, strict=True)):
        if isinstance(target, str):
            results[index] = _failed(source, None, target, 0.0)

    def done(index: int, report: FileReport) -> None:
        results[index] = report
        if progress is not None:
            progress(report, len(results), total)

    indices = [i for i, t in enumerate(targets) if isinstance(t, Path)]
    arguments = [
        (
            conversion_pipeline(
                read_format, write_format, _pattern(t, folder), write_options, verify, tessellate
            ),
            s,
            t,
            folder is not None,
        )
        for s, t in work
    ]

    def finished(position: int, report: FileReport | None, error: BaseException | None) -> None:
        if report is None:  # the worker died (killed, out of memory)
            source, target = arguments[position][1:3]
            report = _failed(source, target, worker_failure(error), 0.0)
        done(indices[position], report)

    run_each(convert_one, arguments, finished, jobs=jobs if len(work) > 1 else 1, client=client)
    return PipelineSummary[FileReport](reports=tuple(results[i] for i in range(total)))


def _pattern(target: Path, folder: Path | None) -> str:
    """The name pattern of a conversion's write step: ``{stem}`` and the extension into a
    folder, the output's own name for one file."""
    if folder is None:
        return _literal(target.name)
    stem = target.name.split(".")[0]
    return "{stem}" + _literal(target.name[len(stem) :])


def run_each(
    function: Callable[..., R],
    arguments: Sequence[tuple[Any, ...]],
    done: Callable[[int, R | None, BaseException | None], None],
    *,
    jobs: int = 1,
    client: Any = None,
) -> None:
    """Call ``function(*args)`` for every tuple of ``arguments``: here, in processes, or on Dask.

    ``jobs > 1`` runs that many worker processes; ``client`` (a ``dask.distributed.Client`` or
    a scheduler address) runs the calls on a Dask cluster. ``done(position, result, None)`` is
    called as each call finishes, in completion order; ``done(position, None, error)`` when a
    worker died under it. ``function`` should not raise: in this process an exception
    propagates. Shared by :func:`convert` and :func:`geobrep.batch.pipeline_run.run_pipeline`.
    """
    if client is not None:
        _run_dask(client, function, arguments, done)
    elif jobs > 1 and len(arguments) > 1:
        _run_processes(jobs, function, arguments, done)
    else:
        for position, args in enumerate(arguments):
            done(position, function(*args), None)


class WorkerDiedError(GeobrepError):
    """A worker process died under one call (a crash, a signal, the out-of-memory killer).

    >>> str(WorkerDiedError(-9))
    'worker died (signal 9, SIGKILL)'
    """

    def __init__(self, exitcode: int | None) -> None:
        self.exitcode = exitcode
        if exitcode is None:
            status = "no exit status"
        elif exitcode < 0:
            try:
                status = f"signal {-exitcode}, {signal.Signals(-exitcode).name}"
            except ValueError:
                status = f"signal {-exitcode}"
        else:
            status = f"exit code {exitcode}"
        super().__init__(f"worker died ({status})")


def worker_failure(error: BaseException | None) -> str:
    """What a report says of a call that returned nothing: its worker died, or raised.

    >>> worker_failure(WorkerDiedError(1))
    'worker died (exit code 1)'
    """
    if isinstance(error, WorkerDiedError):
        return str(error)
    text = f"worker failed: {type(error).__name__}"
    return f"{text}: {error}" if str(error) else text


Done = Callable[[int, R | None, BaseException | None], None]


def _run_processes(
    jobs: int, function: Callable[..., R], arguments: Sequence[tuple[Any, ...]], done: Done[R]
) -> None:
    """Run the calls in a pool of ``jobs`` processes; a worker's death costs only its call.

    At most ``2 * jobs`` calls are in the pool at a time. When a worker dies the pool is broken
    and every call in it fails: those calls (the suspects) are run again, each in a process of
    its own, which tells the one that kills its worker (reported as :class:`WorkerDiedError`
    with the exit status) from the innocent; then a new pool takes the rest.
    """
    context = multiprocessing.get_context()
    waiting = deque(range(len(arguments)))
    while waiting:
        suspects = _pool_round(jobs, context, function, arguments, waiting, done)
        for start in range(0, len(suspects), jobs):
            _run_alone(context, function, arguments, suspects[start : start + jobs], done)


def _pool_round(
    jobs: int,
    context: DefaultContext,
    function: Callable[..., R],
    arguments: Sequence[tuple[Any, ...]],
    waiting: deque[int],
    done: Done[R],
) -> list[int]:
    """Run waiting calls in one pool until they are done or it breaks; returns the suspects."""
    suspects: list[int] = []
    running: dict[Future[R], int] = {}
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        while waiting or running:
            while waiting and len(running) < 2 * jobs and not suspects:
                position = waiting.popleft()
                try:
                    running[pool.submit(function, *arguments[position])] = position
                except BrokenProcessPool:
                    waiting.appendleft(position)
                    break
            if not running:
                break
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                position = running.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool:  # a worker died: this call, or another one in the pool
                    suspects.append(position)
                except Exception as exc:
                    done(position, None, exc)
                else:
                    done(position, result, None)
    return sorted(suspects)


def _run_alone(
    context: DefaultContext,
    function: Callable[..., R],
    arguments: Sequence[tuple[Any, ...]],
    positions: Sequence[int],
    done: Done[R],
) -> None:
    """Run each call in a process of its own, at the same time; a death is that call's."""
    started = {}
    for position in positions:
        receive, send = context.Pipe(duplex=False)
        process = context.Process(target=_call_and_send, args=(send, function, arguments[position]))
        process.start()
        send.close()
        started[receive] = (position, process)
    while started:
        for ready in multiprocessing.connection.wait(list(started)):
            assert isinstance(ready, Connection)
            position, process = started.pop(ready)
            try:
                outcome, value = ready.recv()
            except (EOFError, OSError):  # the process ended without an answer: it died
                process.join()
                done(position, None, WorkerDiedError(process.exitcode))
            else:
                process.join()
                if outcome == "result":
                    done(position, value, None)
                else:
                    done(position, None, value)
            finally:
                ready.close()


def _call_and_send(send: Connection, function: Callable[..., Any], args: tuple[Any, ...]) -> None:
    """In a child process: call ``function`` and send ``("result", value)`` or the exception."""
    try:
        message: tuple[str, Any] = ("result", function(*args))
    except BaseException as exc:  # like a pool worker: the caller gets the exception
        message = ("error", exc)
    try:
        send.send(message)
    except Exception as exc:  # the result or the exception cannot be pickled
        send.send(("error", RuntimeError(f"{type(exc).__name__}: {exc}")))
    finally:
        send.close()


def _run_dask(
    client: Any,
    function: Callable[..., R],
    arguments: Sequence[tuple[Any, ...]],
    done: Callable[[int, R | None, BaseException | None], None],
) -> None:
    distributed = import_optional("distributed", "dask", "running on a Dask cluster")
    own = isinstance(client, str)
    active = distributed.Client(client) if own else client
    try:
        futures = {
            active.submit(function, *args, pure=False): position
            for position, args in enumerate(arguments)
        }
        for future in distributed.as_completed(list(futures)):
            position = futures[future]
            try:
                result = future.result()
            except Exception as exc:  # the worker died
                done(position, None, exc)
            else:
                done(position, result, None)
    finally:
        if own:
            active.close()


def demo_stage(ctx: Any) -> None:
    """Demo: the model converted to .vtu and .ply, a picture with a legend, and a web page."""
    from geobrep.host import registries

    formats = registries().formats
    section: dict[str, Any] = {}
    source = ctx.output / "conversion_source.geobrep"
    write(ctx.scene, source, format="native")
    for name, file_name in (("vtu", "layer_cake.vtu"), ("ply", "layer_cake.ply")):
        if name not in formats:
            section[name] = {"status": "skipped", "reason": f"format {name!r} not installed"}
            ctx.lines.append(f"convert: {name} skipped (format not installed)")
            continue
        report = convert(source, ctx.output / file_name).reports[0]
        section[name] = report.model_dump(mode="json")
        kept = len(read(ctx.output / file_name).entities) if report.status == "converted" else 0
        lost = "; ".join(report.lost) or "nothing"
        ctx.lines.append(
            f"convert: {file_name}: {report.status}, {kept} entities kept; lost: {lost}"
            if report.status == "converted"
            else f"convert: {file_name}: failed: {report.error}"
        )
    source.unlink()
    picture = ctx.output / "layer_cake.png"
    if "png" in formats:
        try:
            write(ctx.scene, picture, format="png", color_by="block")
            section["picture"] = str(picture.name)
            ctx.lines.append(f"render: {picture.name} (coloured by block)")
        except GeobrepError as exc:
            section["picture"] = None
            ctx.lines.append(f"render: skipped ({exc})")
    else:
        section["picture"] = None
        ctx.lines.append("render: skipped (install geobrep[viz] for pictures)")
    section["page"] = _demo_page(ctx, formats)
    ctx.summary["conversion"] = section


def _demo_page(ctx: Any, formats: Any) -> str | None:
    """Demo: ``layer_cake.html``, the model to look at in a browser (``geobrep view``)."""
    page = ctx.output / "layer_cake.html"
    if "html" not in formats:
        ctx.lines.append("view: skipped (format 'html' not installed)")
        return None
    write(ctx.scene, page, format="html")
    ctx.lines.append(f"view: {page.name} (open it in a browser: no server needed)")
    return str(page.name)
