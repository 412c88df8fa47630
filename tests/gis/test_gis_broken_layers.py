"""Broken geometries, missing z and unknown CRSs: clear warnings, and the valid features load."""

from __future__ import annotations

import json
import sqlite3
import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.errors import OptionsError
from geobrep.gis.feature_tables import FeatureWarning
from geobrep.ops.io import read, write

pytest.importorskip("pyogrio")

CRS_32631 = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32631"}}


def _feature(geometry: object, **properties: object) -> dict[str, object]:
    return {"type": "Feature", "properties": properties, "geometry": geometry}


def _geojson(path: Path, features: list[dict[str, object]], crs: object = CRS_32631) -> Path:
    collection: dict[str, object] = {"type": "FeatureCollection", "features": features}
    if crs is not None:
        collection = {"type": "FeatureCollection", "crs": crs, "features": features}
    path.write_text(json.dumps(collection))
    return path


def _messages(caught: list[warnings.WarningMessage]) -> str:
    return "\n".join(str(w.message) for w in caught if issubclass(w.category, FeatureWarning))


def test_broken_features_are_named_and_skipped(tmp_path: Path) -> None:
    point = {"type": "Point", "coordinates": [450_000.5, 6_700_000.25, -10.0]}
    features = [
        _feature(point, name="good", depth=1.0),
        _feature(None, name="empty-handed", depth=2.0),
        _feature({"type": "LineString", "coordinates": [[1.0, 2.0, 3.0]]}, name="stub", depth=3.0),
        _feature(
            {"type": "Polygon", "coordinates": [[[0, 0, 0], [1, 0, 0], [0, 0, 0]]]},
            name="sliver",
            depth=4.0,
        ),
        _feature(
            {"type": "Point", "coordinates": [450_001.0, 6_700_001.0]}, name="flat", depth=5.0
        ),
        _feature(
            {"type": "Point", "coordinates": [450_002.0, 6_700_002.0, -12.0]},
            name="good2",
            depth=6.0,
        ),
    ]
    path = _geojson(tmp_path / "wells.geojson", features)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = read(path)
    text = _messages(caught)
    assert "layer 'wells': feature 1 ('empty-handed'): no geometry" in text
    assert "feature 2 ('stub'): broken geometry" in text
    assert "feature 3 ('sliver'): a polygon ring needs at least 3 points" in text
    assert "feature 4 ('flat'): missing z (the other features have z)" in text
    # the valid features still load, with their attributes
    (points,) = scene.point_sets
    np.testing.assert_array_equal(
        points.vertices, [[450_000.5, 6_700_000.25, -10.0], [450_002.0, 6_700_002.0, -12.0]]
    )
    np.testing.assert_array_equal(points.point_data["depth"].values, [1.0, 6.0])
    assert points.metadata["attributes"] == {"name": ["good", "good2"]}
    assert scene.crs is not None
    assert scene.crs.epsg == 32631


def test_unreadable_geopackage_geometry_is_named(tmp_path: Path) -> None:
    wells = geobrep.PointSet(
        vertices=np.arange(12.0).reshape(4, 3) + np.array([450_000.0, 6_700_000.0, 0.0]),
        point_data={"v": [1.0, 2.0, 3.0, 4.0]},
        name="wells",
    )
    path = write(geobrep.Scene(entities=[wells], crs=geobrep.CRS(epsg=32631)), tmp_path / "w.gpkg")
    with sqlite3.connect(path) as db:  # corrupt feature 2's geometry blob
        for (name,) in db.execute("select name from sqlite_master where type='trigger'").fetchall():
            db.execute(f'drop trigger "{name}"')
        db.execute("update points set geom = X'47500001777F000001E9030000' where fid = 2")
    with pytest.warns(FeatureWarning, match=r"layer 'points': feature 2 \('wells'\): no geometry"):
        scene = read(path)
    np.testing.assert_array_equal(scene["wells"].point_data["v"].values, [1.0, 3.0, 4.0])


def test_missing_z_from_a_column_or_a_constant(tmp_path: Path) -> None:
    features = [
        _feature({"type": "Point", "coordinates": [450_000.0, 6_700_000.0]}, z_m=-5.0),
        _feature({"type": "Point", "coordinates": [450_010.0, 6_700_000.0]}, z_m=None),
        _feature({"type": "Point", "coordinates": [450_020.0, 6_700_000.0]}, z_m=-7.5),
    ]
    path = _geojson(tmp_path / "flat.geojson", features)
    with pytest.warns(FeatureWarning, match=r"feature 1: no z and no value in column 'z_m'"):
        from_column = read(path, z_field="z_m")
    np.testing.assert_array_equal(from_column.point_sets[0].vertices[:, 2], [-5.0, -7.5])
    constant = read(path, z_default=-100.0)
    np.testing.assert_array_equal(constant.point_sets[0].vertices[:, 2], [-100.0] * 3)
    with pytest.warns(FeatureWarning, match="layer 'flat' has no z values: z = 0"):
        zero = read(path)
    np.testing.assert_array_equal(zero.point_sets[0].vertices[:, 2], [0.0] * 3)
    with pytest.raises(OptionsError, match="z_field 'depth' is not a column"):
        read(path, z_field="depth")


def test_unknown_and_missing_crs_warn(tmp_path: Path) -> None:
    point = _feature({"type": "Point", "coordinates": [1.0, 2.0, 3.0]}, a=1)
    unknown = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::999999"}}
    path = _geojson(tmp_path / "odd.geojson", [point], crs=unknown)
    with pytest.warns(FeatureWarning, match="the CRS 'urn:ogc:def:crs:EPSG::999999' is unknown"):
        scene = read(path)
    assert scene.crs is None
    assert scene.point_sets[0].n_points == 1
    bare = geobrep.Scene(entities=[geobrep.PointSet(vertices=[[1.0, 2.0, 3.0]], name="p")])
    with pytest.warns(FeatureWarning, match="the scene has no CRS"):
        write(bare, tmp_path / "bare.shp")
    with pytest.warns(FeatureWarning, match=r"layer\(s\) 'bare' have no CRS"):
        again = read(tmp_path / "bare.shp")
    assert again.crs is None
    assert again["p"].vertices.tolist() == [[1.0, 2.0, 3.0]]


def test_layers_with_different_crs_are_refused(tmp_path: Path) -> None:
    import pyogrio.raw
    import shapely

    path = tmp_path / "two.gpkg"
    geometry = shapely.to_wkb(np.array([shapely.Point(1.0, 2.0, 3.0)]))
    pyogrio.raw.write(
        path,
        geometry,
        [np.array([1])],
        ["a"],
        layer="a",
        crs="EPSG:32631",
        driver="GPKG",
        geometry_type="Point Z",
    )
    pyogrio.raw.write(
        path,
        geometry,
        [np.array([1])],
        ["a"],
        layer="b",
        crs="EPSG:4326",
        append=True,
        driver="GPKG",
        geometry_type="Point Z",
    )
    with pytest.raises(geobrep.FormatError, match="layers have different CRSs"):
        read(path)
    assert read(path, layer="b").crs.epsg == 4326  # type: ignore[union-attr]
