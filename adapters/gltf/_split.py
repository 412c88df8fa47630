"""Large meshes of a tileset split in space, and put back together on read.

A surface (or point set) of more than ``limit`` triangles (points) is cut into leaves of at
most ``limit`` by halving its triangles at the median of their centroids along the widest
axis, again and again (a k-d tree): each leaf is one tile, each halving a tile without content
above them. A leaf is the entity restricted to its triangles and the vertices they use, with
its properties; it remembers which vertices and triangles of the whole it holds
(:class:`Part`), so reading the tiles gives back the whole entity exactly (vertices a cut
shares between leaves are written in each, with the same float32 value).

>>> import numpy as np
>>> from geobrep import PointSet
>>> cloud = PointSet(vertices=np.random.default_rng(0).random((10, 3)))
>>> tree = split_mesh(cloud, cloud, 4)
>>> sorted(len(part.vertex_ids) for part in leaves(tree))
[2, 2, 3, 3]
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import FormatError
from geobrep.model.entities import Entity, PointSet, Surface
from geobrep.model.properties import Property, PropertyMap

__all__ = ["Part", "SplitTree", "leaves", "reassemble", "split_mesh", "splittable"]

IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class Part:
    """One leaf of a split mesh: its own entity and where its elements sit in the whole."""

    geometry: Entity
    """The leaf's mesh: the entity restricted to its triangles (points), properties kept."""
    source: Entity
    """What the leaf shows: ``geometry`` itself, or the block whose boundary it is part of."""
    vertex_ids: IntArray
    """The whole mesh's vertex of each of the leaf's vertices."""
    cell_ids: IntArray
    """The whole mesh's triangle of each of the leaf's triangles (empty for points)."""
    n_vertices: int
    n_cells: int


SplitTree = Part | list["SplitTree"]
"""A leaf, or the two halves of a halving."""


def splittable(geometry: Entity) -> bool:
    """True for the meshes a tileset splits in space: surfaces and point sets."""
    return isinstance(geometry, Surface | PointSet)


def _halves(
    ids: IntArray, centres: NDArray[np.float64], limit: int, whole: bool = False
) -> list[Any]:
    """The k-d tree of element ``ids`` (nested lists of id arrays, each in increasing order),
    leaves of ``limit``; ``centres`` holds one row per axis (a centre's coordinates, or any
    fixed multiple of them). ``whole``: ``ids`` are all the elements, in order (the rows of
    ``centres`` are then their columns as they stand, not gathered)."""
    if len(ids) <= limit:
        return [ids]
    columns = list(centres) if whole else [axis[ids] for axis in centres]
    axis = int(np.argmax([np.ptp(column) for column in columns]))
    half = len(ids) // 2
    lower = np.zeros(len(ids), bool)
    lower[np.argpartition(columns[axis], half)[:half]] = True
    return [_halves(ids[lower], centres, limit), _halves(ids[~lower], centres, limit)]


class _Scratch:
    """Two arrays over a surface's vertices, reused by its leaves: which vertices a leaf's
    triangles use, and their numbers in the leaf. A leaf touches only the span of vertex ids
    its triangles reach and leaves ``used`` as it found it, so a split into ``k`` leaves costs
    what its triangles cost, not ``k`` passes over every vertex."""

    def __init__(self, n: int) -> None:
        self.used = np.zeros(n, bool)
        self.local = np.empty(n, np.int64)

    def vertices(self, corners: NDArray[np.integer[Any]]) -> IntArray:
        """The vertices ``corners`` use, in increasing order."""
        if corners.size == 0:
            return np.zeros(0, np.int64)
        low, high = int(corners.min()), int(corners.max()) + 1
        self.used[corners] = True
        ids = np.flatnonzero(self.used[low:high])
        ids += low
        self.used[ids] = False
        return ids


def _surface_part(
    surface: Surface, source: Entity, faces: IntArray, scratch: _Scratch, loose: IntArray | None
) -> Part:
    """The leaf of ``surface`` holding ``faces`` (and the ``loose`` vertices, which no
    triangle uses)."""
    corners = np.asarray(surface.faces)[faces]
    vertex_ids = scratch.vertices(corners)
    if loose is not None and len(loose):
        vertex_ids = np.union1d(vertex_ids, loose)
    local = scratch.local
    local[vertex_ids] = np.arange(len(vertex_ids))
    labels = None if surface.patch_labels is None else surface.patch_labels[faces]
    geometry = surface.replace(
        vertices=surface.vertices[vertex_ids],
        faces=local[corners],
        patch_labels=labels,
        point_data=surface.point_data.take(vertex_ids),
        cell_data=surface.cell_data.take(faces),
    )
    shown = geometry if source is surface else source
    return Part(geometry, shown, vertex_ids, faces, surface.n_vertices, surface.n_faces)


def _surface_parts(surface: Surface, source: Entity, ids: list[IntArray]) -> list[Part]:
    """The leaves of ``surface`` holding the triangles ``ids`` (one array per leaf), the
    vertices no triangle uses travelling in the first. The first leaf is made last, once the
    others have said which vertices they hold."""
    scratch = _Scratch(surface.n_vertices)
    rest = [_surface_part(surface, source, faces, scratch, None) for faces in ids[1:]]
    held = np.zeros(surface.n_vertices, bool)
    for part in rest:
        held[part.vertex_ids] = True
    held[np.asarray(surface.faces)[ids[0]]] = True
    first = _surface_part(surface, source, ids[0], scratch, np.flatnonzero(~held))
    return [first, *rest]


def _points_part(points: PointSet, source: Entity, ids: IntArray) -> Part:
    geometry = points.replace(vertices=points.vertices[ids], point_data=points.point_data.take(ids))
    shown = geometry if source is points else source
    return Part(geometry, shown, ids, np.zeros(0, np.int64), points.n_points, 0)


def _leaf_ids(tree: list[Any]) -> list[IntArray]:
    """The id arrays of ``tree``'s leaves, left to right."""
    if len(tree) == 1:
        return [tree[0]]
    return [ids for half in tree for ids in _leaf_ids(half)]


def _shaped(tree: list[Any], parts: Iterator[Part]) -> SplitTree:
    """The next of ``parts`` (one per leaf, left to right) in the shape of ``tree``."""
    if len(tree) == 1:
        return next(parts)
    return [_shaped(half, parts) for half in tree]


def _parts(mesh: Entity, source: Entity, tree: list[Any]) -> SplitTree:
    ids = _leaf_ids(tree)
    if isinstance(mesh, Surface):
        parts = _surface_parts(mesh, source, ids)
    else:
        assert isinstance(mesh, PointSet)
        parts = [_points_part(mesh, source, leaf) for leaf in ids]
    return _shaped(tree, iter(parts))


def split_mesh(geometry: Entity, source: Entity, limit: int) -> SplitTree:
    """``geometry`` (a surface or point set showing ``source``) as a k-d tree of leaves of at
    most ``limit`` triangles (points)."""
    if isinstance(geometry, Surface):
        columns = np.ascontiguousarray(np.asarray(geometry.vertices, np.float64).T)
        faces = np.asarray(geometry.faces).T
        # three times the centroids, one row per axis
        centres = np.stack([c[faces[0]] + c[faces[1]] + c[faces[2]] for c in columns])
        count = geometry.n_faces
    elif isinstance(geometry, PointSet):
        centres, count = np.asarray(geometry.vertices, np.float64).T, geometry.n_points
    else:
        raise TypeError(f"{geometry.type} meshes are not split")
    tree = _halves(np.arange(count, dtype=np.int64), centres, max(1, limit), whole=True)
    return _parts(geometry, source, tree)


def leaves(tree: SplitTree) -> list[Part]:
    """The leaves of ``tree``, left to right."""
    if isinstance(tree, Part):
        return [tree]
    return [part for half in tree for part in leaves(half)]


def _scatter(
    props: list[PropertyMap], ids: list[IntArray], size: int, what: str
) -> dict[str, Property]:
    """The properties of the whole from its leaves' (each leaf's values at its ``ids``)."""
    out: dict[str, Property] = {}
    for name, prop in props[0].items():
        values = np.zeros((size, *prop.values.shape[1:]), prop.values.dtype)
        for leaf, where in zip(props, ids, strict=True):
            if name not in leaf or leaf[name].values.shape[1:] != prop.values.shape[1:]:
                raise ValueError(f"{what} {name!r} differs between the tiles")
            values[where] = leaf[name].values
        out[name] = prop.model_copy(update={"values": values})
    return out


def _covered(ids: list[IntArray], size: int, what: str) -> None:
    """Check that the leaves' ``ids`` name every one of the whole's ``size`` elements."""
    if size > sum(len(where) for where in ids):  # before allocating what the file claims
        raise ValueError(f"the tiles hold fewer {what} than the {size} of the whole")
    seen = np.zeros(size, bool)
    for where in ids:
        if len(where) and (where.min() < 0 or where.max() >= size):
            raise ValueError(f"a tile names {what} past the {size} of the whole")
        seen[where] = True
    if not seen.all():
        raise ValueError(f"the tiles leave {int((~seen).sum())} {what} of the whole out")


def _whole(parts: list[tuple[Entity, dict[str, Any]]]) -> Entity:
    first, info = parts[0]
    n_vertices, n_cells = int(info["n_vertices"]), int(info["n_cells"])
    vertex_ids = [np.asarray(p[1]["vertex_ids"], np.int64) for p in parts]
    _covered(vertex_ids, n_vertices, "vertices")
    for (leaf, _), where in zip(parts, vertex_ids, strict=True):
        if len(where) != len(leaf.vertices):  # type: ignore[attr-defined]
            raise ValueError(f"a tile has {len(leaf.vertices)} vertices and {len(where)} ids")  # type: ignore[attr-defined]
    vertices = np.zeros((n_vertices, 3))
    for (leaf, _), where in zip(parts, vertex_ids, strict=True):
        vertices[where] = leaf.vertices  # type: ignore[attr-defined]
    point_data = _scatter([p[0].point_data for p in parts], vertex_ids, n_vertices, "point data")
    if isinstance(first, PointSet):
        return first.replace(vertices=vertices, point_data=point_data)
    assert isinstance(first, Surface)
    cell_ids = [np.asarray(p[1]["cell_ids"], np.int64) for p in parts]
    _covered(cell_ids, n_cells, "triangles")
    if any(len(w) != p[0].n_cells for p, w in zip(parts, cell_ids, strict=True)):
        raise ValueError("a tile's triangle ids do not match its triangles")
    faces = np.zeros((n_cells, 3), np.int64)
    labels = None if first.patch_labels is None else np.zeros(n_cells, np.int64)
    for (leaf, _), where, ids in zip(parts, cell_ids, vertex_ids, strict=True):
        assert isinstance(leaf, Surface)
        faces[where] = ids[leaf.faces]
        if labels is not None and leaf.patch_labels is not None:
            labels[where] = leaf.patch_labels
    cell_data = _scatter([p[0].cell_data for p in parts], cell_ids, n_cells, "cell data")
    return first.replace(
        vertices=vertices,
        faces=faces,
        patch_labels=labels,
        point_data=point_data,
        cell_data=cell_data,
    )


def reassemble(parts: list[tuple[Entity, dict[str, Any]]], where: str) -> Entity:
    """The whole entity from its leaves and what each leaf says of its place in it
    (``vertex_ids``, ``cell_ids``, ``n_vertices``, ``n_cells``); a :class:`FormatError` naming
    ``where`` when the leaves do not make up one whole."""
    if len({type(p[0]) for p in parts}) != 1 or len({p[1]["count"] for p in parts}) != 1:
        raise FormatError("the tiles of one split mesh disagree on its kind or size", where)
    if len(parts) != int(parts[0][1]["count"]):
        raise FormatError(
            f"a split mesh has {len(parts)} of its {parts[0][1]['count']} tiles", where
        )
    try:
        return _whole(parts)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise FormatError(f"a split mesh cannot be put together: {exc}", where) from exc
