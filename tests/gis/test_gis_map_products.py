"""Map products of the faulted layer cake: outlines, traces on the top surface, sections."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.gis.map_products import (
    block_outlines,
    block_sections,
    level_set_segments,
    map_products,
    surface_outlines,
    top_traces,
)
from geobrep.ops.io import read, write

shapely = pytest.importorskip("shapely")

WIDTH, LENGTH, HEIGHT = 1000.0, 800.0, 600.0
ORIGIN = np.array([600_000.0, 5_000_000.0, 0.0])


def _as_shapely(polygon: geobrep.Polygon) -> object:
    pieces = []
    for p in range(polygon.n_polygons):
        rings = [
            polygon.ring(r)[:, :2]
            for r in range(polygon.polygon_offsets[p], polygon.polygon_offsets[p + 1])
        ]
        pieces.append(shapely.Polygon(rings[0], holes=rings[1:]))
    return shapely.union_all(pieces)


def test_block_outlines_match_the_footprint(layer_cake: geobrep.Scene) -> None:
    outlines = block_outlines(layer_cake)
    assert [o.metadata["block"] for o in outlines] == [b.id for b in layer_cake.blocks]
    for outline, block in zip(outlines, layer_cake.blocks, strict=True):
        # the walls are vertical and the fault strikes along y: each outline is the block's
        # map box, x range × the model's length
        box = layer_cake.block_mesh(block).bounds
        assert box is not None
        expected = (box.maxs[0] - box.mins[0]) * (box.maxs[1] - box.mins[1])
        assert outline.area == pytest.approx(expected, rel=1e-12)
        assert outline.metadata["unit_name"] == block.unit_name
        assert np.all(outline.vertices[:, 2] == 0.0)
    union = shapely.union_all([_as_shapely(o) for o in outlines])
    assert union.area == pytest.approx(WIDTH * LENGTH, rel=1e-12)
    assert union.bounds == pytest.approx((450_000.0, 6_700_000.0, 451_000.0, 6_700_800.0))
    # the two top units meet at the fault's trace: x = 550 m from the west wall
    assert outlines[0].area == pytest.approx(550.0 * LENGTH, rel=1e-12)


def test_surface_outlines(layer_cake: geobrep.Scene) -> None:
    by_name = {o.name: o for o in surface_outlines(layer_cake)}
    assert by_name["top"].area == pytest.approx(WIDTH * LENGTH, rel=1e-12)
    # the fault dips 0.3 horizontal per metre over the model height
    assert by_name["fault"].area == pytest.approx(0.3 * HEIGHT * LENGTH, rel=1e-12)
    assert "west" not in by_name  # vertical walls have no map area


def test_fault_trace_lies_on_the_fault_and_the_top(layer_cake: geobrep.Scene) -> None:
    (trace,) = top_traces(layer_cake)
    fault, top = layer_cake["fault"], layer_cake["top"]
    assert trace.kind == "fault"
    assert trace.metadata["surface"] == fault.id

    # conformal model: the trace is the fault's edge shared with the top surface
    def keys(points: np.ndarray) -> set[tuple[float, ...]]:
        return {tuple(p) for p in np.round(points, 6).tolist()}

    shared = keys(fault.vertices) & keys(top.vertices)
    assert keys(trace.vertices) == shared
    assert np.allclose(trace.vertices[:, 0], 450_550.0)
    assert trace.vertices[:, 1].min() == 6_700_000.0
    assert trace.vertices[:, 1].max() == 6_700_800.0
    assert trace.n_parts == 1


def _grid_surface(z_of: object, name: str, kind: str, n: int = 11) -> geobrep.Surface:
    xs, ys = np.meshgrid(np.linspace(0, 200, n), np.linspace(0, 100, n), indexing="ij")
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    vertices[:, 2] = z_of(vertices[:, 0], vertices[:, 1])  # type: ignore[operator]
    idx = np.arange(xs.size).reshape(n, n)
    a, b, c, d = (
        idx[:-1, :-1].ravel(),
        idx[1:, :-1].ravel(),
        idx[1:, 1:].ravel(),
        idx[:-1, 1:].ravel(),
    )
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return geobrep.Surface(vertices=vertices + ORIGIN, faces=faces, name=name, kind=kind)


def test_trace_of_a_fault_crossing_a_non_conformal_top() -> None:
    top = _grid_surface(lambda x, y: 0.05 * x, "topography", "boundary")
    # a plane fault x = 100 + 0.5 (z - 5) + 0.1 y, its own mesh, crossing the topography
    u, v = np.meshgrid(np.linspace(-60, 40, 7), np.linspace(0, 100, 9), indexing="ij")
    z, y = u.ravel(), v.ravel()
    x = 100 + 0.5 * (z - 5) + 0.1 * y
    idx = np.arange(z.size).reshape(u.shape)
    a, b, c, d = (
        idx[:-1, :-1].ravel(),
        idx[1:, :-1].ravel(),
        idx[1:, 1:].ravel(),
        idx[:-1, 1:].ravel(),
    )
    fault = geobrep.Surface(
        vertices=np.column_stack([x, y, z]) + ORIGIN,
        faces=np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]),
        name="F2",
        kind="fault",
    )
    scene = geobrep.Scene(entities=[top, fault])
    (trace,) = top_traces(scene, top="topography")
    local = trace.vertices - [600_000.0, 5_000_000.0, 0.0]
    # on the fault plane and on the topography (both planar: exact up to rounding)
    np.testing.assert_allclose(
        local[:, 0], 100 + 0.5 * (local[:, 2] - 5) + 0.1 * local[:, 1], atol=1e-6
    )
    np.testing.assert_allclose(local[:, 2], 0.05 * local[:, 0], atol=1e-6)
    assert local[:, 1].min() == pytest.approx(0.0)
    assert local[:, 1].max() == pytest.approx(100.0)
    with pytest.raises(geobrep.EntityNotFoundError, match="no top surface 'top'"):
        top_traces(scene)


def test_level_set_of_a_linear_field_is_exact() -> None:
    top = _grid_surface(lambda x, y: 0.0 * x, "plate", "boundary")
    values = top.vertices[:, 0] - 600_000.0 - 73.0
    nodes, segments = level_set_segments(top.vertices, top.faces, values, 1e-9)
    assert np.allclose(nodes[:, 0], 600_073.0)
    lengths = np.linalg.norm(nodes[segments[:, 1]] - nodes[segments[:, 0]], axis=1)
    assert lengths.sum() == pytest.approx(100.0)


def test_horizontal_and_vertical_sections_per_block(layer_cake: geobrep.Scene) -> None:
    level = block_sections(layer_cake, [geobrep.Plane.z(-150.0)])
    assert sum(p.area for p in level) == pytest.approx(WIDTH * LENGTH, rel=1e-9)
    assert all(np.all(p.vertices[:, 2] == pytest.approx(-150.0)) for p in level)
    assert {p.metadata["block"] for p in level} <= {b.id for b in layer_cake.blocks}
    # x = 700 m: the panel is the area between the top's and the bottom's lines on the plane
    panel = block_sections(layer_cake, [geobrep.Plane.x(450_700.0)], with_traces=True)
    polygons = [p for p in panel if isinstance(p, geobrep.Polygon)]
    outline = []
    for name in ("top", "bottom"):
        surface = layer_cake[name]
        nodes, _ = level_set_segments(
            surface.vertices, surface.faces, surface.vertices[:, 0] - 450_700.0, 1e-9
        )
        ordered = nodes[np.argsort(nodes[:, 1])][:, 1:]
        outline.append(ordered if name == "top" else ordered[::-1])
    yz = np.concatenate(outline)
    expected = 0.5 * abs(
        np.dot(yz[:, 0], np.roll(yz[:, 1], -1)) - np.dot(yz[:, 1], np.roll(yz[:, 0], -1))
    )
    assert expected == pytest.approx(LENGTH * HEIGHT, rel=1e-3)
    assert sum(p.area for p in polygons) == pytest.approx(expected, rel=1e-9)
    assert any(p.metadata["layer"] == "section_lines" for p in panel)


def test_map_products_as_a_geopackage(tmp_path: Path, layer_cake: geobrep.Scene) -> None:
    products = map_products(layer_cake, section_levels=[-150.0, -400.0])
    path = write(products, tmp_path / "map.gpkg")
    again = read(path)
    assert again.crs is not None
    assert again.crs.epsg == 32631
    layers = {e.metadata["layer"] for e in again.entities}
    assert layers == {"block_outlines", "traces", "sections"}
    outlines = [e for e in again.polygons if e.metadata["layer"] == "block_outlines"]
    assert [o.metadata["block"] for o in outlines] == [b.id for b in layer_cake.blocks]
    assert [o.metadata["unit_name"] for o in outlines] == [b.unit_name for b in layer_cake.blocks]
    sections = [e for e in again.polygons if e.metadata["layer"] == "sections"]
    assert sum(p.area for p in sections) == pytest.approx(2 * WIDTH * LENGTH, rel=1e-9)
    import pyogrio

    meta, _, _, fields = pyogrio.raw.read(
        path, layer="block_outlines", columns=["unit_name", "map_area"]
    )
    # by name: pyogrio before 0.13 returns the columns in file order, not in the order asked
    unit_names = fields[list(meta["fields"]).index("unit_name")]
    assert sorted(set(unit_names.tolist())) == ["unit 1", "unit 2", "unit 3"]
