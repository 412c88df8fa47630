"""The ``blocks`` builder: conformal surfaces in, closed oriented blocks with their topology out.

Stages (each timed in the report): merge the surfaces into a soup of welded triangles
(:mod:`.soup`), split it into patches (:mod:`.patches`) and arcs (:mod:`.arcs`), look for
non-conformal input (:mod:`.conformity`), deal with free borders (:mod:`.dangling`), sort the
patches around every arc from its direction triangles (:mod:`.orientation`,
:mod:`.radial_sort`), traverse to give every patch side a region (:mod:`.traversal`), find the
universe and the dangling patches (:mod:`.universe`) — when some are removed, the stages run
again without them — then write the scene (:mod:`.assembly`) and validate it
(:mod:`.validation`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from geobrep import Scene, Surface
from geobrep.errors import OptionsError, TopologyError
from geobrep.plugins.blocks._arcs import ArcChains, chain_arcs
from geobrep.plugins.blocks._assembly import Assembly, assemble
from geobrep.plugins.blocks._conformity import check_conformity
from geobrep.plugins.blocks._dangling import (
    DanglingPatch,
    describe_dangling,
    free_border_arcs,
    free_border_patches,
)
from geobrep.plugins.blocks._measures import PatchMeasures, measure_patches
from geobrep.plugins.blocks._patches import PatchSplit, split_patches
from geobrep.plugins.blocks._radial_sort import SortedArcs, sort_arcs
from geobrep.plugins.blocks._soup import Soup, build_soup
from geobrep.plugins.blocks._traversal import traverse
from geobrep.plugins.blocks._universe import Bodies, find_universe
from geobrep.plugins.blocks._validation import Validation, validate_scene
from geobrep.plugins.blocks.options import BlockBuilderOptions
from geobrep.plugins.blocks.report import REPORT_KEY, BlockReport, DanglingEntry

__all__ = ["build_blocks"]


class _Stopwatch:
    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[name] = self.seconds.get(name, 0.0) + time.perf_counter() - start


def _select_surfaces(scene: Scene, wanted: tuple[int | str, ...] | None) -> tuple[Surface, ...]:
    if wanted is None:
        return scene.surfaces
    chosen: list[Surface] = []
    for key in wanted:
        entity = scene[key]
        if not isinstance(entity, Surface):
            raise OptionsError(
                f"builder 'blocks': option 'surfaces': {entity.label} is not a Surface"
            )
        if entity not in chosen:
            chosen.append(entity)
    return tuple(chosen)


def _describe_patch(soup: Soup, split: PatchSplit) -> Callable[[int], str]:
    def describe(patch: int) -> str:
        index = int(split.patch_surface[patch])
        return f"patch {int(split.patch_label[patch])} of {soup.surface_name(index)!r}"

    return describe


def _free_border_error(soup: Soup, split: PatchSplit, chains: ArcChains) -> TopologyError:
    arcs = free_border_arcs(split, chains)
    places = []
    for arc in arcs[:5].tolist():
        chain = chains.chain_vertices[chains.chain_offsets[arc] : chains.chain_offsets[arc + 1]]
        middle = soup.vertices[chain[len(chain) // 2]]
        edge = chains.edge_ids[chains.arc_offsets[arc]]
        patch = int(split.triangle_patch[split.incident_triangles[split.offsets[edge]]])
        places.append(
            f"{_describe_patch(soup, split)(patch)} near "
            f"({middle[0]:.3f}, {middle[1]:.3f}, {middle[2]:.3f})"
        )
    more = f" (and {arcs.size - 5} more)" if arcs.size > 5 else ""
    return TopologyError(
        f"{arcs.size} free border(s) (arcs used by a single patch): " + "; ".join(places) + more
    )


def build_blocks(scene: Scene, options: BlockBuilderOptions) -> Scene:
    """Build patches, arcs, corners, blocks and the universe from the scene's surfaces.

    >>> import geobrep
    >>> model = geobrep.datasets.faulted_layer_cake()
    >>> built = build_blocks(geobrep.Scene(entities=model.surfaces), BlockBuilderOptions())
    >>> len(built.blocks), len(built.patches), built.universe.name
    (6, 31, 'universe')
    """
    watch = _Stopwatch()
    surfaces = _select_surfaces(scene, options.surfaces)
    with watch.stage("soup"):
        soup = build_soup(surfaces, options.tolerance, options.relative_tolerance)
    gap_tolerance = (
        options.gap_tolerance
        if options.gap_tolerance is not None
        else options.relative_gap_tolerance * soup.diagonal
    )
    topology = _closed_topology(soup, options, gap_tolerance, watch)
    with watch.stage("assembly"):
        assembly = assemble(
            scene,
            topology.soup,
            topology.split,
            topology.chains,
            topology.arcs,
            topology.bodies,
            topology.measures,
        )
    validation = None
    if options.validate_blocks:
        with watch.stage("validation"):
            validation = validate_scene(
                assembly.scene,
                topology.soup,
                topology.split,
                topology.measures,
                assembly.vertex_ids,
            )
    report = _report(
        (len(surfaces), soup.n_triangles), gap_tolerance, watch, topology, assembly, validation
    )
    built = assembly.scene
    metadata = {**built.metadata, REPORT_KEY: report.model_dump(mode="json")}
    # Only the metadata changes: the validated parts are not validated again.
    return Scene.from_validated(
        entities=built.entities,
        groups=built.groups,
        crs=built.crs,
        topology=built.topology,
        name=built.name,
        metadata=metadata,
    )


@dataclass(frozen=True)
class _Topology:
    """The last pass over the soup: every stage's result, what was removed, how many passes."""

    soup: Soup
    split: PatchSplit
    chains: ArcChains
    arcs: SortedArcs
    bodies: Bodies
    measures: PatchMeasures
    removed: list[DanglingPatch]
    passes: int


def _closed_topology(
    soup: Soup, options: BlockBuilderOptions, gap_tolerance: float, watch: _Stopwatch
) -> _Topology:
    """Run the stages until no patch dangles (each pass removes the dangling ones)."""
    removed: list[DanglingPatch] = []
    open_border = ""  # the first free borders found, named if nothing closed is left
    passes = 0
    while True:
        passes += 1
        if soup.n_triangles == 0:
            raise _no_closed_block(
                f"every patch was dangling ({len(removed)} removed; the surfaces enclose no "
                "volume)",
                open_border,
            )
        with watch.stage("patches"):
            split = split_patches(soup)
        with watch.stage("arcs"):
            chains = chain_arcs(split, soup.vertices.shape[0], soup.vertices)
        if passes == 1:
            open_border = _first_pass_checks(soup, split, chains, options, gap_tolerance, watch)
        smaller = _without_free_borders(soup, split, chains, options, watch, removed)
        if smaller is None:
            arcs, bodies, measures = _bodies(soup, split, chains, options, watch)
            smaller = _without_dangling(soup, split, bodies, watch, removed)
            if smaller is None:
                if bodies.universe < 0 or bodies.n_bodies < 2:
                    raise _no_closed_block("the surfaces enclose no volume", open_border)
                return _Topology(soup, split, chains, arcs, bodies, measures, removed, passes)
        soup = smaller


def _no_closed_block(reason: str, open_border: str) -> TopologyError:
    where = f": the model is open, {open_border}" if open_border else ""
    return TopologyError(f"no closed block: {reason}{where}")


def _first_pass_checks(
    soup: Soup,
    split: PatchSplit,
    chains: ArcChains,
    options: BlockBuilderOptions,
    gap_tolerance: float,
    watch: _Stopwatch,
) -> str:
    """The free borders of the input in words (or ``""``); non-conformal input raises."""
    open_border = ""
    if free_border_arcs(split, chains).size:
        open_border = str(_free_border_error(soup, split, chains))
    if options.check_conformity:
        with watch.stage("conformity"):
            check_conformity(soup, split, gap_tolerance)
    return open_border


def _without_free_borders(
    soup: Soup,
    split: PatchSplit,
    chains: ArcChains,
    options: BlockBuilderOptions,
    watch: _Stopwatch,
    removed: list[DanglingPatch],
) -> Soup | None:
    """The soup without the patches on free borders (``None``: none to remove), per options."""
    if options.free_borders == "internal":
        return None
    with watch.stage("dangling"):
        free = free_border_patches(split, chains)
        if free.size and options.free_borders == "error":
            raise _free_border_error(soup, split, chains)
        if not free.size:
            return None
        removed += describe_dangling(soup, split, free, "free border")
        return soup.subset(~np.isin(split.triangle_patch, free))


def _bodies(
    soup: Soup,
    split: PatchSplit,
    chains: ArcChains,
    options: BlockBuilderOptions,
    watch: _Stopwatch,
) -> tuple[SortedArcs, Bodies, PatchMeasures]:
    """Patches sorted around the arcs, regions traversed, the universe and the bodies found."""
    with watch.stage("sort"):
        arcs = sort_arcs(
            soup.vertices,
            soup.triangles,
            split,
            chains,
            options.angle_tolerance,
            _describe_patch(soup, split),
        )
    with watch.stage("traversal"):
        regions = traverse(arcs.around, split.n_patches)
    with watch.stage("universe"):
        measures = measure_patches(soup, split)
        bodies = find_universe(soup, split, regions, measures)
    return arcs, bodies, measures


def _without_dangling(
    soup: Soup,
    split: PatchSplit,
    bodies: Bodies,
    watch: _Stopwatch,
    removed: list[DanglingPatch],
) -> Soup | None:
    """The soup without the patches outside the model or bounding no volume (``None``: none)."""
    if not bodies.dangling.size:
        return None
    with watch.stage("dangling"):
        removed += describe_dangling(soup, split, bodies.outside, "outside the model")
        removed += describe_dangling(soup, split, bodies.floating, "bounds no volume")
        return soup.subset(~np.isin(split.triangle_patch, bodies.dangling))


def _report(
    inputs: tuple[int, int],
    gap_tolerance: float,
    watch: _Stopwatch,
    topology: _Topology,
    assembly: Assembly,
    validation: Validation | None,
) -> BlockReport:
    """The builder's report: ``inputs`` are the numbers of input surfaces and triangles."""
    n_surfaces, n_input = inputs
    soup, split, chains, arcs = topology.soup, topology.split, topology.chains, topology.arcs
    built = assembly.scene
    return BlockReport(
        surfaces=n_surfaces,
        triangles=n_input,
        vertices=int(soup.vertices.shape[0]),
        merged_vertices=soup.merged_vertices,
        degenerate_triangles=soup.degenerate_triangles,
        orientation_seams=split.orientation_seams,
        patches=split.n_patches,
        arcs=chains.n_arcs,
        corners=int(chains.corners.shape[0]),
        blocks=len(built.blocks),
        internal_patches=assembly.internal_patches,
        dangling=[DanglingEntry(**vars(entry)) for entry in topology.removed],
        removed_surfaces=assembly.removed_surfaces,
        nested_bodies=topology.bodies.nested_components,
        direction_triangles=arcs.touched_triangles,
        sorted_share=arcs.touched_triangles / max(n_input, 1),
        retried_arcs=arcs.retried_arcs,
        passes=topology.passes,
        tolerance=soup.tolerance,
        tolerance_source=soup.tolerance_source,
        precision=soup.precision.quantum if soup.precision else None,
        precision_source=soup.precision.source if soup.precision else None,
        gap_tolerance=gap_tolerance,
        stage_seconds=watch.seconds,
        validated=validation is not None,
        checks=validation.checks if validation else [],
        universe_closed=validation.universe_closed if validation else None,
        volume_balance=validation.volume_balance if validation else None,
        adjacency=built.block_adjacency(),
    )
