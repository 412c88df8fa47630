"""Entities to and from open3d geometries (extra ``open3d``; open3d is imported lazily).

========================  ===========================================================
geobrep                   open3d
========================  ===========================================================
``Surface``               ``TriangleMesh`` (quads split in two triangles)
``PointSet``              ``PointCloud``
``PolyLine``              ``LineSet`` (one line per segment)
``LinearOctree``          ``VoxelGrid`` (leaves expanded to finest voxels)
========================  ===========================================================

open3d's legacy geometries store coordinates as float64, so UTM coordinates pass unchanged.
They hold only three-component ``normals`` and ``colors`` (values in [0, 1]) per point (and
normals per triangle): the point properties of those names travel, anything else does not,
and :func:`open3d_losses` lists it (``to_open3d`` also warns with
:class:`Open3dLossWarning`). Names, ids and patch labels have no place in open3d.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.cell_layout import chain_segments
from geobrep.errors import FormatError, import_optional
from geobrep.geometry.morton import morton_decode, morton_encode
from geobrep.model.entities import Entity, LinearOctree, PointSet, PolyLine, Surface
from geobrep.model.properties import PropertyMap

__all__ = ["Open3dLossWarning", "from_open3d", "open3d_losses", "to_open3d"]

#: More finest-level voxels than this makes ``to_open3d(octree)`` refuse (memory).
MAX_VOXELS = 50_000_000


class Open3dLossWarning(UserWarning):
    """Part of an entity could not go into an open3d geometry."""


def _open3d() -> Any:
    return import_optional("open3d", "open3d", "the open3d bridge")


def _vector3(prop: Any) -> bool:
    values = np.asarray(prop)
    return values.ndim == 2 and values.shape[1] == 3 and values.dtype.kind in "fiu"


def open3d_losses(entity: Entity) -> list[str]:
    """What of ``entity`` an open3d geometry cannot hold (empty: nothing)."""
    lost: list[str] = []
    carried_points = {"normals", "colors"} if isinstance(entity, Surface | PointSet) else set()
    carried_cells = {"normals"} if isinstance(entity, Surface) else set()
    for field, carried, noun in (
        ("point_data", carried_points, "point"),
        ("cell_data", carried_cells, "cell"),
    ):
        props: PropertyMap = getattr(entity, field)
        dropped = sorted(n for n, p in props.items() if n not in carried or not _vector3(p))
        if dropped:
            lost.append(f"{noun} properties dropped: {', '.join(dropped)}")
    if entity.name:
        lost.append("name dropped")
    if isinstance(entity, Surface):
        if entity.patch_labels is not None:
            lost.append("patch labels dropped")
        if entity.faces.shape[1] == 4:
            lost.append("quads split into triangles")
    if isinstance(entity, LinearOctree):
        if entity.labels is not None:
            lost.append("leaf labels kept only as voxel colours")
        if len(np.unique(np.asarray(entity.levels))) > 1:
            lost.append("coarse leaves expanded to finest voxels")
    return lost


def to_open3d(entity: Entity) -> Any:
    """The open3d geometry of ``entity``; warns :class:`Open3dLossWarning` about what is lost.

    >>> import numpy as np, geobrep  # doctest: +SKIP
    >>> cloud = to_open3d(geobrep.PointSet(vertices=np.zeros((3, 3))))  # doctest: +SKIP
    """
    o3d = _open3d()
    lost = open3d_losses(entity)
    if lost:
        warnings.warn(f"{entity.label} to open3d: " + "; ".join(lost), Open3dLossWarning, 2)
    vec = o3d.utility.Vector3dVector
    if isinstance(entity, Surface):
        faces = entity.faces
        if faces.shape[1] == 4:
            faces = np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]])
        mesh = o3d.geometry.TriangleMesh(
            vec(np.array(entity.vertices)), o3d.utility.Vector3iVector(faces.astype(np.int32))
        )
        _attach(entity.point_data, mesh, "vertex_normals", "vertex_colors", vec)
        normals = entity.cell_data.get("normals")
        if normals is not None and _vector3(normals) and entity.faces.shape[1] == 3:
            mesh.triangle_normals = vec(np.asarray(normals, dtype=np.float64).copy())
        return mesh
    if isinstance(entity, PointSet):
        cloud = o3d.geometry.PointCloud(vec(np.array(entity.vertices)))
        _attach(entity.point_data, cloud, "normals", "colors", vec)
        return cloud
    if isinstance(entity, PolyLine):
        lines = o3d.geometry.LineSet(
            vec(np.array(entity.vertices)),
            o3d.utility.Vector2iVector(entity.segments.astype(np.int32)),
        )
        return lines
    if isinstance(entity, LinearOctree):
        return _voxel_grid(entity, o3d)
    raise FormatError(f"{entity.label}: open3d has no geometry for {entity.type}")


def _attach(props: PropertyMap, geometry: Any, normals: str, colors: str, vec: Any) -> None:
    for name, attribute in (("normals", normals), ("colors", colors)):
        prop = props.get(name)
        if prop is not None and _vector3(prop):
            setattr(geometry, attribute, vec(np.asarray(prop, dtype=np.float64).copy()))


def _voxel_grid(octree: LinearOctree, o3d: Any) -> Any:
    depth = octree.depth
    levels = np.asarray(octree.levels, dtype=np.int64)
    spans = 8 ** (depth - levels)
    total = int(spans.sum())
    if total > MAX_VOXELS:
        raise FormatError(f"{octree.label}: {total} finest voxels exceed {MAX_VOXELS}")
    leaf = np.repeat(np.arange(len(levels)), spans)
    rank = np.arange(total) - np.repeat(np.cumsum(spans) - spans, spans)
    codes = np.asarray(octree.codes, dtype=np.uint64)[leaf] + rank.astype(np.uint64)
    ijk = np.column_stack(morton_decode(codes)).astype(np.float64)
    cell = octree.size / 2.0**depth
    origin = np.asarray(octree.origin, dtype=np.float64)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(origin + (ijk + 0.5) * cell))
    if octree.labels is not None:
        labels = np.asarray(octree.labels, dtype=np.float64)[leaf]
        span = max(float(labels.max()), 1.0)
        cloud.colors = o3d.utility.Vector3dVector(np.column_stack([labels / span] * 3))
    top = origin + octree.size
    return o3d.geometry.VoxelGrid.create_from_point_cloud_within_bounds(cloud, cell, origin, top)


def from_open3d(geometry: Any, name: str = "") -> Entity:
    """The entity of an open3d ``TriangleMesh``, ``PointCloud``, ``LineSet`` or ``VoxelGrid``.

    Normals and colours become the ``normals`` and ``colors`` properties.
    """
    o3d = _open3d()
    g = o3d.geometry
    if isinstance(geometry, g.TriangleMesh):
        point_data = _collect(geometry, "vertex_normals", "vertex_colors")
        cell_data = {}
        if geometry.has_triangle_normals():
            cell_data["normals"] = np.asarray(geometry.triangle_normals, dtype=np.float64)
        return Surface(
            vertices=np.asarray(geometry.vertices, dtype=np.float64),
            faces=np.asarray(geometry.triangles, dtype=np.int64).reshape(-1, 3),
            point_data=point_data,
            cell_data=cell_data,
            name=name,
        )
    if isinstance(geometry, g.PointCloud):
        return PointSet(
            vertices=np.asarray(geometry.points, dtype=np.float64).reshape(-1, 3),
            point_data=_collect(geometry, "normals", "colors"),
            name=name,
        )
    if isinstance(geometry, g.LineSet):
        vertices = np.asarray(geometry.points, dtype=np.float64).reshape(-1, 3)
        segments = np.asarray(geometry.lines, dtype=np.int64).reshape(-1, 2)
        return chain_segments(vertices, segments, PropertyMap(), {"name": name})
    if isinstance(geometry, g.VoxelGrid):
        return _octree_from_voxels(geometry, name)
    raise FormatError(f"from_open3d() cannot convert {type(geometry).__name__}")


def _collect(geometry: Any, normals: str, colors: str) -> dict[str, NDArray[np.float64]]:
    data: dict[str, NDArray[np.float64]] = {}
    if getattr(geometry, f"has_{normals}")():
        data["normals"] = np.asarray(getattr(geometry, normals), dtype=np.float64)
    if getattr(geometry, f"has_{colors}")():
        data["colors"] = np.asarray(getattr(geometry, colors), dtype=np.float64)
    return data


def _octree_from_voxels(grid: Any, name: str) -> LinearOctree:
    # open3d exposes voxels only as a list of objects; one pass to copy their indices out
    indices = np.array([v.grid_index for v in grid.get_voxels()], dtype=np.int64).reshape(-1, 3)
    if indices.size == 0:
        raise FormatError("from_open3d(): the voxel grid is empty")
    if indices.min() < 0:
        raise FormatError("from_open3d(): negative voxel indices")
    depth = max(int(np.ceil(np.log2(int(indices.max()) + 1))), 0)
    codes = np.unique(morton_encode(indices[:, 0], indices[:, 1], indices[:, 2]))
    return LinearOctree(
        codes=codes,
        levels=np.full(len(codes), depth, dtype=np.uint8),
        depth=depth,
        origin=np.asarray(grid.origin, dtype=np.float64),
        size=float(grid.voxel_size) * 2.0**depth,
        name=name,
    )
