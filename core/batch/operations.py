"""geobrep's own operations, declared like a plugin's, and the registry of all of them.

Each built-in operation is an :class:`~geobrep.host.operations.OperationSpec` whose options
model is its pipeline step (:mod:`geobrep.batch.pipeline`) and whose function is the public
function of a Scene (:func:`geobrep.clip`, :func:`geobrep.voxelize`, ...). :func:`operations`
is every operation: these first, then the ones plugins registered
(``geobrep_register_operations``); a plugin's operation may not take a built-in name.

>>> [spec.name for spec in builtin_operations()][:3]
['reproject', 'clip', 'clip_box']
"""

from __future__ import annotations

import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from geobrep.batch.catalog import SUMMARIES
from geobrep.batch.pipeline import (
    BuildBlocksStep,
    BuildStep,
    CheckStep,
    ClipBoxStep,
    ClipStep,
    ConvertStep,
    FitStep,
    MapProductsStep,
    RenderStep,
    RepairStep,
    ReprojectStep,
    SectionStep,
    ViewStep,
    VoxelizeStep,
)
from geobrep.errors import EntityNotFoundError, FileAccessError, FormatError, OptionsError
from geobrep.host.operations import OperationRegistry, OperationSpec, options_table
from geobrep.model.entities import Entity, PointSet, PolyLine, Well
from geobrep.model.scene import Scene

__all__ = [
    "as_written",
    "builtin_operations",
    "docs_tables",
    "fit_inputs",
    "fit_markers",
    "fit_points",
    "map_scene_products",
    "operations",
    "read_wells",
    "update_docs",
]


def _scene(result: Any, scene: Scene) -> Scene:
    """A clip that left nothing is an empty scene with the input's CRS and name."""
    if isinstance(result, Scene):
        return result
    return Scene(crs=scene.crs, name=scene.name, metadata=scene.metadata)


def _cut(step: ClipStep | ClipBoxStep | SectionStep) -> dict[str, Any]:
    return {"tolerance": step.tolerance, "options": step.options, "clippers": step.clippers}


def _reproject(scene: Scene, step: ReprojectStep) -> Scene:
    return scene.to_crs(step.to, source=step.source)


def _clip(scene: Scene, step: ClipStep) -> Scene:
    from geobrep.ops.clipping import clip

    if step.keep == "both":  # two scenes: a pipeline carries both, geobrep.clip returns both
        raise OptionsError(
            "keep 'both' gives two scenes: call geobrep.clip(scene, plane, keep='both') or use "
            "a pipeline (each half goes on through the following steps)"
        )

    return _scene(clip(scene, step.plane, step.keep, **_cut(step)), scene)


def _clip_box(scene: Scene, step: ClipBoxStep) -> Scene:
    from geobrep.ops.clipping import clip_box

    region: Any = step.bounds if step.bounds is not None else step.planes
    return _scene(clip_box(scene, region, **_cut(step)), scene)


def _section(scene: Scene, step: SectionStep) -> Scene:
    from geobrep.ops.clipping import section

    return _scene(section(scene, step.plane, **_cut(step)), scene)


def fit_inputs(scene: Scene, names: Sequence[str] | None) -> list[PointSet | PolyLine]:
    """What a fit step fits: the PointSets and PolyLines ``names`` names, else every PointSet."""
    if names is None:
        points: list[PointSet | PolyLine] = list(scene.point_sets)
        if not points:
            raise EntityNotFoundError("the scene holds no PointSet to fit")
        return points
    points = []
    for name in names:
        found = [e for e in scene.find(name) if isinstance(e, PointSet | PolyLine)]
        if not found:
            raise EntityNotFoundError(f"no PointSet or PolyLine named {name!r} to fit")
        points.extend(found)
    return points


def read_wells(paths: Sequence[str], folder: Path | None = None) -> list[Well]:
    """The wells of the files ``paths`` (any readable format: GOCAD ``.wl``, deviation tables,
    ``.geobrep``, ...), in order: what a fit's ``markers`` name.

    With ``folder`` (a pipeline's), each path is relative to it and must stay in it: no
    absolute path, no ``..`` part, and the file must resolve (symlinks followed) inside
    ``folder``. Without, paths are taken as given (the command line's).

    Raises:
        FileAccessError: a file is missing, or outside ``folder``.
        FormatError: a file holds no well (or cannot be read).
    """
    from geobrep.batch.pipeline import confinement_problem
    from geobrep.ops.io import read

    wells: list[Well] = []
    for name in paths:
        path = Path(name)
        if folder is not None:
            problem = confinement_problem(str(name))
            if problem:
                raise FileAccessError(f"well file {problem}", path)
            path = folder / path
            inside = folder.resolve()
            if path.exists() and not path.resolve().is_relative_to(inside):
                raise FileAccessError(
                    f"well file resolves to {path.resolve()}, outside the pipeline's folder "
                    f"{folder}; a step reads files in it only",
                    path,
                )
        if not path.is_file():
            raise FileAccessError("no such well file" if not path.exists() else "not a file", path)
        found = read(path).wells
        if not found:
            raise FormatError("the file holds no well (markers need wells)", path)
        wells.extend(found)
    return wells


def fit_markers(step: FitStep, folder: Path | None) -> dict[str, Any]:
    """The keywords of :func:`geobrep.fit` that a fit step's ``markers`` options give (the
    wells read from ``folder``, see :func:`read_wells`); empty without markers."""
    if step.markers is None:
        return {}
    return {
        "markers": read_wells(step.markers, folder),
        "marker_surface": step.marker_surface,
        "marker_weight": step.marker_weight,
    }


def fit_points(scene: Scene, step: FitStep) -> Scene:
    """The surfaces fitted to the scene's PointSets (or the entities ``step.points`` names);
    ``step.markers`` are read relative to, and inside, the working folder."""
    from geobrep.ops.fitting import fit

    points = fit_inputs(scene, step.points)
    options: dict[str, Any] = dict(step.options)
    markers = fit_markers(step, Path.cwd())
    surfaces: list[Entity] = [
        fit(entity, method=step.method, **markers, **options).surface.model_copy(
            update={"id": None}
        )
        for entity in points
    ]
    if step.keep_input:
        return scene.with_entities(*surfaces)
    return Scene(entities=surfaces, crs=scene.crs, name=scene.name)


def _build_blocks(scene: Scene, step: BuildBlocksStep) -> Scene:
    from geobrep.ops.building import build_blocks

    return build_blocks(scene, step.builder, **step.options)


def _voxelize(scene: Scene, step: VoxelizeStep) -> Scene:
    from geobrep.ops.voxelization import voxelize

    return scene.with_entities(voxelize(scene, **step.builder_options()))


def check_scene(scene: Scene, step: CheckStep) -> Scene:
    """``scene`` itself, after inspecting it: defects raise (``fail``), warn, or pass."""
    import warnings

    from geobrep.errors import TopologyError
    from geobrep.ops.inspection import inspect

    report = inspect(scene, step.checks, step.tolerance)
    if report.ok or step.on_defects == "continue":
        return scene
    found = ", ".join(f"{name} {n}" for name, n in report.counts().items() if n)
    message = f"check found {report.n_defects} defect(s): {found}"
    if step.on_defects == "fail":
        raise TopologyError(message)
    warnings.warn(message, stacklevel=2)
    return scene


def _repair(scene: Scene, step: RepairStep) -> Scene:
    from geobrep.ops.repairing import repair

    return repair(scene, step.actions, step.tolerance)[0]


def map_scene_products(scene: Scene, step: MapProductsStep) -> Scene:
    """The map products of ``scene`` (:func:`geobrep.map_products`) the step's options give."""
    from geobrep.geometry import Plane
    from geobrep.gis.map_products import map_products

    return map_products(
        scene,
        top=step.top,
        section_levels=step.section_levels,
        section_planes=[Plane(*plane) for plane in step.section_planes],
        elevation=step.elevation,
        with_section_lines=step.with_section_lines,
        section_coordinates=step.section_coordinates,
    )


def as_written(scene: Scene, step: Any) -> Scene:
    """The scene a step that writes a file writes: ``scene`` without the reader's list of
    what it skipped (that describes the source, not the file written)."""
    from geobrep.host.capabilities import without_read_losses

    return without_read_losses(scene)


def builtin_operations() -> list[OperationSpec]:
    """geobrep's own operations, in the order the documentation presents them."""
    return [
        OperationSpec(
            name="reproject",
            summary=SUMMARIES["reproject"],
            options=ReprojectStep,
            function=_reproject,
            writes="every entity in the target CRS",
        ),
        OperationSpec(
            name="clip",
            summary=SUMMARIES["clip"],
            options=ClipStep,
            function=_clip,
            writes="the side kept; cut blocks closed by caps",
        ),
        OperationSpec(
            name="clip_box",
            summary=SUMMARIES["clip_box"],
            options=ClipBoxStep,
            function=_clip_box,
            command=None,  # `geobrep clip --box`
            writes="the inside of the box",
        ),
        OperationSpec(
            name="section",
            summary=SUMMARIES["section"],
            options=SectionStep,
            function=_section,
            writes="one polygon per cut block, one trace per cut surface",
        ),
        OperationSpec(
            name="fit",
            summary=SUMMARIES["fit"],
            options=FitStep,
            function=fit_points,
            writes="the fitted surfaces (and the input with keep_input)",
        ),
        OperationSpec(
            name="build_blocks",
            summary=SUMMARIES["build_blocks"],
            options=BuildBlocksStep,
            function=_build_blocks,
            command="blocks",
            writes="the surfaces with their blocks, patches, arcs and corners",
        ),
        OperationSpec(
            name="build",
            summary=SUMMARIES["build"],
            options=BuildStep,
            function=_build_blocks,
            command=None,
            writes="what the builder returns",
        ),
        OperationSpec(
            name="voxelize",
            summary=SUMMARIES["voxelize"],
            options=VoxelizeStep,
            function=_voxelize,
            writes="the scene with its linear octree appended",
        ),
        OperationSpec(
            name="check",
            summary=SUMMARIES["check"],
            options=CheckStep,
            function=check_scene,
            writes="the scene unchanged (the defects in the summary)",
        ),
        OperationSpec(
            name="repair",
            summary=SUMMARIES["repair"],
            options=RepairStep,
            function=_repair,
            writes="the repaired scene (properties, ids and names kept)",
        ),
        OperationSpec(
            name="map_products",
            summary=SUMMARIES["map_products"],
            options=MapProductsStep,
            function=map_scene_products,
            command="map",
            writes="the block outlines, top traces and sections (layers), in the model's CRS",
        ),
        OperationSpec(
            name="convert",
            summary=SUMMARIES["convert"],
            description="Convert one file (IN OUT), or many files into a folder "
            "(IN... --to FMT -o DIR). What the target format cannot hold is reported per file.",
            options=ConvertStep,
            function=as_written,
            output="files",
            writes="a file per input in another format (the scene flows on unchanged)",
        ),
        OperationSpec(
            name="render",
            summary=SUMMARIES["render"],
            description="Render a model to a PNG file without a display.",
            options=RenderStep,
            function=as_written,
            output="files",
            writes="a PNG picture of the scene (the scene flows on unchanged)",
        ),
        OperationSpec(
            name="view",
            summary=SUMMARIES["view"],
            description="Write MODEL as a self-contained HTML page (3D view, no server needed).",
            options=ViewStep,
            function=as_written,
            output="files",
            writes="an HTML page of the scene (the scene flows on unchanged)",
        ),
    ]


def operations() -> OperationRegistry:
    """Every operation: geobrep's own, then those of the loaded plugins.

    >>> spec = operations().get("voxelize")
    >>> spec.command_name, spec.step_kind
    ('voxelize', 'voxelize')
    """
    from geobrep.host import registries

    registry = OperationRegistry()
    for spec in builtin_operations():
        registry.add(spec.model_copy(update={"plugin": "geobrep", "builtin": True}))
    for spec in registries().operations:
        taken = spec.name in registry or (
            spec.step_kind is not None and registry.for_step(spec.step_kind) is not None
        )
        if not taken:  # a plugin cannot replace a built-in operation
            registry.add(spec)
    return registry


_TABLE = re.compile(r"(<!-- options: (\w+) -->\n).*?(<!-- end options -->)", re.S)


def docs_tables() -> dict[str, str]:
    """The option table of every built-in operation's step, by step kind (generated)."""
    return {
        str(spec.step_kind): options_table(spec.options, spec.command_name)
        for spec in builtin_operations()
    }


def update_docs(text: str) -> str:
    """``text`` with each ``<!-- options: KIND -->`` ... ``<!-- end options -->`` section
    holding the generated table of that step (``make docs-tables`` rewrites the pages)."""
    tables = docs_tables()

    def table(match: re.Match[str]) -> str:
        kind = match.group(2)
        if kind not in tables:
            raise KeyError(f"no operation has the step kind {kind!r}")
        return f"{match.group(1)}{tables[kind]}\n{match.group(3)}"

    return _TABLE.sub(table, text)


if __name__ == "__main__":  # pragma: no cover - `make docs-tables`
    for name in sys.argv[1:]:
        page = Path(name)
        page.write_text(update_docs(page.read_text(encoding="utf-8")), encoding="utf-8")
