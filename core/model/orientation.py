"""Orientation of a model's patches and blocks: made consistent, or an error naming the block.

Field models carry flipped triangles and REGION signs that contradict the geometry. Two repairs
make a scene's blocks true again:

* :func:`orient_patches` — within each patch of a surface, every triangle is turned to agree
  with the patch's reference face (a GOCAD TFACE's key triangle), or, without one, with the
  majority of its connected piece.
* :func:`orient_blocks` — the sides a block lists are checked against its boundary: a side whose
  patch runs against the rest of the shell is reversed (the patch's area decides which way the
  shell runs), and a shell that encloses negative volume is turned inside out. The universe
  (the outside) must enclose negative volume. A block whose shell cannot be oriented (a patch
  that would have to flip in part, a non-orientable shell) or whose volume is zero is a
  :class:`~geobrep.errors.TopologyError` naming it.

Each repair is described in one sentence of the returned list, for the reader to warn with.

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> repaired, notes = orient_blocks(scene)
>>> notes
[]
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from geobrep.errors import TopologyError
from geobrep.geometry import mesh
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.geometry.bbox import column_extremes
from geobrep.geometry.orientation import orientation_flips
from geobrep.model._shells import (
    Shell,
    block_shell,
    open_edges_if_one_way,
    patch_edges,
    patch_edges_of_incidence,
    patch_triangles,
)
from geobrep.model.entities import Block, PatchSide, Surface
from geobrep.model.scene import RELATIVE_MERGE_TOLERANCE, Scene

if TYPE_CHECKING:
    from geobrep.model.arcs import JoinedPatches

__all__ = ["BlockOrientation", "block_orientations", "orient_blocks", "orient_patches"]

#: An open shell's volume decides its orientation when it exceeds this share of area^1.5.
_OPEN_VOLUME_SHARE = 1e-6


def orient_patches(
    surface: Surface, reference_faces: Mapping[int, int | None] | None = None
) -> tuple[Surface, dict[int, int]]:
    """``surface`` with each patch's faces agreeing with its reference face; flips per label.

    ``reference_faces`` maps a patch label to the index (in ``surface.faces``) of the face whose
    winding the patch must follow; a label without one (or a piece of the patch that does not
    hold it) follows the majority of its faces. Returns the surface unchanged when nothing flips.
    """
    faces = surface.faces
    if faces.shape[0] < 2:
        return surface, {}
    labels = (
        np.zeros(faces.shape[0], dtype=np.int64)
        if surface.patch_labels is None
        else np.asarray(surface.patch_labels, dtype=np.int64)
    )
    # One pass over all patches: each patch gets vertices of its own, so no piece crosses two.
    n_vertices = int(faces.max()) + 1
    separate = faces + (labels * n_vertices)[:, None]
    roots = [
        face
        for label, face in (reference_faces or {}).items()
        if face is not None and 0 <= face < faces.shape[0] and labels[face] == label
    ]
    if mesh.is_consistently_oriented(separate):  # the usual case: nothing to turn
        return surface, {}
    result = orientation_flips(separate, roots or None)
    flip = result.flip.copy()
    # Pieces without the reference face follow their majority.
    n_flipped = np.bincount(result.piece, weights=flip, minlength=result.n_pieces)
    n_faces = np.bincount(result.piece, minlength=result.n_pieces)
    invert = n_flipped * 2 > n_faces
    invert[result.piece[np.asarray(roots, dtype=np.int64)]] = False
    flip ^= invert[result.piece]
    flip_all = flip
    counts = np.bincount(labels[flip], minlength=surface.n_patches)
    flipped = {int(label): int(counts[label]) for label in np.flatnonzero(counts)}
    if not flipped:
        return surface, {}
    new_faces = faces.copy()
    new_faces[flip_all] = mesh.flip_faces(faces[flip_all])
    return surface.replace(faces=new_faces), flipped


@dataclass(frozen=True)
class BlockOrientation:
    """What the geometry says about one block's listed sides.

    ``sides`` are the sides that orient its shell outward (``reversed_patches`` lists the patch
    ids whose side changed); ``volume`` is the volume the oriented shell encloses (negative for
    the universe); ``open_edges`` counts shell edges used by one face only.
    """

    block: Block
    sides: tuple[PatchSide, ...]
    reversed_patches: tuple[int, ...]
    volume: float
    open_edges: int

    @property
    def changed(self) -> bool:
        return bool(self.reversed_patches)


def _shell_flips(block: Block, faces: IntArray, areas: FloatArray) -> BoolArray:
    """The faces of a block's shell to turn so that it runs one way (within each connected
    piece, the side of larger area keeps its sign); none when it already does."""
    if mesh.is_consistently_oriented(faces):  # no directed edge twice: every piece agrees
        return np.zeros(faces.shape[0], dtype=np.bool_)
    result = orientation_flips(faces)
    if result.n_conflicts:
        raise TopologyError(
            f"{block.label}: its boundary cannot be oriented ({result.n_conflicts} edge(s) "
            "where neighbouring triangles disagree whichever way they turn)"
        )
    flip = result.flip.copy()
    flipped_area = np.bincount(result.piece, weights=areas * flip, minlength=result.n_pieces)
    total_area = np.bincount(result.piece, weights=areas, minlength=result.n_pieces)
    flip ^= (flipped_area * 2 > total_area)[result.piece]
    return flip


def _shell_orientation(block: Block, shell: Shell | Surface) -> BlockOrientation:
    """The orientation of ``block`` from its boundary (:meth:`Scene.block_mesh`)."""
    faces: IntArray = np.asarray(shell.faces, dtype=np.int64)
    labels = np.asarray(shell.patch_labels, dtype=np.int64)
    internal = block.internal_patches
    boundary_sides = [s for s in block.sides if s.patch not in internal]
    areas = mesh.face_areas(shell.vertices, faces)
    flip = _shell_flips(block, faces, areas)
    n_sides = len(boundary_sides)
    flipped_count = np.bincount(labels, weights=flip, minlength=n_sides)
    face_count = np.bincount(labels, minlength=n_sides)
    partial = np.flatnonzero((flipped_count > 0) & (flipped_count < face_count))
    if partial.size:
        patch = boundary_sides[int(partial[0])].patch
        raise TopologyError(
            f"{block.label}: patch {patch} would have to turn over in part to close the "
            "block's boundary consistently"
        )
    turn = flipped_count > 0
    oriented = faces.copy()
    oriented[flip] = mesh.flip_faces(faces[flip])
    open_edges = int(mesh.boundary_edges(faces).shape[0])
    centre = shell.vertices.mean(axis=0) if shell.vertices.size else np.zeros(3)
    volume = mesh.signed_volume(shell.vertices - centre, oriented)
    # An open shell's volume is only meaningful when it is far from zero (a box with a gap);
    # a closed one must enclose some.
    return _decide(block, turn, volume, float(areas.sum()), open_edges)


def _decide(
    block: Block,
    turn: BoolArray,
    volume: float,
    area: float,
    open_edges: int,
) -> BlockOrientation:
    """The sides of ``block`` once its shell is oriented (``turn``: per boundary side)."""
    decided = abs(volume) > _OPEN_VOLUME_SHARE * area**1.5
    if (volume < 0) != block.is_universe and (decided or not open_edges):
        turn = ~turn
        volume = -volume
    if not open_edges and (volume == 0.0 or not np.isfinite(volume)):
        raise TopologyError(f"{block.label}: its boundary encloses no volume")
    internal = block.internal_patches
    new_sides: list[PatchSide] = []
    reversed_patches: list[int] = []
    position = 0
    for side in block.sides:
        if side.patch in internal:
            new_sides.append(side)
            continue
        if turn[position]:
            new_sides.append(PatchSide(side.patch, -side.side))
            reversed_patches.append(side.patch)
        else:
            new_sides.append(side)
        position += 1
    return BlockOrientation(block, tuple(new_sides), tuple(reversed_patches), volume, open_edges)


def block_orientations(
    scene: Scene, exact_volumes: bool = True, joined: JoinedPatches | None = None
) -> list[BlockOrientation]:
    """How each block of ``scene`` (the universe included) must list its sides.

    ``exact_volumes=False``: a closed block whose shell runs one way and whose sides stand
    (the usual block) is decided from the volumes of its patches about one origin when they
    leave the sign of its volume beyond doubt; its ``volume`` is then that sum, which may
    differ from the volume of its shell in the last bits. Every other block is measured as
    with ``True``. ``joined`` (with ``exact_volumes=False``): the scene's patches joined as
    :func:`~geobrep.model.arcs.corners_and_arcs_of` joined them; when every block is such a
    block on that mesh and it is the mesh the scene's own tolerance gives, the blocks are
    decided on it.
    """
    blocks = [
        block
        for block in scene.of_type(Block)
        if block.sides and any(s.patch not in block.internal_patches for s in block.sides)
    ]
    if not blocks:
        return []
    if joined is not None and not exact_volumes:
        on_joined = _standing_on_joined(scene, blocks, joined)
        if on_joined is not None:
            return on_joined
    points, triangles_of = patch_triangles(scene, blocks)
    edges = patch_edges(triangles_of, int(points.shape[0]))
    areas, volumes = _patch_measures(points, triangles_of, with_volumes=not exact_volumes)
    out = []
    for block in blocks:
        open_edges = None if edges is None else open_edges_if_one_way(edges, block)
        if open_edges == 0 and volumes is not None:
            standing = _standing_orientation(block, volumes)
            if standing is not None:
                out.append(standing)
                continue
        shell = block_shell(points, triangles_of, block)
        if open_edges is None:  # some triangles to turn: the whole rule
            out.append(_shell_orientation(block, shell))
            continue
        out.append(_one_way_orientation(block, shell, areas, open_edges))
    return out


@dataclass(frozen=True)
class _PatchVolumes:
    """Six times each patch's share of the signed volume of a closed shell through it (its
    triangles about one origin, as a shell on the patch's negative side lists them), its
    triangle count, and what bounds the rounding of a shell's sum."""

    sextuple: dict[int, float]
    count: dict[int, int]
    diameter: float  # of the points' box: no point is farther from a centre inside it
    reach: float  # the largest distance of a point from the coordinates' origin


def _patch_measures(
    points: FloatArray,
    triangles_of: dict[int, IntArray],
    with_volumes: bool,
    with_areas: bool = True,
) -> tuple[dict[int, FloatArray], _PatchVolumes | None]:
    """The area of every triangle of every patch (one pass over all of them; none without
    ``with_areas``) and, with ``with_volumes``, their :class:`_PatchVolumes`."""
    ids = list(triangles_of)
    if not ids:
        return {}, None
    counts = np.array([triangles_of[i].shape[0] for i in ids], dtype=np.int64)
    triangles = np.concatenate([triangles_of[i] for i in ids])
    cuts = np.cumsum(counts)[:-1]
    by_patch: dict[int, FloatArray] = {}
    if with_areas:
        by_patch = dict(zip(ids, np.split(mesh.face_areas(points, triangles), cuts), strict=True))
    if not with_volumes or not points.size:
        return by_patch, None
    low, high = column_extremes(points)
    local = np.ascontiguousarray((points - 0.5 * (low + high)).T)
    a, b, c = (np.take(local, triangles[:, k], axis=1) for k in range(3))
    terms = a[0] * (b[1] * c[2] - b[2] * c[1])
    terms += a[1] * (b[2] * c[0] - b[0] * c[2])
    terms += a[2] * (b[0] * c[1] - b[1] * c[0])
    shares = np.split(terms, cuts)
    with np.errstate(over="ignore", invalid="ignore"):
        diameter = float(np.hypot.reduce(high - low))
        reach = float(np.hypot.reduce(np.maximum(np.abs(low), np.abs(high))))
    return by_patch, _PatchVolumes(
        sextuple={i: float(part.sum()) for i, part in zip(ids, shares, strict=True)},
        count=dict(zip(ids, counts.tolist(), strict=True)),
        diameter=diameter,
        reach=reach,
    )


def _standing_on_joined(
    scene: Scene, blocks: list[Block], joined: JoinedPatches
) -> list[BlockOrientation] | None:
    """Every block's :func:`_standing_orientation` on the ``joined`` mesh, or None when a
    block is no standing one there or the mesh may not be the one :func:`patch_triangles`
    joins: that one joins the points within the scene's tolerance, which is no larger than
    ``joined.tolerance``, so when ``joined`` only joined copies of one point the two join the
    same vertices and drop the same triangles (the patches the same surfaces' labels)."""
    box = scene.bounds
    tolerance = RELATIVE_MERGE_TOLERANCE * (box.diagonal if box else 1.0)
    if not (joined.exact and tolerance <= joined.tolerance):
        return None
    position = {p.id: k for k, p in enumerate(joined.patches)}
    surfaces = {scene.topology.patch(s.patch).surface for b in blocks for s in b.sides}
    bounds = np.searchsorted(joined.owners, np.arange(len(joined.patches) + 1)).tolist()
    triangles_of: dict[int, IntArray] = {}
    index_of = np.full(len(joined.patches), -1, dtype=np.int64)  # joined -> triangles_of
    for patch in scene.topology.patches:  # the patches patch_triangles gives triangles to
        if patch.surface not in surfaces:
            continue
        k = position.get(patch.id)
        if k is None:
            return None
        listed = joined.patches[k]
        if (listed.surface, listed.label) != (patch.surface, patch.label) or (
            joined.surfaces[k] is not scene.get(patch.surface)
        ):
            return None
        index_of[k] = len(triangles_of)
        triangles_of[patch.id] = joined.triangles[bounds[k] : bounds[k + 1]]
    n_points = int(joined.points.shape[0])
    edges = None
    if joined.incidence is not None:  # the corners' and arcs' incidence: no sort again
        edges = patch_edges_of_incidence(
            list(triangles_of),
            index_of,
            joined.triangles,
            joined.incidence,
            n_points,
        )
    if edges is None:
        edges = patch_edges(triangles_of, n_points)
    _, volumes = _patch_measures(joined.points, triangles_of, with_volumes=True, with_areas=False)
    if edges is None or volumes is None:
        return None
    out = []
    for block in blocks:
        if any(side.patch not in triangles_of for side in block.sides):
            return None
        if open_edges_if_one_way(edges, block) != 0:
            return None
        standing = _standing_orientation(block, volumes)
        if standing is None:
            return None
        out.append(standing)
    return out


def _patch_areas(points: FloatArray, triangles_of: dict[int, IntArray]) -> dict[int, FloatArray]:
    """The area of every triangle of every patch (one pass over all of them)."""
    return _patch_measures(points, triangles_of, with_volumes=False)[0]


def _standing_orientation(block: Block, volumes: _PatchVolumes) -> BlockOrientation | None:
    """The orientation of a closed ``block`` whose shell runs one way, from the volumes of
    its patches, when its sides stand and the sum leaves the sign of its volume (as
    :func:`_one_way_orientation` computes it) beyond doubt; else None.

    Both computations lie within ``bound`` (six times a volume) of the volume the shell's
    points enclose: each of the ``n`` triple products of coordinates within ``d`` of their
    origin (the points' box centre here, the shell's there) is rounded by less than
    ``64 eps d^3`` and summed, in whatever order, with less than ``n eps`` times the sum of
    their sizes (each below ``11 d^3``); the shifts of the points (coordinates up to ``r``)
    move each by less than ``2 eps r``, hence each product by less than ``12 eps r d^2``.
    """
    internal = block.internal_patches
    total = 0.0
    n = 0
    for patch, side in block.sides:
        if patch in internal:
            continue
        share = volumes.sextuple[patch]
        total += -share if side == 1 else share  # the positive side lists it flipped
        n += volumes.count[patch]
    eps = float(np.finfo(np.float64).eps)
    d, r = np.float64(volumes.diameter), np.float64(volumes.reach)  # overflow to inf, not raise
    with np.errstate(over="ignore", invalid="ignore"):
        bound = eps * n * ((64.0 + 11.0 * (n + 1)) * d**3 + 12.0 * r * d * d)
    if not (np.isfinite(total) and np.isfinite(bound) and abs(total) > 2.0 * bound):
        return None
    volume = total / 6.0
    if (volume < 0) != block.is_universe:  # a side to reverse: measured as written
        return None
    return BlockOrientation(block, tuple(block.sides), (), volume, 0)


def _one_way_orientation(
    block: Block, shell: Shell, areas: dict[int, FloatArray], open_edges: int
) -> BlockOrientation:
    """:func:`_shell_orientation` of a shell known to run one way (no triangle turns)."""
    internal = block.internal_patches
    boundary = [s.patch for s in block.sides if s.patch not in internal]
    area = float(np.concatenate([areas[p] for p in boundary]).sum())
    centre = shell.vertices.mean(axis=0) if shell.vertices.size else np.zeros(3)
    volume = mesh.signed_volume(shell.vertices - centre, shell.faces)
    return _decide(block, np.zeros(len(boundary), dtype=np.bool_), volume, area, open_edges)


def orient_blocks(scene: Scene, joined: JoinedPatches | None = None) -> tuple[Scene, list[str]]:
    """``scene`` with every block's sides orienting its boundary outward; one note per repair.

    Blocks enclose positive volume and the universe negative volume afterwards; patches record
    their new positive and negative blocks. A block that cannot be oriented is a TopologyError.
    ``joined``: the patches as a reader joined them to find the corners and arcs (see
    :func:`block_orientations`), for the usual model's blocks to be checked on that mesh.
    """
    orientations = block_orientations(scene, exact_volumes=False, joined=joined)
    notes: list[str] = []
    changed = {int(o.block.id or 0): o for o in orientations if o.changed}
    for item in orientations:
        if item.open_edges:
            notes.append(
                f"block {item.block.name or item.block.id!r}: its boundary is not closed "
                f"({item.open_edges} edge(s) bound one face only), so its volume is not checked"
            )
        if item.changed:
            patches = ", ".join(str(p) for p in item.reversed_patches)
            plural = "es" if len(item.reversed_patches) > 1 else ""
            what = "the outside" if item.block.is_universe else f"volume {item.volume:.6g}"
            notes.append(
                f"block {item.block.name or item.block.id!r}: side of patch{plural} {patches} "
                f"reversed so that its boundary is consistently oriented ({what})"
            )
    if not changed:
        return scene, notes
    entities = [
        changed[int(e.id or 0)].block.replace(sides=changed[int(e.id or 0)].sides)
        if isinstance(e, Block) and int(e.id or 0) in changed
        else e
        for e in scene.entities
    ]
    blocks = [e for e in entities if isinstance(e, Block)]
    positive: dict[int, int] = {}
    negative: dict[int, int] = {}
    for block in blocks:
        for patch_id, side in block.sides:
            claims = positive if side == 1 else negative
            other = claims.setdefault(patch_id, int(block.id or 0))
            if other != int(block.id or 0) and side in (1, -1):
                owner = scene.get(other)
                raise TopologyError(
                    f"{block.label} and {owner.label} both lie on the "
                    f"{'positive' if side == 1 else 'negative'} side of patch {patch_id}"
                )
    topology = scene.topology.model_copy(
        update={
            "patches": tuple(
                p.model_copy(
                    update={
                        "positive_block": positive.get(p.id),
                        "negative_block": negative.get(p.id),
                    }
                )
                for p in scene.topology.patches
            )
        }
    )
    return scene.replace(entities=entities, topology=topology), notes
