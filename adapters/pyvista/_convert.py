"""Scenes and entities to and from pyvista datasets (pyvista is imported only when used).

Every mesh entity becomes one dataset (``PolyData`` for point sets, polylines and surfaces,
``UnstructuredGrid`` for tetrahedral meshes and octrees) carrying its properties as point and
cell arrays, its patch labels as the ``geobrep_part`` cell array, and its name, id, kind and
property units as a JSON header in field data; a scene becomes a ``MultiBlock`` of them keyed by
entity name. Block entities (which have no mesh of their own) become their closed boundary
mesh in :func:`scene_blocks_to_pyvista`. Any VTK dataset converts back (polygons and strips are
triangulated, poly-lines split into segments).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.cell_layout import (
    HEADER_ARRAY,
    LAYOUT_TYPES,
    CellLayout,
    decode_header,
    encode_header,
    header_applies,
    layout_to_scene,
    scene_to_layout,
)
from geobrep.errors import FormatError, import_optional
from geobrep.model.entities import Entity, LinearOctree
from geobrep.model.scene import Scene

__all__ = [
    "dataset_to_layout",
    "from_pyvista",
    "import_pyvista",
    "layout_to_dataset",
    "octree_to_pyvista",
    "scene_blocks_to_pyvista",
    "to_pyvista",
]

_VTK_TYPE: Final = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "tetra": 10}
_VTK_KIND: Final = {v: k for k, v in _VTK_TYPE.items()}
_POLY_ORDER: Final = ("vertex", "line", "triangle", "quad")
_SCENE_ARRAY: Final = "geobrep_scene"


def import_pyvista(feature: str) -> Any:
    """The ``pyvista`` module, or :class:`MissingDependencyError` naming the ``viz`` extra."""
    return import_optional("pyvista", "viz", feature)


def _padded(conn: NDArray[np.int64]) -> NDArray[np.int64]:
    """VTK's ``[n, i0, ..., n, j0, ...]`` cell array of fixed-width cells."""
    count = np.full((conn.shape[0], 1), conn.shape[1], dtype=np.int64)
    return np.hstack([count, conn]).ravel()


def layout_to_dataset(layout: CellLayout) -> Any:
    """A ``PolyData`` (no tetrahedra) or ``UnstructuredGrid`` holding ``layout``."""
    pv = import_pyvista("converting to pyvista")
    kinds = [kind for kind, _ in layout.blocks]
    slices = layout.block_slices()
    if "tetra" in kinds:
        order = list(range(len(kinds)))
        cells: Any = np.concatenate([_padded(conn) for _, conn in layout.blocks])
        types = np.concatenate(
            [np.full(len(conn), _VTK_TYPE[k], np.uint8) for k, conn in layout.blocks]
        )
        dataset = pv.UnstructuredGrid(cells, types, layout.points)
    else:
        order = sorted(range(len(kinds)), key=lambda i: _POLY_ORDER.index(kinds[i]))
        parts: dict[str, list[NDArray[np.int64]]] = {"verts": [], "lines": [], "faces": []}
        for i in order:
            key = {"vertex": "verts", "line": "lines"}.get(kinds[i], "faces")
            parts[key].append(_padded(layout.blocks[i][1]))
        dataset = pv.PolyData()
        dataset.points = layout.points.copy()
        for key, arrays in parts.items():
            if arrays:
                setattr(dataset, key, np.concatenate(arrays))
    permutation = (
        np.concatenate([np.arange(slices[i].start, slices[i].stop) for i in order])
        if order
        else np.zeros(0, np.int64)
    )
    for name, values in layout.point_data.items():
        dataset.point_data[name] = values
    for name, values in layout.cell_data.items():
        dataset.cell_data[name] = np.asarray(values)[permutation]
    if layout.header is not None:
        dataset.field_data[HEADER_ARRAY] = encode_header(layout.header)
    return dataset


def dataset_to_layout(dataset: Any) -> CellLayout:
    """The cells of any VTK dataset: polygons and strips triangulated, poly-lines split."""
    pv = import_pyvista("converting from pyvista")
    uniform = _uniform_faces(dataset) if isinstance(dataset, pv.PolyData) else None
    if uniform is not None:  # only triangles (or only quads): the arrays as VTK holds them
        header = None
        if HEADER_ARRAY in dataset.field_data:
            header = decode_header(dataset.field_data[HEADER_ARRAY])
        cell_data = {name: np.asarray(dataset.cell_data[name]) for name in dataset.cell_data}
        return CellLayout(
            points=np.asarray(dataset.points, dtype=np.float64),
            blocks=[uniform],
            point_data={name: np.asarray(dataset.point_data[name]) for name in dataset.point_data},
            cell_data=cell_data,
            header=header if header_applies(header, cell_data) else None,
        )
    if isinstance(dataset, pv.PolyData) and (dataset.n_strips or _has_polygons(dataset)):
        dataset = dataset.triangulate(inplace=False)
    if isinstance(dataset, pv.PolyData):
        grid = dataset
        types, offsets, connectivity = _polydata_cells(dataset)
    else:
        grid = (
            dataset
            if isinstance(dataset, pv.UnstructuredGrid)
            else dataset.cast_to_unstructured_grid()
        )
        types = np.asarray(grid.celltypes, dtype=np.int64)
        offsets = np.asarray(grid.cell_offsets, dtype=np.int64)
        connectivity = np.asarray(grid.cell_connectivity, dtype=np.int64)
    sizes = np.diff(offsets)
    blocks: list[tuple[str, NDArray[np.int64]]] = []
    source_cell: list[NDArray[np.int64]] = []
    vtk_poly_line, vtk_poly_vertex = 4, 2
    present = np.flatnonzero(np.bincount(types)) if len(types) else np.zeros(0, np.int64)
    for vtk_type in (int(t) for t in present):
        cells = np.flatnonzero(types == vtk_type)
        if vtk_type in _VTK_KIND:
            width = {"vertex": 1, "line": 2, "triangle": 3, "quad": 4, "tetra": 4}[
                _VTK_KIND[vtk_type]
            ]
            if len(cells) == len(types) and len(connectivity) == width * len(cells):
                block = connectivity.reshape(len(cells), width)  # one cell type: no gather
            else:
                block = connectivity[offsets[cells][:, None] + np.arange(width)]
            blocks.append((_VTK_KIND[vtk_type], block))
            source_cell.append(cells)
        elif vtk_type == vtk_poly_line:
            counts = sizes[cells] - 1
            owner = np.repeat(cells, counts)
            rank = np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)
            start = offsets[owner] + rank
            blocks.append(("line", np.column_stack([connectivity[start], connectivity[start + 1]])))
            source_cell.append(owner)
        elif vtk_type == vtk_poly_vertex:
            owner = np.repeat(cells, sizes[cells])
            start = np.concatenate([np.arange(offsets[c], offsets[c + 1]) for c in cells])
            blocks.append(("vertex", connectivity[start][:, None]))
            source_cell.append(owner)
        else:
            raise FormatError(f"VTK cell type {int(vtk_type)} has no geobrep entity")
    take = np.concatenate(source_cell) if source_cell else np.zeros(0, np.int64)
    identity = len(take) == len(types) and bool((take == np.arange(len(take))).all())
    cell_data = {
        name: np.asarray(grid.cell_data[name])
        if identity
        else np.asarray(grid.cell_data[name])[take]
        for name in grid.cell_data
    }
    header = None
    if HEADER_ARRAY in dataset.field_data:
        header = decode_header(dataset.field_data[HEADER_ARRAY])
    return CellLayout(
        points=np.asarray(grid.points, dtype=np.float64),
        blocks=blocks,
        point_data={name: np.asarray(grid.point_data[name]) for name in grid.point_data},
        cell_data=cell_data,
        header=header if header_applies(header, cell_data) else None,
    )


def _polydata_cells(
    polydata: Any,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """VTK cell types, offsets and connectivity of a PolyData's verts, lines and polys (in
    VTK's cell order), read straight from its cell arrays (no copy into an unstructured grid)."""
    from vtkmodules.util import numpy_support

    vtk_to_numpy: Callable[[Any], NDArray[Any]] = numpy_support.vtk_to_numpy
    types: list[NDArray[np.int64]] = []
    offsets: list[NDArray[np.int64]] = [np.zeros(1, np.int64)]
    connectivity: list[NDArray[np.int64]] = []
    shift = 0
    for cells, single, several in (
        (polydata.GetVerts(), {1: 1}, 2),
        (polydata.GetLines(), {2: 3}, 4),
        (polydata.GetPolys(), {3: 5, 4: 9}, 7),
    ):
        if cells is None or cells.GetNumberOfCells() == 0:
            continue
        conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64, copy=False)
        offs = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64, copy=False)
        sizes = np.diff(offs)
        kind = np.full(len(sizes), several, dtype=np.int64)
        for size, vtk_type in single.items():
            kind[sizes == size] = vtk_type
        types.append(kind)
        offsets.append(offs[1:] + shift)
        connectivity.append(conn)
        shift += len(conn)
    if not types:
        return np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(0, np.int64)
    return np.concatenate(types), np.concatenate(offsets), np.concatenate(connectivity)


def _uniform_faces(polydata: Any) -> tuple[str, NDArray[np.int64]] | None:
    """``("triangle" | "quad", faces)`` of a PolyData holding only faces of that one size."""
    if polydata.GetNumberOfVerts() or polydata.GetNumberOfLines() or polydata.GetNumberOfStrips():
        return None
    if not polydata.GetNumberOfPolys():
        return None
    from vtkmodules.util import numpy_support

    vtk_to_numpy: Callable[[Any], NDArray[Any]] = numpy_support.vtk_to_numpy
    polys = polydata.GetPolys()
    offsets = vtk_to_numpy(polys.GetOffsetsArray())
    n = offsets.shape[0] - 1
    width = int(offsets[-1]) // n
    if width not in (3, 4) or not np.array_equal(offsets, np.arange(0, width * n + 1, width)):
        return None
    faces = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64, copy=False)
    return ("triangle" if width == 3 else "quad"), faces.reshape(n, width)


def _has_polygons(polydata: Any) -> bool:
    if not polydata.GetNumberOfPolys():
        return False
    from vtkmodules.util import numpy_support

    vtk_to_numpy: Callable[[Any], NDArray[Any]] = numpy_support.vtk_to_numpy
    sizes = np.diff(vtk_to_numpy(polydata.GetPolys().GetOffsetsArray()))
    low, high = int(sizes.min()), int(sizes.max())
    return low != high or low not in (3, 4)


def octree_to_pyvista(octree: LinearOctree) -> Any:
    """The leaves of an octree as hexahedral cells (``level`` and ``label`` cell arrays)."""
    pv = import_pyvista("converting an octree to pyvista")
    from geobrep.geometry.morton import morton_decode

    depth = octree.depth
    corner = np.column_stack(morton_decode(np.asarray(octree.codes, np.uint64))).astype(np.float64)
    cell = octree.size / 2.0**depth
    edge = (2.0 ** (depth - np.asarray(octree.levels, np.float64)))[:, None]
    offsets = np.array(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
        dtype=np.float64,
    )
    points = (corner[:, None, :] + edge[:, None, :] * offsets[None]) * cell + octree.origin
    n = len(corner)
    conn = np.arange(8 * n, dtype=np.int64).reshape(n, 8)
    grid = pv.UnstructuredGrid(_padded(conn), np.full(n, 12, np.uint8), points.reshape(-1, 3))
    grid.cell_data["level"] = np.asarray(octree.levels)
    if octree.labels is not None:
        grid.cell_data["label"] = np.asarray(octree.labels)
    for name, prop in octree.cell_data.items():
        grid.cell_data[name] = prop.values
    return grid


def _entity_dataset(entity: Entity, scene: Scene) -> Any | None:
    if isinstance(entity, LinearOctree):
        return octree_to_pyvista(entity)
    if entity.type not in LAYOUT_TYPES:
        return None
    sub = Scene(entities=[entity], crs=scene.crs)
    layout = scene_to_layout(sub)
    if not layout.blocks:
        return None
    return layout_to_dataset(layout)


def to_pyvista(data: Scene | Entity) -> Any:
    """A ``pyvista.MultiBlock`` of a scene (one block per mesh entity), or one entity's dataset.

    Point sets, polylines and surfaces become ``PolyData``, tetrahedral meshes and octrees
    ``UnstructuredGrid``; properties become point and cell arrays. Entities without a mesh
    (blocks, annotations, NURBS, polygons) are not included; see
    :func:`scene_blocks_to_pyvista` for block boundaries.

    >>> import geobrep
    >>> blocks = to_pyvista(geobrep.datasets.faulted_layer_cake())
    >>> blocks.n_blocks, blocks.keys()[0]
    (9, 'H1')
    """
    pv = import_pyvista("to_pyvista()")
    if isinstance(data, Entity):
        dataset = _entity_dataset(data, Scene(entities=[data]))
        if dataset is None:
            raise FormatError(f"{data.label} has no mesh pyvista can hold")
        return dataset
    multiblock = pv.MultiBlock()
    for entity in data.entities:
        dataset = _entity_dataset(entity, data)
        if dataset is not None:
            multiblock.append(dataset, entity.name or f"{entity.type} {entity.id}")
    scene_info = scene_to_layout(Scene(crs=data.crs, name=data.name, metadata=data.metadata))
    assert scene_info.header is not None
    multiblock.field_data[_SCENE_ARRAY] = encode_header(scene_info.header)
    return multiblock


def scene_blocks_to_pyvista(scene: Scene) -> Any:
    """A ``MultiBlock`` of the closed boundary mesh of every block (universe excluded)."""
    pv = import_pyvista("scene_blocks_to_pyvista()")
    multiblock = pv.MultiBlock()
    universe = scene.universe
    for block in scene.blocks:
        if universe is not None and block.id == universe.id:
            continue
        mesh = scene.block_mesh(block)
        dataset = _entity_dataset(mesh.replace(name=block.name, id=block.id), scene)
        if dataset is not None:
            multiblock.append(dataset, block.name or f"block {block.id}")
    return multiblock


def from_pyvista(data: Any) -> Scene | Entity:
    """A scene from a ``MultiBlock``, an entity from a single dataset (any VTK type).

    Datasets written by :func:`to_pyvista` come back with names, ids, kinds, patch labels and
    property units; others become one entity per cell type.
    """
    pv = import_pyvista("from_pyvista()")
    if isinstance(data, pv.MultiBlock):
        entities: list[Any] = []
        for index in range(data.n_blocks):
            block = data[index]
            if block is None:
                continue
            part = from_pyvista(block)
            found: tuple[Any, ...] = part.entities if isinstance(part, Scene) else (part,)
            if HEADER_ARRAY not in block.field_data:
                name = data.get_block_name(index)
                found = tuple(e.replace(name=name) if name else e for e in found)
            entities.extend(found)
        crs = None
        name = ""
        metadata: dict[str, Any] = {}
        if _SCENE_ARRAY in data.field_data:
            header = decode_header(data.field_data[_SCENE_ARRAY])
            if header is not None:
                crs = header.get("crs")
                name = header.get("name", "")
                metadata = header.get("metadata", {})
        ids = [e.id for e in entities]
        if len(set(ids)) != len(ids):
            entities = [e.replace(id=None) for e in entities]
        return Scene(entities=entities, crs=crs, name=name, metadata=metadata)
    if not isinstance(data, pv.DataSet):
        raise FormatError(f"from_pyvista() takes a pyvista dataset, not {type(data).__name__}")
    scene = layout_to_scene(dataset_to_layout(data))
    if len(scene.entities) == 1:
        return scene.entities[0]
    return scene
