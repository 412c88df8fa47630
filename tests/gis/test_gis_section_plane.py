"""Vertical sections a GIS can draw: the section in its own plane's coordinates (issue 12/9)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

import geobrep
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.gis.feature_tables import FeatureWarning
from geobrep.gis.map_products import (
    SectionFrame,
    block_sections,
    from_section_plane,
    map_products,
    section_frame,
)

geopandas = pytest.importorskip("geopandas")
pyogrio = pytest.importorskip("pyogrio")
shapely = pytest.importorskip("shapely")

CAKE = geobrep.datasets.faulted_layer_cake()
BOUNDS = CAKE.bounds
assert BOUNDS is not None
DIAGONAL = float(BOUNDS.diagonal)
VERTICAL = {
    "along y": geobrep.Plane.y(6_700_400.0),
    "oblique": geobrep.Plane.from_point_normal(BOUNDS.center, (1.0, 0.8, 0.0)),
}


def _ring_vector_area(ring: NDArray[np.float64]) -> NDArray[np.float64]:
    """Newell's vector area of a closed ring (first point repeated or not), about its mean."""
    local = ring - ring.mean(axis=0)
    return 0.5 * np.cross(local, np.roll(local, -1, axis=0)).sum(axis=0)


def _true_area(polygon: Any, normal: NDArray[np.float64]) -> float:
    """Area in 3D of a shapely Polygon Z lying in a plane of unit ``normal``: outer - holes."""
    outer = abs(
        _ring_vector_area(shapely.get_coordinates(polygon.exterior, include_z=True)) @ normal
    )
    holes = sum(
        abs(_ring_vector_area(shapely.get_coordinates(ring, include_z=True)) @ normal)
        for ring in polygon.interiors
    )
    return float(outer - holes)


def _frame_of(path: Path, layer: str) -> dict[str, list[float]]:
    metadata = pyogrio.read_info(path, layer=layer)["layer_metadata"]
    frame: dict[str, list[float]] = json.loads(metadata["geobrep_section_frame"])
    return frame


@pytest.mark.parametrize("name", sorted(VERTICAL))
def test_a_vertical_section_in_plane_coordinates_is_drawable(tmp_path: Path, name: str) -> None:
    plane = VERTICAL[name]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no CRS warning: the plane layer has no CRS by design
        path = geobrep.write(map_products(CAKE, section_planes=[plane]), tmp_path / "map.gpkg")
    world = geopandas.read_file(path, layer="sections").sort_values("block_id")
    flat = geopandas.read_file(path, layer="sections_plane").sort_values("block_id")
    assert len(world) == len(flat) == len(CAKE.blocks)
    assert flat.crs is None  # along-section metres, not the map's CRS
    # in map coordinates the section is a vertical polygon: nothing a GIS can draw
    assert np.all(shapely.area(world.geometry.values) < 1e-6 * DIAGONAL**2)
    assert not shapely.is_valid(world.geometry.values).any()
    # in its plane it is a set of valid polygons of the true area
    assert shapely.is_valid(flat.geometry.values).all()
    true_areas = [_true_area(g, plane.normal) for g in world.geometry.values]
    assert min(true_areas) > 0
    assert shapely.area(flat.geometry.values) == pytest.approx(true_areas, rel=1e-9)
    assert shapely.area(flat.geometry.values).sum() == pytest.approx(
        sum(p.area for p in block_sections(CAKE, [plane])), rel=1e-9
    )
    # the transform in the layer metadata puts the plane coordinates back on the 3D section
    frame = _frame_of(path, "sections_plane")
    origin, along, up = (np.asarray(frame[k]) for k in ("origin", "along", "up"))
    assert np.linalg.norm(along) == pytest.approx(1.0, abs=1e-15)
    assert up.tolist() == [0.0, 0.0, 1.0]  # a vertical plane: the second coordinate is z
    assert abs(along @ plane.normal) < 1e-15
    for flat_geometry, world_geometry in zip(
        flat.geometry.values, world.geometry.values, strict=True
    ):
        local = shapely.get_coordinates(flat_geometry, include_z=True)
        assert np.abs(local[:, 2]).max() < 1e-9 * DIAGONAL  # offset from the plane
        mapped = origin + local[:, :1] * along + local[:, 1:2] * up
        expected = shapely.get_coordinates(world_geometry, include_z=True)
        assert np.abs(mapped - expected).max() < 1e-9 * DIAGONAL
        assert np.abs(local[:, 1] - expected[:, 2]).max() < 1e-9 * DIAGONAL  # elevation
    starts = shapely.bounds(flat.geometry.values)
    assert starts[:, 0].min() == pytest.approx(0.0, abs=1e-9 * DIAGONAL)  # distance from start


def test_geobrep_reads_the_frame_back_and_returns_to_world(tmp_path: Path) -> None:
    plane = VERTICAL["oblique"]
    products = map_products(CAKE, section_planes=[plane], with_section_lines=True)
    path = geobrep.write(products, tmp_path / "panel.gpkg")
    again = geobrep.read(path)
    assert again.crs is not None
    assert again.crs.epsg == 32631  # the plane layers do not disturb the CRS of the others
    in_plane = [e for e in again.entities if "section_frame" in e.metadata]
    assert {e.metadata["layer"] for e in in_plane} == {"sections_plane", "section_lines_plane"}
    frame = SectionFrame.model_validate(in_plane[0].metadata["section_frame"])
    written = next(e for e in products.entities if "section_frame" in e.metadata)
    assert frame == SectionFrame.model_validate(written.metadata["section_frame"])  # bit for bit
    back = from_section_plane(in_plane)
    by_layer = {
        (e.metadata["layer"], e.name): e
        for e in again.entities
        if "section_frame" not in e.metadata
        and e.metadata["layer"] in ("sections", "section_lines")
    }
    for entity in back:
        world = by_layer[(entity.metadata["layer"], entity.name)]
        assert np.abs(entity.vertices - world.vertices).max() < 1e-9 * DIAGONAL


def test_several_planes_get_one_layer_each_and_horizontal_ones_none(tmp_path: Path) -> None:
    planes = [VERTICAL["along y"], VERTICAL["oblique"], geobrep.Plane.z(-150.0)]
    products = block_sections(CAKE, planes, section_coordinates="plane")
    layers = {e.metadata["layer"] for e in products}
    assert layers == {"sections_plane_1", "sections_plane_2", "sections"}
    assert all(
        p.vertices[:, 2].max() == -150.0 for p in products if p.metadata["layer"] == "sections"
    )
    path = geobrep.write(geobrep.Scene(entities=products, crs=CAKE.crs), tmp_path / "s.gpkg")
    frames = [_frame_of(path, f"sections_plane_{k}") for k in (1, 2)]
    assert frames[0]["along"] == [1.0, 0.0, 0.0]
    assert frames[1]["along"][0] > 0  # west to east
    with pytest.raises(DegenerateGeometryError, match="horizontal"):
        section_frame(geobrep.Plane.z(-150.0))
    assert {e.metadata["layer"] for e in block_sections(CAKE, planes)} == {"sections"}
    with pytest.raises(OptionsError, match="section_coordinates='map'"):
        block_sections(CAKE, planes, section_coordinates="map")  # type: ignore[arg-type]


def test_an_inclined_section_keeps_its_area() -> None:
    plane = geobrep.Plane.from_point_normal(BOUNDS.center, (0.3, 0.0, 1.0))
    world = block_sections(CAKE, [plane])
    flat = block_sections(CAKE, [plane], section_coordinates="plane")
    frame = SectionFrame.model_validate(flat[0].metadata["section_frame"])
    assert frame.up[2] == pytest.approx(0.3 / np.hypot(0.3, 1.0))  # up the dip: sin(dip)
    assert np.allclose(frame.rotation @ frame.rotation.T, np.eye(3), atol=1e-15)
    assert sum(p.area for p in flat) == pytest.approx(sum(p.area for p in world), rel=1e-12)
    for polygon in flat:
        rings = [polygon.ring(i) for i in range(polygon.n_rings)]
        map_area = sum(
            float(shapely.area(shapely.Polygon(r[:, :2]))) * (1 if i == 0 else -1)
            for i, r in enumerate(rings)
        )
        assert map_area == pytest.approx(polygon.area, rel=1e-9)


def test_geojson_and_shapefile_leave_plane_layers_out_with_a_warning(tmp_path: Path) -> None:
    products = map_products(CAKE, section_planes=[VERTICAL["along y"]])
    with pytest.warns(FeatureWarning, match="'sections_plane' in section-plane coordinates"):
        path = geobrep.write(products, tmp_path / "map.geojson")
    assert "sections_plane" not in {e.metadata["layer"] for e in geobrep.read(path).entities}
    with pytest.raises(geobrep.FormatError, match="section-plane coordinates: ESRI Shapefile"):
        geobrep.write(products, tmp_path / "plane.shp", layer="sections_plane")


def test_the_geopandas_bridge_keeps_plane_coordinates_apart() -> None:
    from geobrep.gis.crs_ops import to_geodataframe

    products = map_products(CAKE, section_planes=[VERTICAL["along y"]])
    with pytest.warns(FeatureWarning, match="left out 6 entities in section-plane coordinates"):
        frame = to_geodataframe(products)
    assert "sections_plane" not in set(frame["layer"])
    assert frame.crs.to_epsg() == 32631
    plane = [e for e in products.entities if "section_frame" in e.metadata]
    flat = to_geodataframe(plane)
    assert flat.crs is None
    assert flat.geometry.is_valid.all()


def test_cli_section_to_geopackage_is_drawable_by_default(tmp_path: Path) -> None:
    from geobrep.cli import main

    source = tmp_path / "cake.geobrep"
    geobrep.write(CAKE, source)
    target = tmp_path / "section.gpkg"
    assert main(["section", str(source), str(target), "--y", "6700400"]) == 0
    layers = {str(name) for name, _ in pyogrio.list_layers(target)}
    assert {"sections", "sections_plane"} <= layers
    drawn = geopandas.read_file(target, layer="sections_plane")
    assert drawn.geometry.is_valid.all()
    world = geobrep.section(CAKE, geobrep.Plane.y(6_700_400.0))
    assert isinstance(world, geobrep.Scene)
    true_area = sum(p.area for p in world.polygons)
    assert float(drawn.geometry.area.sum()) == pytest.approx(true_area, rel=1e-9)
    world_only = tmp_path / "world.gpkg"
    args = ["section", str(source), str(world_only), "--y", "6700400", "--coordinates", "world"]
    assert main(args) == 0
    assert "sections_plane" not in {str(n) for n, _ in pyogrio.list_layers(world_only)}
