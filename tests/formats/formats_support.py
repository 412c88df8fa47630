"""Helpers of the format tests: a scene exercising every held feature, and the held-equal check."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.datasets import faulted_layer_cake
from geobrep.host.capabilities import restrict_scene
from geobrep.host.registry import FormatCapabilities
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface, TetMesh
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

#: Formats the meshio, ply and pyvista adapters (and the native format) register.
OUR_FORMATS = (
    "native",
    "vtu",
    "vtk",
    "gmsh",
    "obj",
    "stl",
    "off",
    "ply",
    "vtp",
    "csv",
    "resqml",
)


def rich_scene() -> Scene:
    """The layer cake with properties on its surfaces, plus wells, a polyline and a tet mesh."""
    cake = faulted_layer_cake()
    surfaces = []
    for surface in cake.surfaces:
        centred = surface.vertices - surface.vertices.mean(axis=0)
        surfaces.append(
            surface.replace(
                point_data={
                    "depth": Property(values=-surface.vertices[:, 2], unit="m"),
                    "gradient": centred / (np.linalg.norm(centred, axis=1, keepdims=True) + 1.0),
                },
                cell_data={"face_index": np.arange(surface.n_faces, dtype=np.int32)},
            )
        )
    rng = np.random.default_rng(4)
    origin = np.array([450000.0, 6700000.0, -500.0])
    wells = PointSet(
        vertices=origin + rng.uniform(0, 1000, (25, 3)),
        name="well tops",
        kind="wells",
        point_data={"porosity": Property(values=rng.uniform(0, 0.3, 25), no_data_value=-999.0)},
    )
    trace = PolyLine.from_parts(
        origin + rng.uniform(0, 1000, (9, 3)),
        [[0, 1, 2, 3], [4, 5, 6, 7, 8]],
        closed=[False, True],
        name="fault trace",
        cell_data={"throw": np.linspace(1.0, 8.0, 8)},
    )
    tets = TetMesh(
        vertices=origin + np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10], [10, 10, 10]]),
        cells=[[0, 1, 2, 3], [1, 2, 3, 4]],
        region_labels=[0, 1],
        region_names=("lower", "upper"),
        name="grid",
        cell_data={"facies": np.array([1, 2], dtype=np.int64)},
    )
    blocks = [e for e in cake.entities if e.type == "Block"]
    return cake.replace(entities=[*surfaces, wells, trace, tets, *blocks])


def _cell_coordinates(entity: Entity) -> NDArray[np.float64]:
    """The coordinates of every cell, rows sorted: independent of vertex numbering."""
    if isinstance(entity, Surface):
        coords = entity.vertices[entity.faces].reshape(entity.n_faces, -1)
    elif isinstance(entity, TetMesh):
        coords = entity.vertices[entity.cells].reshape(entity.n_cells, -1)
    elif isinstance(entity, PolyLine):
        coords = entity.vertices[entity.segments].reshape(len(entity.segments), -1)
    else:
        coords = np.asarray(entity.vertices)
    return coords[np.lexsort(coords.T[::-1])]


def merged_cells(entities: Any) -> dict[str, NDArray[np.float64]]:
    """Cell coordinates of ``entities`` gathered per entity type."""
    found: dict[str, list[NDArray[np.float64]]] = {}
    for entity in entities:
        found.setdefault(entity.type, []).append(_cell_coordinates(entity))
    merged = {}
    for kind, parts in found.items():
        coords = np.concatenate(parts)
        merged[kind] = coords[np.lexsort(coords.T[::-1])]
    return merged


def assert_held_equal(original: Scene, back: Scene, caps: FormatCapabilities) -> None:
    """What ``caps`` says the format holds came back equal (exactly: float64 coordinates)."""
    expected = restrict_scene(original, caps)
    assert {e.type for e in back.entities} <= caps.entity_types
    if caps.names and caps.multiple_entities and caps.point_data and caps.cell_data:
        # full-fidelity formats: the whole restricted scene, names, ids, properties, CRS
        assert back.entities == expected.entities
        assert back.crs == (expected.crs if caps.crs else None)
        assert back.groups == expected.groups
        return
    if caps.multiple_entities and caps.ids:
        by_id = {e.id: e for e in back.entities}
        assert set(by_id) == {e.id for e in expected.entities}
        for entity in expected.entities:
            got = by_id[entity.id]
            assert got.type == entity.type
            np.testing.assert_array_equal(_cell_coordinates(got), _cell_coordinates(entity))
            if caps.point_data and entity.point_data and isinstance(got, type(entity)):
                for name, _prop in entity.point_data.items():
                    assert name in got.point_data, name
        return
    # one merged entity per type: compare the cells, wherever their vertices went
    want, got = merged_cells(expected.entities), merged_cells(back.entities)
    assert set(got) == set(want)
    for kind in want:
        np.testing.assert_array_equal(got[kind], want[kind])
