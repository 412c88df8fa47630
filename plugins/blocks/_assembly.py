"""Write the built topology into a new scene: patch-labelled surfaces, corners, arcs, patches,
blocks with their signed patch lists and attributes, and the universe.

Each surface keeps its id, name, kind, metadata and properties; its faces become triangles (quads
are split, their face properties repeated), dangling and collapsed faces are dropped, vertices
merged with another surface take that vertex's coordinates, and ``patch_labels`` /
``patch_names`` number its patches. Vertex order is kept where vertices survive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Arc, Block, Corner, Entity, Group, Patch, PatchSide, Scene, Surface, Topology
from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.plugins import UNIVERSE_KIND
from geobrep.plugins.blocks._arcs import ArcChains
from geobrep.plugins.blocks._measures import PatchMeasures
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._radial_sort import SortedArcs
from geobrep.plugins.blocks._soup import Soup
from geobrep.plugins.blocks._units import block_attributes
from geobrep.plugins.blocks._universe import Bodies

__all__ = ["Assembly", "assemble"]


def _frozen(array: NDArray[np.float64]) -> NDArray[np.float64]:
    """``array`` (a copy this module made) made read-only, as the models keep their arrays."""
    array.flags.writeable = False
    return array


@dataclass(frozen=True)
class Assembly:
    scene: Scene
    removed_surfaces: list[str]
    internal_patches: list[int]
    #: Soup vertex of every vertex of each rebuilt surface, by surface id.
    vertex_ids: dict[int, IntArray]


@dataclass(frozen=True)
class _Scratch:
    """Arrays over the soup's vertices shared by the rebuilt surfaces: each surface writes only
    at its own vertices (before reading them), so none is cleared or allocated per surface."""

    first: IntArray  # lowest original vertex of each merged vertex
    rank: IntArray  # rebuilt vertex of each merged vertex
    used: BoolArray  # used by the surface's triangles (cleared after each surface)

    @classmethod
    def over(cls, n_vertices: int) -> _Scratch:
        return cls(
            np.empty(n_vertices, dtype=np.int64),
            np.empty(n_vertices, dtype=np.int64),
            np.zeros(n_vertices, dtype=np.bool_),
        )


def _rebuilt_surface(
    soup: Soup, split: PatchSplit, index: int, scratch: _Scratch
) -> tuple[Surface, IntArray] | None:
    surface = soup.surfaces[index]
    # A surface's triangles are contiguous in the soup, surfaces in order.
    start, stop = np.searchsorted(soup.triangle_surface, [index, index + 1]).tolist()
    if start == stop:
        return None
    rows = slice(start, stop)
    merged = soup.triangles[rows]
    vertex_map = soup.vertex_maps[index]
    # The first original vertex of each merged vertex its triangles use stands for it, in
    # their order: the originals that are first of theirs and used, ascending.
    count = vertex_map.shape[0]
    original = np.arange(count, dtype=np.int64)
    scratch.first[vertex_map] = count
    np.minimum.at(scratch.first, vertex_map, original)
    corners = merged.reshape(-1)
    scratch.used[corners] = True
    kept = np.flatnonzero((scratch.first[vertex_map] == original) & scratch.used[vertex_map])
    scratch.used[vertex_map] = False
    ids = vertex_map[kept]
    scratch.rank[ids] = np.arange(kept.shape[0], dtype=np.int64)
    labels = split.patch_label[split.triangle_patch[rows]]
    n_labels = int(labels.max()) + 1
    name = surface.name or f"surface {surface.id}"
    rebuilt = Surface(
        id=surface.id,
        name=surface.name,
        kind=surface.kind,
        metadata=surface.metadata,
        vertices=np.take(soup.vertices, ids, axis=0),
        faces=scratch.rank[merged],
        patch_labels=labels,
        patch_names=tuple(f"{name}:{k}" for k in range(n_labels)),
        point_data=surface.point_data.take(kept),
        cell_data=surface.cell_data.take(soup.triangle_face[rows]),
    )
    return rebuilt, ids


def assemble(
    scene: Scene,
    soup: Soup,
    split: PatchSplit,
    chains: ArcChains,
    arcs: SortedArcs,
    bodies: Bodies,
    measures: PatchMeasures,
) -> Assembly:
    """The scene with the built topology (blocks and topology of ``scene`` are replaced)."""
    built_ids = {int(s.id or 0) for s in soup.surfaces}
    scratch = _Scratch.over(soup.vertices.shape[0])
    results = {
        int(s.id or 0): _rebuilt_surface(soup, split, i, scratch)
        for i, s in enumerate(soup.surfaces)
    }
    surfaces = {key: None if found is None else found[0] for key, found in results.items()}
    vertex_ids = {key: found[1] for key, found in results.items() if found is not None}
    kept: list[Entity] = []
    for entity in scene.entities:
        if isinstance(entity, Block):
            continue
        if int(entity.id or 0) in built_ids and isinstance(entity, Surface):
            rebuilt = surfaces[int(entity.id or 0)]
            if rebuilt is not None:
                kept.append(rebuilt)
            continue
        kept.append(entity)
    removed = [
        soup.surface_name(i)
        for i, s in enumerate(soup.surfaces)
        if surfaces[int(s.id or 0)] is None
    ]

    # Blocks: real bodies by decreasing centroid height, then the universe.
    real = [b for b in range(bodies.n_bodies) if b != bodies.universe]
    attributes = block_attributes(
        soup, split, measures, bodies.positive, bodies.negative, bodies.volumes, real
    )
    real.sort(key=lambda b: (-attributes[b].centroid[2], attributes[b].centroid[0], b))
    next_id = max((int(e.id or 0) for e in kept), default=-1) + 1
    block_id = {body: next_id + k for k, body in enumerate(real)}
    block_id[bodies.universe] = next_id + len(real)

    sides: dict[int, list[PatchSide]] = {b: [] for b in block_id.values()}
    for patch in range(split.n_patches):
        sides[block_id[int(bodies.positive[patch])]].append(PatchSide(patch, 1))
        sides[block_id[int(bodies.negative[patch])]].append(PatchSide(patch, -1))
    blocks: list[Block] = []
    for k, body in enumerate(real):
        info = attributes[body]
        metadata: dict[str, Any] = {
            "volume": float(bodies.volumes[body]),
            "centroid": list(info.centroid),
            "top_horizons": list(info.tops),
            "base_horizons": list(info.bases),
            "faults": list(info.faults),
        }
        blocks.append(
            Block(
                id=block_id[body],
                name=f"block {k + 1}",
                unit_name=info.unit_name,
                sides=tuple(sides[block_id[body]]),
                metadata=metadata,
            )
        )
    blocks.append(
        Block(
            id=block_id[bodies.universe],
            name="universe",
            kind=UNIVERSE_KIND,
            sides=tuple(sides[block_id[bodies.universe]]),
        )
    )

    topology = _topology(soup, split, chains, arcs, bodies, block_id)
    groups = _groups(scene, {int(e.id or 0) for e in kept}, [int(b.id or 0) for b in blocks])
    internal = [p.id for p in topology.patches if p.is_internal]
    # The parts are validated models (the input's entities, the rebuilt surfaces, the blocks,
    # the topology and the groups): the scene checks ids and references without validating
    # them again.
    built = Scene.from_validated(
        entities=(*kept, *blocks),
        groups=groups,
        crs=scene.crs,
        topology=topology,
        name=scene.name,
        metadata=scene.metadata,
    )
    return Assembly(built, removed, internal, vertex_ids)


def _topology(
    soup: Soup,
    split: PatchSplit,
    chains: ArcChains,
    arcs: SortedArcs,
    bodies: Bodies,
    block_id: dict[int, int],
) -> Topology:
    around = arcs.around
    # Corners, arcs and patches are built from checked data (the soup's finite vertices, arcs
    # of at least one edge between numbered corners, ids and labels counted from 0): what their
    # validation would do is done here. The topology checks its references.
    corners = tuple(
        Corner.model_construct(id=k, point=_frozen(soup.vertices[v]))
        for k, v in enumerate(chains.corners.tolist())
    )
    patch_arcs: list[set[int]] = [set() for _ in range(split.n_patches)]
    for arc, patch in zip(around.arc.tolist(), around.patch.tolist(), strict=True):
        patch_arcs[patch].add(arc)
    arc_list = []
    bounds, offsets = chains.chain_offsets.tolist(), around.offsets.tolist()
    starts, ends, members = (
        chains.arc_start.tolist(),
        chains.arc_end.tolist(),
        around.patch.tolist(),
    )
    for a in range(chains.n_arcs):
        chain = chains.chain_vertices[bounds[a] : bounds[a + 1]]
        arc_list.append(
            Arc.model_construct(
                id=a,
                points=_frozen(soup.vertices[chain]),
                start=starts[a],
                end=ends[a],
                patches=tuple(members[offsets[a] : offsets[a + 1]]),
            )
        )
    counts = split.patch_triangle_counts()
    patches = []
    for patch in range(split.n_patches):
        index = int(split.patch_surface[patch])
        surface = soup.surfaces[index]
        label = int(split.patch_label[patch])
        patches.append(
            Patch.model_construct(
                id=patch,
                surface=int(surface.id or 0),
                label=label,
                name=f"{surface.name or f'surface {surface.id}'}:{label}",
                positive_block=block_id[int(bodies.positive[patch])],
                negative_block=block_id[int(bodies.negative[patch])],
                arcs=tuple(sorted(patch_arcs[patch])),
                metadata={"triangles": int(counts[patch])},
            )
        )
    return Topology(corners=corners, arcs=tuple(arc_list), patches=tuple(patches))


def _groups(scene: Scene, entity_ids: set[int], block_ids: list[int]) -> tuple[Group, ...]:
    """The scene's groups without members that are gone, plus a ``blocks`` group."""

    def prune(group: Group) -> Group:
        return group.model_copy(
            update={
                "members": tuple(m for m in group.members if m in entity_ids),
                "children": tuple(prune(c) for c in group.children),
            }
        )

    kept = tuple(prune(g) for g in scene.groups if g.name != "blocks")
    return (*kept, Group(name="blocks", kind="blocks", members=tuple(block_ids)))
