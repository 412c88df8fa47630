"""Running a pipeline: each input through the steps, here, in processes or on a Dask cluster.

:func:`run_pipeline` checks the whole pipeline against the plugin registries first (a bad option
fails before any file is read), expands the inputs, plans every output name (an output that two
inputs would write, or that would overwrite an input, fails that input), then runs each input on
its own, like :func:`geobrep.convert`: a failing input fails alone with the step that failed;
the others go on. An input's outputs are written only after all its steps succeeded, each
atomically; if one of them cannot be written, those already written for that input are removed,
so a failed input leaves no outputs behind.

>>> import geobrep, tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = geobrep.write(geobrep.datasets.faulted_layer_cake(), folder / "cake.geobrep")
>>> summary = run_pipeline({"inputs": [str(folder / "*.geobrep")], "output": str(folder / "out"),
...     "steps": [{"clip": {"plane": [1, 0, 0, -450500]}}, {"write": {"format": "native"}}]})
>>> summary.ok, [path.name for path in summary.reports[0].outputs]
(True, ['cake.geobrep'])
"""

from __future__ import annotations

import functools
import time
import warnings
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from geobrep.batch.conversion import (
    PipelineFileReport,
    PipelineSummary,
    StepReport,
    expand,
    file_losses,
    run_each,
    verify_written,
    worker_failure,
)
from geobrep.batch.outputs import OutputFolder, contained, half_name, name_fields
from geobrep.batch.pipeline import (
    BuildBlocksStep,
    BuildStep,
    CheckStep,
    ClipBoxStep,
    ClipStep,
    ConvertStep,
    FitStep,
    MapProductsStep,
    OperationStep,
    OutputStep,
    Pipeline,
    ReadStep,
    RenderStep,
    RepairStep,
    ReprojectStep,
    SectionStep,
    StepOptions,
    ViewStep,
    VoxelizeStep,
    WriteStep,
)
from geobrep.errors import (
    FileAccessError,
    GeobrepError,
    OptionsError,
    TopologyError,
)
from geobrep.host.capabilities import without_read_losses
from geobrep.model.entities import Entity, LinearOctree, NurbsSurface, Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

if TYPE_CHECKING:
    from geobrep.host.registry import Registries
    from geobrep.ops.fitting import FitResult

__all__ = [
    "PipelineFileReport",
    "PipelineSummary",
    "StepReport",
    "plan_outputs",
    "run_file",
    "run_pipeline",
    "run_steps",
]

PathArg = str | PathLike[str]
Progress = Callable[["PipelineFileReport", int, int], None]

#: Extensions read as ``x, y, z`` point columns when no registered format claims them.


# ------------------------------------------------------------------------------- planning
def _as_pipeline(pipeline: Pipeline | PathArg | Mapping[str, Any]) -> Pipeline:
    if isinstance(pipeline, Pipeline):
        return pipeline
    if isinstance(pipeline, str | PathLike):
        return Pipeline.load(pipeline)
    return Pipeline.from_data(pipeline)


def plan_outputs(
    pipeline: Pipeline, sources: list[Path], out_dir: Path, registries: Registries
) -> list[tuple[Path, ...] | str]:
    """Per source, the file each write step produces; a message for a source that cannot run.

    A write step after a clip keeping both writes each half (in order, negative first), named
    by :func:`geobrep.batch.outputs.half_name`. Names come from
    :func:`geobrep.batch.outputs.format_name` and paths from
    :class:`~geobrep.batch.outputs.OutputFolder`: a name that is not a plain file name, or a
    path that resolves outside ``out_dir`` (through a symlink), is that source's failure. So is
    a name another source already claimed, or that is one of the inputs (the earlier source
    keeps the name).
    """
    patterns = [
        step.pattern(registries) for step in pipeline.step_list if isinstance(step, OutputStep)
    ]
    folder = OutputFolder(out_dir)
    inputs = {source.resolve() for source in sources}
    owners: dict[Path, Path] = {}
    plans: list[tuple[Path, ...] | str] = []
    halves = pipeline.halves()
    for index, source in enumerate(sources):
        try:
            targets = tuple(
                folder.target(half_name(pattern, name_fields(source, index, half)))
                for pattern, step_halves in zip(patterns, halves, strict=True)
                for half in step_halves
            )
        except GeobrepError as exc:
            plans.append(str(exc))
            continue
        problem = None
        for position, target in enumerate(targets):
            key = target.resolve()
            if key in {t.resolve() for t in targets[:position]}:
                problem = f"output {target} is written twice (give the write steps other names)"
            elif key in inputs:
                problem = f"output {target} would overwrite an input"
            elif key in owners:
                problem = f"output {target} is also the output of {owners[key]}"
            if problem:
                break
        if problem is None:
            owners.update((target.resolve(), source) for target in targets)
            plans.append(targets)
        else:
            plans.append(problem)
    return plans


def run_pipeline(
    pipeline: Pipeline | PathArg | Mapping[str, Any],
    *,
    inputs: PathArg | Iterable[PathArg] | None = None,
    output: PathArg | None = None,
    jobs: int = 1,
    client: Any = None,
    progress: Progress | None = None,
) -> PipelineSummary[PipelineFileReport]:
    """Run a pipeline over its inputs; returns the per-input reports (it never stops at one).

    ``pipeline`` is a :class:`~geobrep.batch.pipeline.Pipeline`, the path of a pipeline file, or its
    parsed mapping. ``inputs`` and ``output`` replace the pipeline's own (relative to the working
    folder; the pipeline's are relative to its file). ``jobs`` runs that many worker processes;
    ``client`` (a ``dask.distributed.Client`` or a scheduler address such as
    ``"tcp://scheduler:8786"``) runs the inputs on a Dask cluster. ``progress(report, done,
    total)`` is called as each input finishes.

    Raises:
        OptionsError: the pipeline is invalid (a plugin or option is unknown), or has no inputs.
        FileAccessError: the output folder cannot be created.
    """
    from geobrep.host import registries as loaded

    if jobs < 1:
        raise OptionsError(f"jobs must be at least 1, got {jobs}")
    the_pipeline = _as_pipeline(pipeline)
    registries = loaded()
    the_pipeline.check(registries)
    base = the_pipeline.base_dir or Path.cwd()
    if inputs is None:
        patterns: list[PathArg] = [str(base / item) for item in the_pipeline.inputs]
    else:
        patterns = [inputs] if isinstance(inputs, str | PathLike) else list(inputs)
    if not patterns:
        raise OptionsError(
            "the pipeline has no inputs: list them under 'inputs' or pass them "
            "(geobrep run pipeline.yaml FILE...)"
        )
    sources = expand(patterns)
    out_dir = Path(output) if output is not None else base / the_pipeline.output
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileAccessError(f"cannot create the output folder ({exc})", out_dir) from exc
    plans = plan_outputs(the_pipeline, sources, out_dir, registries)

    total = len(sources)
    results: dict[int, PipelineFileReport] = {}

    def done(index: int, report: PipelineFileReport) -> None:
        results[index] = report
        if progress is not None:
            progress(report, len(results), total)

    indices: list[int] = []
    arguments: list[tuple[Any, ...]] = []
    for index, (source, plan) in enumerate(zip(sources, plans, strict=True)):
        if isinstance(plan, str):
            done(index, PipelineFileReport(source=source, status="failed", error=plan))
        else:
            indices.append(index)
            arguments.append((the_pipeline, source, plan))

    def finished(
        position: int, report: PipelineFileReport | None, error: BaseException | None
    ) -> None:
        if report is None:  # the worker died (killed, out of memory)
            source = arguments[position][1]
            message = worker_failure(error)
            report = PipelineFileReport(source=source, status="failed", error=message)
        done(indices[position], report)

    run_each(run_file, arguments, finished, jobs=jobs, client=client)
    return PipelineSummary[PipelineFileReport](reports=tuple(results[i] for i in range(total)))


# ------------------------------------------------------------------------------- one input
@dataclass(frozen=True)
class _Output:
    """A file a write step makes once every step of the input succeeded."""

    number: int
    kind: str
    target: Path
    scene: Scene
    format: str
    options: dict[str, Any]
    verify: bool
    lost: tuple[str, ...]
    """What the format cannot hold of ``scene`` (checked on read-back with ``verify``)."""


@dataclass
class _Work:
    """What the steps of one input share."""

    source: Path
    targets: tuple[Path, ...]
    registries: Registries
    folder: Path = field(default_factory=Path.cwd)
    """The pipeline's folder: the files a step reads (a fit's well files) are in it."""
    contain: bool = True
    """Check that each output still resolves inside its folder right before writing it."""
    number: int = 0
    """The step running (0: the implicit read)."""
    kind: str = "read"
    pending: list[_Output] = field(default_factory=list)
    """Outputs to write once every step succeeded."""
    lost: list[str] = field(default_factory=list)
    fits: list[tuple[NurbsSurface, FitResult, FitStep]] = field(default_factory=list)
    """The NURBS surfaces fit steps made, with their results: a write step that tessellates one
    refines its mesh against the fitted points and reports the mesh's accuracy."""


def run_file(pipeline: Pipeline, source: Path, targets: tuple[Path, ...]) -> PipelineFileReport:
    """Run every step on one input and write its outputs; never raises (a failure is reported).

    ``targets`` are the files of the write steps, in order (see :func:`plan_outputs`).
    """
    return run_steps(pipeline, source, targets)[0]


def run_steps(
    pipeline: Pipeline, source: Path, targets: tuple[Path, ...], *, contain: bool = True
) -> tuple[PipelineFileReport, str | None]:
    """:func:`run_file`, and the error of a failed input without the step that raised it.

    ``contain``: each target must still resolve inside its own folder when it is written (off
    for the one file ``geobrep convert IN OUT`` writes wherever ``OUT`` is).
    """
    from geobrep.host import registries

    started = time.perf_counter()
    reports: list[StepReport] = []
    bodies = pipeline.step_list
    numbered: list[tuple[int, StepOptions]] = list(enumerate(bodies, 1))
    if not isinstance(bodies[0], ReadStep):
        numbered.insert(0, (0, ReadStep()))
    work = _Work(
        source=source,
        targets=targets,
        registries=registries(),
        folder=pipeline.base_dir or Path.cwd(),
        contain=contain,
    )
    try:
        branches: list[tuple[str, Scene]] = [("", _nothing_read())]
        for work.number, body in numbered:
            work.kind = body.kind
            begun = time.perf_counter()
            branches, notes = _step(body, branches, work)
            reports.append(
                StepReport(
                    step=work.number,
                    kind=work.kind,
                    entities=sum(len(scene.entities) for _, scene in branches),
                    columns=sum(len(scene.stratigraphic_columns) for _, scene in branches),
                    seconds=time.perf_counter() - begun,
                    notes=tuple(notes),
                )
            )
        spent = _write_outputs(work)
        reports = [
            r.model_copy(update={"seconds": r.seconds + spent[r.step]}) if r.step in spent else r
            for r in reports
        ]
    except Exception as exc:
        error = str(exc) if isinstance(exc, GeobrepError) else f"{type(exc).__name__}: {exc}"
        where = f"step {work.number} ({work.kind})" if work.number else work.kind
        failed = PipelineFileReport(
            source=source,
            status="failed",
            error=f"{where}: {error}",
            failed_step=work.number,
            steps=tuple(reports),
            seconds=time.perf_counter() - started,
        )
        return failed, error
    done = PipelineFileReport(
        source=source,
        status="done",
        outputs=targets,
        steps=tuple(reports),
        lost=tuple(work.lost),
        seconds=time.perf_counter() - started,
    )
    return done, None


@functools.cache
def _nothing_read() -> Scene:
    """The empty scene a pipeline starts from (scenes are immutable: one serves every file)."""
    return Scene()


def _write_outputs(work: _Work) -> dict[int, float]:
    """Write the pending outputs; if one fails, remove those written and re-raise.

    Returns the seconds spent writing, per write step.
    """
    written: list[Path] = []
    spent: dict[int, float] = {}
    try:
        for output in work.pending:
            work.number, work.kind = output.number, output.kind
            begun = time.perf_counter()
            target = output.target
            if work.contain:  # planned inside; still inside now (symlinks)?
                contained(target, target.parent)
            write(output.scene, target, format=output.format, **output.options)
            written.append(target)
            if output.verify:
                verify_written(output.scene, target, output.format, output.lost)
            spent[output.number] = time.perf_counter() - begun
    except BaseException:
        for path in written:
            path.unlink(missing_ok=True)
        raise
    return spent


# ------------------------------------------------------------------------------- steps
Applied = tuple[Scene, list[str]]


Branches = list[tuple[str, Scene]]
"""The scenes a step works on, each with its half (``""`` until a clip keeps both sides)."""


def _step(body: StepOptions, branches: Branches, work: _Work) -> tuple[Branches, list[str]]:
    """One step on every half of the scene; a clip keeping both splits each half in two."""
    result: Branches = []
    notes: list[str] = []
    for half, scene in branches:
        if isinstance(body, ClipStep) and body.keep == "both":
            for side, part in _clip_both(body, scene):
                result.append((f"{half}-{side}" if half else side, part))
            continue
        applied, said = _APPLY.get(type(body), _operation)(body, scene, work)
        result.append((half, applied))
        named = half and not isinstance(body, OutputStep)  # a write's notes name its file
        notes.extend(f"{half}: {note}" if named else note for note in said)
    return result, notes


def _clip_both(step: ClipStep, scene: Scene) -> list[tuple[str, Scene]]:
    from geobrep.ops.clipping import clip

    negative, positive = clip(scene, step.plane, "both", **_cut_keywords(step))
    return [
        (side, part if isinstance(part, Scene) else _empty(scene))
        for side, part in (("negative", negative), ("positive", positive))
    ]


def _read(step: ReadStep, scene: Scene, work: _Work) -> Applied:
    options: dict[str, Any] = dict(step.options)  # may hold `repair`, checked by read
    return read(work.source, format=step.format, **options), []


def _reproject(step: ReprojectStep, scene: Scene, work: _Work) -> Applied:
    moved = scene.to_crs(step.to, source=step.source)
    return moved, [f"reprojected to {moved.crs.label if moved.crs else step.to}"]


def _cut_keywords(step: ClipStep | ClipBoxStep | SectionStep) -> dict[str, Any]:
    return {"tolerance": step.tolerance, "options": step.options, "clippers": step.clippers}


def _empty(scene: Scene) -> Scene:
    return Scene(crs=scene.crs, name=scene.name, metadata=scene.metadata)


def _clip(step: ClipStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.clipping import clip

    result = clip(scene, step.plane, step.keep, **_cut_keywords(step))
    return (result if isinstance(result, Scene) else _empty(scene)), []


def _clip_box(step: ClipBoxStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.clipping import clip_box

    region: Any = step.bounds if step.bounds is not None else step.planes
    result = clip_box(scene, region, **_cut_keywords(step))
    return (result if isinstance(result, Scene) else _empty(scene)), []


def _section(step: SectionStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.clipping import section

    result = section(scene, step.plane, **_cut_keywords(step))
    return (result if isinstance(result, Scene) else _empty(scene)), []


def _fit(step: FitStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.batch.operations import fit_inputs, fit_markers
    from geobrep.ops.fitting import fit

    points = fit_inputs(scene, step.points)
    markers = fit_markers(step, work.folder)
    surfaces: list[Entity] = []
    notes: list[str] = []
    for entity in points:
        options: dict[str, Any] = dict(step.options)
        result = fit(entity, method=step.method, **markers, **options)
        label = entity.name or entity.label
        report = result.report
        if report is None:
            notes.append(f"{label}: fitted with {step.method} (no accuracy report)")
        else:
            verdict = {True: "meets ε", False: "does not meet ε", None: "no ε"}[report.passed]
            notes.append(
                f"{label}: {step.method} σ = {report.sigma:.4g}, max |d| = "
                f"{report.max_abs:.4g}, n = {report.n} ({verdict})"
            )
            if "markers" in report.subsets:
                found = report.subsets["markers"]
                notes.append(
                    f"{label}: {found.n} well marker(s), σ = {found.sigma:.4g}, max |d| = "
                    f"{found.max_abs:.4g}"
                )
            if step.check_epsilon and report.passed is False:
                raise OptionsError(
                    f"the {step.method} fit of {label!r} does not meet ε = {report.epsilon:g} "
                    f"(σ = {report.sigma:.4g})"
                )
        surface = result.surface.model_copy(update={"id": None})
        if isinstance(surface, NurbsSurface):
            work.fits.append((surface, result, step))
        surfaces.append(surface)
    if step.keep_input:
        return scene.with_entities(*surfaces), notes
    return Scene(entities=surfaces, crs=scene.crs, name=scene.name), notes


def _build_blocks(step: BuildBlocksStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.building import build_blocks

    built = build_blocks(scene, step.builder, **step.options)
    return built, [f"{len(built.blocks)} blocks, {len(built.patches)} patches"]


def _build(step: BuildBlocksStep, scene: Scene, work: _Work) -> Applied:
    spec = work.registries.builders.get(step.builder)
    validated = spec.validate_options(step.options)
    result = spec.function(scene, validated)
    if not isinstance(result, Scene):
        raise GeobrepError(f"{spec.label} returned {type(result).__name__}, not a Scene")
    return result, []


def _voxelize(step: VoxelizeStep, scene: Scene, work: _Work) -> Applied:
    spec = work.registries.voxelizers.get("voxelize")
    octree = spec.function(scene, spec.validate_options(step.builder_options()))
    if not isinstance(octree, LinearOctree):
        raise GeobrepError(f"{spec.label} returned {type(octree).__name__}, not a LinearOctree")
    result = scene.with_entities(octree)
    return result, [f"octree: {octree.n_leaves} leaves, depth {octree.depth}"]


def _check(step: CheckStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.inspection import inspect

    report = inspect(scene, step.checks, step.tolerance)
    found = {name: n for name, n in report.counts().items() if n}
    text = ", ".join(f"{name} {n}" for name, n in found.items())
    if not found:
        return scene, [f"check: clean ({len(report.sections)} checks)"]
    if step.on_defects == "fail":
        raise TopologyError(f"check found {report.n_defects} defect(s): {text}")
    if step.on_defects == "warn":
        warnings.warn(f"check found {report.n_defects} defect(s): {text}", stacklevel=2)
    return scene, [f"check: {report.n_defects} defect(s): {text}"]


def _repair(step: RepairStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.ops.repairing import repair

    repaired, report = repair(scene, step.actions, step.tolerance)
    done = ", ".join(f"{a.action} {a.count}" for a in report.actions if a.count)
    return repaired, [f"repair: {done or 'nothing to mend'}"]


def _map_products(step: MapProductsStep, scene: Scene, work: _Work) -> Applied:
    from geobrep.batch.operations import map_scene_products

    products = map_scene_products(scene, step)
    layers = Counter(str(e.metadata.get("layer", "?")) for e in products.entities)
    return products, [", ".join(f"{layer} {n}" for layer, n in layers.items()) or "no products"]


def _operation(step: OperationStep, scene: Scene, work: _Work) -> Applied:
    spec = work.registries.operations.for_step(step.operation)
    if spec is None:  # checked before the run: the plugin went away meanwhile
        raise OptionsError(f"no operation has the step kind {step.operation!r}")
    result = spec.function(scene, spec.validate_options(step.options))
    if not isinstance(result, Scene):
        raise GeobrepError(f"{spec.label} returned {type(result).__name__}, not a Scene")
    return result, []


def _write(step: OutputStep, scene: Scene, work: _Work) -> Applied:
    target = work.targets[len(work.pending)]
    if scene.holds_nothing and not step.allow_empty:  # no geometry, no stratigraphic column
        raise GeobrepError(
            f"{target.name}: the result holds nothing to write (a clip or section that misses "
            "the model?); give the write step allow_empty: true (geobrep run --allow-empty) to "
            "write it anyway"
        )
    spec = work.registries.formats.choose_writer(target, step.writer_format())
    caps = spec.capabilities
    held = caps.entity_types
    meshes: list[str] = []
    written = scene
    if step.tessellates() and held and "NurbsSurface" not in held and "Surface" in held:
        written, meshes = _tessellated(scene, work, target)
    lost = tuple(file_losses(written, spec, target))
    losses = [f"{target.name}: {loss}" for loss in lost]
    work.lost.extend(losses)
    work.pending.append(
        _Output(
            number=work.number,
            kind=step.kind,
            target=target,
            scene=without_read_losses(written),  # they describe the source, not the file
            format=spec.name,
            options=step.writer_options(),
            verify=step.verifies(),
            lost=lost,
        )
    )
    return written, [*meshes, *(losses or [f"{target.name}: nothing lost"])]


def _tessellated(scene: Scene, work: _Work, target: Path) -> tuple[Scene, list[str]]:
    """The scene with its NURBS surfaces as meshes; a fitted surface's mesh is refined against
    its points (see :meth:`geobrep.ops.fitting.FitResult.tessellated`) and its accuracy noted."""
    if not scene.nurbs_surfaces:
        return scene, []
    entities: list[Entity] = []
    notes: list[str] = []
    for entity in scene.entities:
        if isinstance(entity, NurbsSurface):
            fitted = _fitted(entity, work)
            if fitted is None:
                tolerance = 1e-3 * float(entity.bounds.diagonal) if entity.bounds else None
                mesh = entity.tessellate(tolerance=tolerance)
            else:
                mesh, note = _fitted_mesh(entity, *fitted, target)
                notes.append(note)
            entity = mesh.model_copy(update={"id": entity.id})
        entities.append(entity)
    return scene.replace(entities=tuple(entities)), notes


def _fitted(surface: NurbsSurface, work: _Work) -> tuple[FitResult, FitStep] | None:
    """The fit that made ``surface``, when no step changed its geometry since."""
    for fitted, result, step in work.fits:
        if fitted is surface or (
            fitted.control_points.shape == surface.control_points.shape
            and np.array_equal(fitted.control_points, surface.control_points)
            and np.array_equal(fitted.knots_u, surface.knots_u)
            and np.array_equal(fitted.knots_v, surface.knots_v)
            and np.array_equal(fitted.weights, surface.weights)
        ):
            return result, step
    return None


def _fitted_mesh(
    surface: NurbsSurface, result: FitResult, step: FitStep, target: Path
) -> tuple[Surface, str]:
    written = result.tessellated(max_triangles=step.max_triangles)
    mesh = written.written
    accuracy = written.report.written if written.report is not None else None
    assert mesh is not None
    label = surface.name or surface.label
    if accuracy is None or written.report is None:
        return mesh, f"{target.name}: {label!r} written as a mesh of {mesh.n_vertices} vertices"
    verdict = {True: "meets ε", False: "does not meet ε", None: "no ε"}[accuracy.passed]
    agreement = "" if accuracy.agrees else ", not within 2 % of the surface's at max_triangles"
    note = (
        f"{target.name}: {label!r} written as a mesh of {accuracy.n_vertices} vertices: σ = "
        f"{accuracy.sigma:.4g}, max |d| = {accuracy.max_abs:.4g} ({verdict}{agreement}; the "
        f"surface: σ = {written.report.sigma:.4g}, max |d| = {written.report.max_abs:.4g})"
    )
    if step.check_epsilon and accuracy.passed is False:
        raise OptionsError(
            f"the mesh of the {step.method} fit {label!r} written to {target.name} does not meet "
            f"ε = {accuracy.epsilon:g} (σ = {accuracy.sigma:.4g}; the surface's σ = "
            f"{written.report.sigma:.4g}); raise max_triangles ({step.max_triangles}) for a "
            "finer mesh"
        )
    return mesh, note


_APPLY: dict[type[StepOptions], Callable[[Any, Scene, _Work], Applied]] = {
    ReadStep: _read,
    ReprojectStep: _reproject,
    ClipStep: _clip,
    ClipBoxStep: _clip_box,
    SectionStep: _section,
    FitStep: _fit,
    BuildBlocksStep: _build_blocks,
    BuildStep: _build,
    VoxelizeStep: _voxelize,
    CheckStep: _check,
    RepairStep: _repair,
    MapProductsStep: _map_products,
    WriteStep: _write,
    ConvertStep: _write,
    RenderStep: _write,
    ViewStep: _write,
}
