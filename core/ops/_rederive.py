"""Re-derive patches and blocks where repairs changed a surface's connectivity.

Welding vertices (two patches' borders becoming one edge chain) or splitting edges at
T-junctions changes which faces touch which; the patches a file listed may then no longer be
those the geometry gives. :func:`rederive_patches` rebuilds the model with the block builder
(:func:`geobrep.build_blocks`) and writes its patch labels onto the repaired surfaces (their
faces, vertices and properties untouched), its corners, arcs and patches into the topology and
its blocks as the blocks — each new patch keeping the name, metadata and (first) id of the patch
most of its faces had, each block matching an old one (the same signed patch set) keeping that
block's id, name, kind, metadata and properties.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import GeobrepError
from geobrep.geometry import mesh
from geobrep.model.entities import Block, Entity, Surface
from geobrep.model.entities.block import PatchSide
from geobrep.model.scene import Scene
from geobrep.model.topology import Patch, Topology

__all__ = ["connectivity", "rederive_patches"]

IntArray = NDArray[np.int64]
Key = tuple[int, int]  # (surface id, patch label)


def connectivity(surface: Surface) -> tuple[int, int]:
    """What repairs can change of a surface's connectivity: its edges and its border edges."""
    triangles, _ = mesh.triangulate(surface.faces)
    if triangles.shape[0] == 0:
        return 0, 0
    edges = mesh.edge_face_incidence(triangles)[0]
    return int(edges.shape[0]), int(mesh.boundary_edges(triangles).shape[0])


def _face_labels(surface: Surface, built: Surface, tol: float) -> IntArray | None:
    """The built patch label of each face of ``surface`` (matched by triangle centroids)."""
    from scipy.spatial import cKDTree

    mine, source = mesh.triangulate(surface.faces)
    theirs = np.asarray(built.faces, dtype=np.int64)
    centre = surface.vertices.mean(axis=0)
    tree = cKDTree(built.vertices[theirs].mean(axis=1) - centre)
    distance, nearest = tree.query(surface.vertices[mine].mean(axis=1) - centre)
    if distance.size and float(distance.max()) > 2.0 * tol + 1e-12 * (1.0 + np.abs(centre).max()):
        return None
    built_labels = np.asarray(built.patch_labels, dtype=np.int64)[nearest]
    labels = np.full(surface.n_faces, -1, dtype=np.int64)
    labels[source[::-1]] = built_labels[::-1]  # a face takes its first triangle's label
    return labels


def _majority(old: IntArray, new: IntArray) -> dict[int, int]:
    """For each new label, the old label most of its faces had."""
    pairs = Counter(zip(new.tolist(), old.tolist(), strict=True))
    best: dict[int, tuple[int, int]] = {}
    for (n, o), count in pairs.items():
        if n not in best or count > best[n][1]:
            best[n] = (o, count)
    return {n: o for n, (o, _) in best.items()}


def rederive_patches(scene: Scene, changed: set[int], tol: float) -> tuple[Scene, list[str]]:
    """``scene`` with patches, topology and blocks re-derived by the builder when surfaces
    ``changed`` (ids) have a topology to re-derive; the notes say what was done or why not."""
    if not changed or not scene.topology.patches:
        return scene, []
    from geobrep.ops.building import build_blocks

    try:
        built = build_blocks(Scene(entities=scene.surfaces, crs=scene.crs), tolerance=tol or None)
    except GeobrepError as exc:
        return scene, [f"patches not re-derived (the builder failed: {exc})"]
    rebuilt = {int(s.id or 0): s for s in built.surfaces}
    labels: dict[int, IntArray] = {}
    for surface in scene.surfaces:
        found = rebuilt.get(int(surface.id or 0))
        mapped = None if found is None else _face_labels(surface, found, tol)
        if mapped is None:
            return scene, [f"patches not re-derived ({surface.name!r}: faces not all rebuilt)"]
        labels[int(surface.id or 0)] = mapped
    return _relabelled(scene, built, labels, changed)


def _relabelled(
    scene: Scene, built: Scene, labels: dict[int, IntArray], changed: set[int]
) -> tuple[Scene, list[str]]:
    old_patches = {(p.surface, p.label): p for p in scene.topology.patches}
    origin: dict[Key, Key] = {}  # new (surface, label) -> the old one most of its faces had
    forward: dict[Key, Key] = {}  # old (surface, label) -> the new one most of its faces have
    surfaces: dict[int, Surface] = {}
    notes = []
    for surface in scene.surfaces:
        sid = int(surface.id or 0)
        old = (
            np.zeros(surface.n_faces, np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, np.int64)
        )
        majority = _majority(old, labels[sid])
        origin.update({(sid, n): (sid, o) for n, o in majority.items()})
        forward.update({(sid, o): (sid, n) for o, n in _majority(labels[sid], old).items()})
        seen: Counter[int] = Counter()
        names = []
        for n in range(len(majority)):
            seen[majority[n]] += 1
            name = surface.patch_name(majority[n])
            names.append(name if seen[majority[n]] == 1 else f"{name}:{seen[majority[n]]}")
        surfaces[sid] = surface.replace(patch_labels=labels[sid], patch_names=tuple(names))
        if sid in changed and len(majority) != surface.n_patches:
            notes.append(
                f"{surface.name or sid!r}: {surface.n_patches} patch(es) -> {len(majority)}"
            )
    patch_ids = _patch_ids(built.topology.patches, origin, old_patches)
    block_ids, blocks = _blocks(scene, built, origin, forward, patch_ids)
    topology = _topology(built.topology, origin, old_patches, patch_ids, block_ids)
    by_id = {int(b.id or 0): b for b in blocks}
    entities: list[Entity] = []
    for e in scene.entities:  # kept blocks where they were, new ones at the end
        if isinstance(e, Block):
            entities += [by_id.pop(int(e.id or 0))] if int(e.id or 0) in by_id else []
        else:
            entities.append(surfaces.get(int(e.id or 0), e) if isinstance(e, Surface) else e)
    entities += list(by_id.values())
    notes.append(f"topology re-derived: {len(topology.patches)} patches, {len(blocks)} blocks")
    return scene.replace(entities=entities, topology=topology), notes


def _patch_ids(
    patches: tuple[Patch, ...], origin: dict[Key, Key], old: dict[Key, Patch]
) -> dict[int, int]:
    """Built patch id -> kept id: the old patch's for the first new patch from it, else new."""
    taken: set[int] = set()
    fresh = max([p.id for p in old.values()] + [p.id for p in patches] + [-1]) + 1
    ids = {}
    for patch in patches:
        before = old.get(origin.get((patch.surface, patch.label), (-1, -1)))
        if before is not None and before.id not in taken:
            ids[patch.id] = before.id
            taken.add(before.id)
        else:
            ids[patch.id], fresh = fresh, fresh + 1
    return ids


def _blocks(
    scene: Scene,
    built: Scene,
    origin: dict[Key, Key],
    forward: dict[Key, Key],
    patch_ids: dict[int, int],
) -> tuple[dict[int, int], list[Block]]:
    """The built blocks, each matching an old one keeping it: the same (signed, else unsigned)
    set of patches, counted in old patches (``origin``) or in new ones (``forward``)."""
    old_key = {p.id: (p.surface, p.label) for p in scene.topology.patches}
    new_key = {p.id: origin.get((p.surface, p.label), (-1, p.id)) for p in built.topology.patches}
    built_key = {p.id: (p.surface, p.label) for p in built.topology.patches}
    old_sets: dict[tuple[str, frozenset[object]], Block] = {}
    for b in scene.of_type(Block):  # its patches, as they were and as they became (merged)
        for tag, key in (
            ("old", old_key),
            ("new", {k: forward.get(v, v) for k, v in old_key.items()}),
        ):
            old_sets.setdefault((tag, frozenset((key[s.patch], s.side) for s in b.sides)), b)
            old_sets.setdefault((tag, frozenset(key[s.patch] for s in b.sides)), b)  # a side
    used = {int(e.id or 0) for e in scene.entities}
    fresh = max(used | {int(e.id or 0) for e in built.entities} | {-1}) + 1
    block_ids: dict[int, int] = {}
    blocks = []
    for block in built.of_type(Block):
        sides = tuple(PatchSide(patch_ids[s.patch], s.side) for s in block.sides)
        match = None
        for tag, key in (("old", new_key), ("new", built_key)):
            for wanted in (
                frozenset((key[s.patch], s.side) for s in block.sides),
                frozenset(key[s.patch] for s in block.sides),
            ):
                match = match or old_sets.get((tag, wanted))
        if match is not None:
            kept = match.replace(sides=sides)
        else:
            kept, fresh = block.replace(id=fresh, sides=sides), fresh + 1
        block_ids[int(block.id or 0)] = int(kept.id or 0)
        blocks.append(kept)
    return block_ids, blocks


def _topology(
    topology: Topology,
    origin: dict[Key, Key],
    old: dict[Key, Patch],
    patch_ids: dict[int, int],
    block_ids: dict[int, int],
) -> Topology:
    def block(b: int | None) -> int | None:
        return None if b is None else block_ids.get(b, b)

    patches = []
    for patch in topology.patches:
        before = old.get(origin.get((patch.surface, patch.label), (-1, -1)))
        update: dict[str, object] = {
            "id": patch_ids[patch.id],
            "positive_block": block(patch.positive_block),
            "negative_block": block(patch.negative_block),
        }
        if before is not None:
            update |= {"name": before.name, "metadata": before.metadata}
        patches.append(patch.model_copy(update=update))
    arcs = tuple(
        a.model_copy(update={"patches": tuple(patch_ids[p] for p in a.patches)})
        for a in topology.arcs
    )
    return Topology(corners=topology.corners, arcs=arcs, patches=tuple(patches))
