"""The geopandas bridge: to_geodataframe / from_geodataframe."""

from __future__ import annotations

import numpy as np
import pytest

import geobrep
from geobrep.gis.crs_ops import from_geodataframe, to_geodataframe
from geobrep.gis.feature_tables import FeatureWarning

geopandas = pytest.importorskip("geopandas")
shapely = pytest.importorskip("shapely")


def _scene() -> geobrep.Scene:
    points = geobrep.PointSet(
        vertices=[[450_000.125, 6_700_000.5, -10.0], [450_001.0, 6_700_002.0, -11.0]],
        point_data={"porosity": [0.1, 0.2], "facies": np.array([3, 4], dtype=np.int64)},
        name="wells",
        id=5,
    )
    outline = geobrep.Polygon.from_rings(
        [
            [450_000.0, 6_700_000.0, 0.0],
            [450_550.0, 6_700_000.0, 0.0],
            [450_550.0, 6_700_800.0, 0.0],
        ],
        name="footwall unit 1",
        kind="outline",
        metadata={"block": 9, "unit_name": "unit 1", "layer": "block_outlines"},
        id=9,
    )
    return geobrep.Scene(entities=[points, outline], crs=geobrep.CRS(epsg=32631))


def test_to_geodataframe_has_rows_columns_and_crs() -> None:
    frame = to_geodataframe(_scene())
    assert frame.crs.to_epsg() == 32631
    assert frame["layer"].tolist() == ["points", "points", "block_outlines"]
    assert frame["porosity"].iloc[:2].tolist() == [0.1, 0.2]
    assert frame["unit_name"].iloc[2] == "unit 1"
    assert int(frame["block_id"].iloc[2]) == 9
    assert frame.geometry.iloc[0].equals(shapely.Point(450_000.125, 6_700_000.5, -10.0))
    assert frame.geometry.iloc[2].area == pytest.approx(0.5 * 550 * 800)


def test_round_trip_through_a_geodataframe() -> None:
    scene = _scene()
    again = from_geodataframe(to_geodataframe(scene))
    assert again.crs is not None
    assert again.crs.epsg == 32631
    wells = again[5]
    assert isinstance(wells, geobrep.PointSet)
    assert wells.name == "wells"
    assert np.array_equal(wells.vertices, scene[5].vertices)  # type: ignore[attr-defined]
    np.testing.assert_array_equal(wells.point_data["facies"].values, [3, 4])
    outline = again[9]
    assert isinstance(outline, geobrep.Polygon)
    assert outline.metadata["block"] == 9
    assert outline.metadata["unit_name"] == "unit 1"
    assert outline.metadata["layer"] == "block_outlines"


def test_from_geodataframe_z_from_a_column_or_a_constant() -> None:
    frame = geopandas.GeoDataFrame(
        {"elevation": [12.5, -3.0], "name": ["a", "b"]},
        geometry=[shapely.Point(450_000.0, 6_700_000.0), shapely.Point(450_010.0, 6_700_000.0)],
        crs="EPSG:32631",
    )
    scene = from_geodataframe(frame, z="elevation", name="survey")
    points = scene["survey"]
    assert points.vertices[:, 2].tolist() == [12.5, -3.0]  # type: ignore[attr-defined]
    assert points.metadata["attributes"] == {"name": ["a", "b"]}
    constant = from_geodataframe(frame, z=-50.0)["layer"]  # unnamed: called after the layer
    assert constant.vertices[:, 2].tolist() == [-50.0, -50.0]  # type: ignore[attr-defined]
    with pytest.warns(FeatureWarning, match="has no z values"):
        from_geodataframe(frame)
