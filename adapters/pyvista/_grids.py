"""Grids and wells as pyvista datasets for pictures: grid cells, well traces and their markers.

A RegularGrid or a StructuredGrid given by points is a ``pyvista.StructuredGrid`` (its cells
drawn as the grid's outer faces), a corner-point grid an ``UnstructuredGrid`` of its hexahedra;
inactive cells (``actnum`` False, or the cell property ``active`` 0 of a clipped RegularGrid)
are left out. Cell and point properties become cell and point arrays. A Well is the polyline of
its stations (point array ``md``) and, when it has markers, a second dataset of the marker
points whose names are labels in the picture.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geobrep.adapters._grid_boundary import active_cells
from geobrep.adapters.pyvista._convert import import_pyvista
from geobrep.model.entities import Entity, RegularGrid, StructuredGrid, Well
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene

__all__ = ["MARKER_NAMES", "grid_and_well_datasets", "grid_to_pyvista", "well_to_pyvista"]

#: Field array of a marker dataset holding the marker names (one string per point).
MARKER_NAMES = "geobrep_marker_names"
# VTK's hexahedron corner order, as corner numbers x + 2y + 4z
_VTK_HEX = np.array([0, 1, 3, 2, 4, 5, 7, 6], dtype=np.int64)
_VTK_HEXAHEDRON = 12


def _arrays(target: Any, props: PropertyMap) -> None:
    for name, prop in props.items():
        if prop.values.dtype.kind in "biuf":
            target[name] = np.asarray(prop.values)


def grid_to_pyvista(grid: RegularGrid | StructuredGrid) -> Any:
    """The cells of a grid (active ones only) with their properties."""
    pv = import_pyvista("drawing grids")
    if isinstance(grid, StructuredGrid) and grid.is_corner_point:
        corners = grid.cell_corners()[:, _VTK_HEX]
        n = corners.shape[0]
        cells = np.hstack([np.full((n, 1), 8), np.arange(8 * n).reshape(n, 8)]).reshape(-1)
        dataset = pv.UnstructuredGrid(
            cells, np.full(n, _VTK_HEXAHEDRON, np.uint8), corners.reshape(-1, 3)
        )
    else:
        points = grid.points() if isinstance(grid, RegularGrid) else grid.points
        assert points is not None
        ni, nj, nk = grid.counts
        dataset = pv.StructuredGrid()
        dataset.points = np.asarray(points, dtype=np.float64)
        dataset.dimensions = (ni + 1, nj + 1, nk + 1)
        _arrays(dataset.point_data, grid.point_data)
    _arrays(dataset.cell_data, grid.cell_data)
    active = active_cells(grid)
    if active is not None and not active.all():
        dataset = dataset.extract_cells(np.flatnonzero(active))
    dataset.set_active_scalars(None)
    return dataset


def well_to_pyvista(well: Well) -> tuple[Any, Any | None]:
    """The trace of a well (point array ``md``, station properties) and its marker points."""
    pv = import_pyvista("drawing wells")
    trace = pv.lines_from_points(np.asarray(well.vertices, dtype=np.float64))
    trace.point_data["md"] = np.asarray(well.md)
    _arrays(trace.point_data, well.point_data)
    trace.set_active_scalars(None)  # drawn in its colour unless a property is asked for
    if not well.markers:
        return trace, None
    markers = pv.PolyData(well.marker_positions())
    markers.point_data["md"] = np.array([m.md for m in well.markers])
    markers.set_active_scalars(None)
    markers.field_data[MARKER_NAMES] = [m.name or m.surface for m in well.markers]
    return trace, markers


def grid_and_well_datasets(scene: Scene) -> list[tuple[str, Any, Entity]]:
    """``(label, dataset, entity)`` for every grid and well of ``scene`` with something to draw."""
    out: list[tuple[str, Any, Entity]] = []
    for entity in scene.entities:
        label = entity.name or entity.label
        if isinstance(entity, RegularGrid | StructuredGrid):
            dataset = grid_to_pyvista(entity)
            if dataset.n_cells:
                out.append((label, dataset, entity))
        elif isinstance(entity, Well) and entity.n_stations >= 2:
            trace, markers = well_to_pyvista(entity)
            out.append((label, trace, entity))
            if markers is not None:
                out.append((f"{label} markers", markers, entity))
    return out
