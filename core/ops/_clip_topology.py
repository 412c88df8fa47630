"""Carrying a scene's B-Rep topology through a plane cut (used by :func:`geobrep.clip`).

After the surfaces of a scene are cut, each half keeps:

* the **patches** that still have faces, with their ids, names and blocks. Faces of a patch lying
  in the plane bound only the block on the kept side: they stay in the patch when the other side
  was the universe already, move to a new patch between that block and the universe when it was
  another block, and are dropped when the kept side is the universe;
* the **blocks** with a part on that side, with ids, names, units and metadata; each cut block is
  closed by a **cap** patch (registered by the Block clipper) between it and the universe. The
  caps of a half form one new Surface, ``kind="cap"``, one patch label per block, so neighbouring
  blocks' caps share their edges;
* **corners and arcs** rebuilt from the half's patches by the one rule of :mod:`geobrep.model.arcs`
  (the caps' borders included), and the **groups** without the entities that are gone, plus a
  ``caps`` group.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from geobrep.geometry import Plane, boxes_plane_side, mesh
from geobrep.geometry.arrays import IntArray
from geobrep.model.arcs import build_corners_and_arcs
from geobrep.model.entities import Block, Entity, PatchSide, Surface
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Patch, Topology

if TYPE_CHECKING:
    from geobrep.host.registry import ClipperRegistry
    from geobrep.ops.clipping import ClipContext, Keep, SceneDraft

__all__ = ["carry_topology"]


def carry_topology(
    scene: Scene,
    plane: Plane,
    keep: Keep,
    context: ClipContext,
    clip_block: Callable[[Block], tuple[Block | None, ...]],
    registry: ClipperRegistry,
    choice: Mapping[str, str],
) -> tuple[Scene, ...]:
    """Finish the halves in ``context.drafts``: patches, blocks with caps, arcs, groups."""
    from geobrep.ops.clipping import halves

    wanted = halves(keep)
    universe = scene.universe
    universe_id = None if universe is None else int(universe.id or 0)
    next_patch = max((p.id for p in scene.patches), default=-1) + 1
    for side in wanted:
        draft = context.drafts[side]
        draft.patches, next_patch = _carry_patches(
            scene, plane, draft, context.tolerance, universe_id, next_patch
        )
    results: dict[int, tuple[Block | None, ...]] = {}
    if scene.patches:
        for block in scene.blocks:
            results[int(block.id or 0)] = clip_block(block)
    cap_id = max((int(e.id or 0) for e in scene.entities), default=-1) + 1
    scenes = []
    for position, side in enumerate(wanted):
        draft = context.drafts[side]
        kept: dict[int, Block] = {}
        for ident, parts in results.items():
            part = parts[position]
            if part is not None:
                kept[ident] = part
        scenes.append(
            _assemble(
                scene, plane, side, draft, kept, universe_id, cap_id, next_patch, context, registry
            )
        )
    return tuple(scenes)


# ------------------------------------------------------------------------------- patches
def _carry_patches(
    scene: Scene,
    plane: Plane,
    draft: SceneDraft,
    tolerance: float,
    universe_id: int | None,
    next_patch: int,
) -> tuple[dict[int, Patch], int]:
    """The patches of one half, splitting off faces that lie in the plane (see module doc)."""
    by_surface: dict[int, list[Patch]] = {}
    for patch in scene.patches:
        by_surface.setdefault(patch.surface, []).append(patch)
    patches: dict[int, Patch] = {}
    for surface_id, listed in by_surface.items():
        surface = draft.entities.get(surface_id)
        if not isinstance(surface, Surface):
            continue
        bounds = surface.bounds
        if (
            bounds is None
            or boxes_plane_side(bounds.mins[None, :], bounds.maxs[None, :], plane, tolerance)[0]
        ):  # entirely on one side: kept whole
            patches.update({p.id: p for p in listed})
            continue
        surface, split, next_patch = _split_in_plane(
            surface, listed, plane, draft.side, tolerance, universe_id, next_patch
        )
        draft.entities[surface_id] = surface
        labels = _labels(surface)
        present = np.bincount(labels, minlength=surface.n_patches) > 0
        for patch in listed:
            if patch.label < present.shape[0] and present[patch.label]:
                patches[patch.id] = patch
        patches.update({p.id: p for p in split})
    return patches, next_patch


def _labels(surface: Surface) -> IntArray:
    if surface.patch_labels is None:
        return np.zeros(surface.n_faces, dtype=np.int64)
    return np.asarray(surface.patch_labels, dtype=np.int64)


def _split_in_plane(
    surface: Surface,
    listed: list[Patch],
    plane: Plane,
    side: int,
    tolerance: float,
    universe_id: int | None,
    next_patch: int,
) -> tuple[Surface, list[Patch], int]:
    """Drop or move faces of ``surface`` lying in the plane, per the rule of the module doc."""
    if surface.n_faces == 0:
        return surface, [], next_patch
    on = np.abs(plane.signed_distance(surface.vertices)) <= tolerance
    lying = np.flatnonzero(on[surface.faces].all(axis=1))
    if lying.shape[0] == 0:
        return surface, [], next_patch
    facing = np.sign(mesh.face_normals(surface.vertices, surface.faces[lying]) @ plane.normal)
    labels = _labels(surface).copy()
    names = list(surface.patch_names) or [str(i) for i in range(surface.n_patches)]
    drop = np.zeros(surface.n_faces, dtype=np.bool_)
    split: list[Patch] = []
    by_label = {p.label: p for p in listed}
    for label in np.unique(labels[lying]).tolist():
        patch = by_label.get(int(label))
        if patch is None:
            continue
        for sign in (-1.0, 1.0):
            faces = lying[(labels[lying] == label) & (facing == sign)]
            if faces.shape[0] == 0:
                continue
            # The patch's positive side is where its normal points: +n when sign > 0.
            kept_is_positive = sign == side
            kept = patch.positive_block if kept_is_positive else patch.negative_block
            removed = patch.negative_block if kept_is_positive else patch.positive_block
            if kept is None or kept == universe_id:
                drop[faces] = True
            elif removed is not None and removed != universe_id:
                labels[faces] = len(names)
                names.append(f"{patch.name or names[patch.label]}:on-plane")
                split.append(
                    Patch(
                        id=next_patch,
                        surface=patch.surface,
                        label=len(names) - 1,
                        name=names[-1],
                        positive_block=kept if kept_is_positive else universe_id,
                        negative_block=universe_id if kept_is_positive else kept,
                        metadata={**patch.metadata, "split_from": patch.id},
                    )
                )
                next_patch += 1
    if not drop.any() and not split:
        return surface, [], next_patch
    keep_faces = np.flatnonzero(~drop)
    changed = surface.replace(patch_labels=labels, patch_names=tuple(names))
    return (
        changed.extract_faces(keep_faces, id=surface.id, metadata=surface.metadata),
        split,
        next_patch,
    )


# ------------------------------------------------------------------------------- assembly
def _assemble(
    scene: Scene,
    plane: Plane,
    side: int,
    draft: SceneDraft,
    blocks: dict[int, Block],
    universe_id: int | None,
    cap_id: int,
    next_patch: int,
    context: ClipContext,
    registry: ClipperRegistry,
) -> Scene:
    patches = dict(draft.patches)
    cap_surface, cap_patches = _caps(draft, blocks, cap_id, next_patch, universe_id)
    patches.update({p.id: p for p in cap_patches})
    alive = set(blocks) | ({universe_id} if universe_id is not None else set())
    fixed = {
        pid: p.model_copy(
            update={
                "positive_block": p.positive_block if p.positive_block in alive else None,
                "negative_block": p.negative_block if p.negative_block in alive else None,
            }
        )
        for pid, p in patches.items()
    }
    fixed = {pid: p.model_copy(update={"arcs": ()}) for pid, p in fixed.items()}
    entities: list[Entity] = []
    for entity in scene.entities:
        ident = int(entity.id or 0)
        if isinstance(entity, Block):
            if ident == universe_id:
                entities.append(_with_sides(entity, fixed))
            elif ident in blocks:
                entities.append(_with_sides(blocks[ident], fixed))
        elif ident in draft.entities:
            entities.append(draft.entities[ident])
    if cap_surface is not None:
        entities.append(cap_surface)
    present = {int(e.id or 0) for e in entities}
    groups = tuple(_prune(group, present) for group in scene.groups)
    if cap_surface is not None:
        groups = (*groups, Group(name="caps", kind="caps", members=(cap_id,)))
    half = Scene(
        entities=entities,
        groups=groups,
        crs=scene.crs,
        topology=Topology(patches=tuple(fixed.values())),
        name=scene.name,
        metadata=scene.metadata,
    )
    if not scene.topology.arcs:
        return half
    # Corners and arcs follow the one rule of geobrep.model.arcs, as if the half had been read.
    return half.replace(topology=build_corners_and_arcs(half))


def _with_sides(block: Block, patches: dict[int, Patch]) -> Block:
    ident = int(block.id or 0)
    order = {patch: position for position, (patch, _) in enumerate(block.sides)}
    sides: list[PatchSide] = []
    for patch in patches.values():
        if patch.positive_block == ident:
            sides.append(PatchSide(patch.id, 1))
        if patch.negative_block == ident:
            sides.append(PatchSide(patch.id, -1))
    split_from = {
        p.id: int(p.metadata["split_from"])  # type: ignore[arg-type]
        for p in patches.values()
        if isinstance(p.metadata.get("split_from"), int)
    }

    def rank(side: PatchSide) -> tuple[int, int]:
        source = split_from.get(side.patch, side.patch)
        return (order.get(source, len(order)), side.patch)

    sides.sort(key=rank)
    return block.replace(sides=tuple(sides))


def _prune(group: Group, present: set[int]) -> Group:
    return group.model_copy(
        update={
            "members": tuple(m for m in group.members if m in present),
            "children": tuple(_prune(child, present) for child in group.children),
        }
    )


def _caps(
    draft: SceneDraft,
    blocks: dict[int, Block],
    cap_id: int,
    next_patch: int,
    universe_id: int | None,
) -> tuple[Surface | None, list[Patch]]:
    """One Surface holding every block's cap (shared edges share vertices) and its patches."""
    caps = [(ident, cap) for ident, cap in sorted(draft.caps.items()) if ident in blocks]
    caps = [(ident, cap) for ident, cap in caps if cap.n_faces]
    if not caps:
        return None, []
    vertices = np.concatenate([cap.vertices for _, cap in caps])
    offsets = np.cumsum([0] + [cap.n_vertices for _, cap in caps])
    faces = np.concatenate(
        [
            cap.faces.astype(np.int64) + offset
            for (_, cap), offset in zip(caps, offsets, strict=False)
        ]
    )
    labels = np.repeat(np.arange(len(caps)), [cap.n_faces for _, cap in caps])
    unique, inverse = np.unique(vertices + 0.0, axis=0, return_inverse=True)
    names = tuple(f"cap:{blocks[ident].name or ident}" for ident, _ in caps)
    surface = Surface(
        id=cap_id,
        vertices=unique,
        faces=inverse.reshape(-1)[faces],
        patch_labels=labels,
        patch_names=names,
        name="cap",
        kind="cap",
        metadata={"blocks": [ident for ident, _ in caps]},
    )
    patches = [
        Patch(
            id=next_patch + position,
            surface=cap_id,
            label=position,
            name=names[position],
            negative_block=ident,
            positive_block=universe_id,
        )
        for position, (ident, _) in enumerate(caps)
    ]
    return surface, patches
