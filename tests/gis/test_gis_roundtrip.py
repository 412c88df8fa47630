"""Round trips through GeoPackage, GeoJSON and shapefile keep coordinates, z, attributes, CRS."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.errors import FormatError
from geobrep.gis.crs_ops import crs_from_user_input
from geobrep.gis.feature_tables import FeatureWarning
from geobrep.ops.io import read, write

pytest.importorskip("pyogrio")


def _survey_scene(crs: geobrep.CRS | None = None) -> geobrep.Scene:
    rng = np.random.default_rng(7)
    xyz = np.column_stack(
        [
            450_000.0 + rng.uniform(0, 1000, 40),
            6_700_000.0 + rng.uniform(0, 800, 40),
            rng.uniform(-300, 0, 40),
        ]
    )
    xyz[0] = [450_000.123456789012, 6_700_000.987654321098, -12.345678901234567]
    points = geobrep.PointSet(
        vertices=xyz,
        point_data={
            "depth_error": rng.uniform(0, 1, 40),
            "core": np.arange(40, dtype=np.int64) % 3,
        },
        name="markers",
        kind="survey",
        metadata={"attributes": {"well": [f"W{i % 5}" for i in range(40)]}},
    )
    trace = geobrep.PolyLine.from_point_lists(
        [
            [
                [450_100.5, 6_700_000.25, -1.5],
                [450_150.75, 6_700_400.5, -2.5],
                [450_200.0, 6_700_800.0, -3.0],
            ],
            [
                [450_300.0, 6_700_100.0, 5.0],
                [450_350.0, 6_700_100.0, 6.0],
                [450_325.0, 6_700_150.0, 7.0],
            ],
        ],
        closed=[False, True],
        name="F1 trace",
        kind="fault",
        cell_data={"throw": [80.0, 80.0, 12.5, 12.5, 12.5]},
    )
    section = geobrep.Polygon.from_polygons(
        [
            (
                [
                    [450_000.0, 6_700_000.0, -150.0],
                    [450_550.0, 6_700_000.0, -150.0],
                    [450_550.0, 6_700_800.0, -150.0],
                    [450_000.0, 6_700_800.0, -150.0],
                ],
                [
                    [
                        [450_100.0, 6_700_100.0, -150.0],
                        [450_100.0, 6_700_200.0, -150.0],
                        [450_200.0, 6_700_200.0, -150.0],
                        [450_200.0, 6_700_100.0, -150.0],
                    ]
                ],
            ),
            (
                [
                    [450_600.0, 6_700_000.0, -150.0],
                    [450_700.0, 6_700_000.0, -150.0],
                    [450_650.0, 6_700_100.0, -150.0],
                ],
                [],
            ),
        ],
        name="footwall unit 1",
        kind="section",
        metadata={"block": 9, "unit_name": "unit 1", "layer": "sections"},
        cell_data={"density": [2.45, 2.61]},
    )
    horizon_line = geobrep.PolyLine.from_point_lists(
        [[[450_000.0, 6_700_400.0, -100.0], [451_000.0, 6_700_400.0, -150.0]]],
        name="H1",
        kind="horizon",
        metadata={"layer": "sections"},
    )
    note = geobrep.Annotation(
        text="Fault F1", anchor=[450_500.0, 6_700_400.0, 10.0], baseline=[0, 1, 0], height=25.0
    )
    return geobrep.Scene(
        entities=[points, trace, section, horizon_line, note],
        crs=crs or geobrep.CRS(epsg=32631),
    )


def _same_entities(before: geobrep.Scene, after: geobrep.Scene) -> None:
    assert len(after.entities) == len(before.entities)
    for original in before.entities:
        again = after[original.id]
        assert type(again) is type(original)
        assert again.name == original.name
        assert again.kind == original.kind
        if isinstance(original, geobrep.Annotation):
            assert again.text == original.text
            assert again.height == original.height
            np.testing.assert_array_equal(again.anchor, original.anchor)
            np.testing.assert_array_equal(again.baseline, original.baseline)
            continue
        # float64 coordinates and z bit for bit
        assert again.vertices.dtype == np.float64
        assert np.array_equal(again.vertices, original.vertices)
        for field in ("point_data", "cell_data"):
            ours, theirs = getattr(original, field), getattr(again, field)
            assert set(theirs) == set(ours), field
            for name, prop in ours.items():
                np.testing.assert_array_equal(theirs[name].values, prop.values)
                assert theirs[name].values.dtype.kind == prop.values.dtype.kind
        if isinstance(original, geobrep.PolyLine):
            assert again.closed.tolist() == original.closed.tolist()
            assert again.part_offsets.tolist() == original.part_offsets.tolist()
        if isinstance(original, geobrep.Polygon):
            assert again.ring_offsets.tolist() == original.ring_offsets.tolist()
            assert again.polygon_offsets.tolist() == original.polygon_offsets.tolist()
        for key in ("block", "unit_name", "attributes", "horizon"):
            assert again.metadata.get(key) == original.metadata.get(key), key


@pytest.mark.parametrize("suffix", [".gpkg", ".geojson"])
def test_round_trip_keeps_coordinates_z_attributes_and_crs(tmp_path: Path, suffix: str) -> None:
    scene = _survey_scene()
    path = write(scene, tmp_path / f"survey{suffix}")
    again = read(path)
    _same_entities(scene, again)
    assert again.crs is not None
    assert again.crs.epsg == 32631
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"survey{suffix}"]  # nothing else


def test_geopackage_keeps_layers_and_the_whole_crs(tmp_path: Path) -> None:
    crs = crs_from_user_input("EPSG:2263+6360")  # NY Long Island ftUS + NAVD88 height ftUS
    scene = _survey_scene(crs.model_copy(update={"metadata": {"survey": "2026"}}))
    again = read(write(scene, tmp_path / "survey.gpkg"))
    assert again.crs == scene.crs
    assert again.crs.axis_units == ("ftUS", "ftUS", "ftUS")
    assert again.crs.vertical_datum == "North American Vertical Datum 1988"
    layers = {e.metadata["layer"] for e in again.entities}
    # one geometry type per layer: the mixed "sections" layer is split by geometry
    assert layers == {"points", "lines", "sections_polygons", "sections_lines", "annotations"}
    import pyogrio

    assert sorted(row[0] for row in pyogrio.list_layers(tmp_path / "survey.gpkg")) == sorted(layers)


def test_geojson_holds_a_compound_crs(tmp_path: Path) -> None:
    crs = crs_from_user_input("EPSG:2263+6360")
    again = read(write(_survey_scene(crs), tmp_path / "survey.geojson"))
    assert again.crs is not None
    assert again.crs.axis_units[2] == "ftUS"
    assert again.crs.vertical_datum == "North American Vertical Datum 1988"


def test_geojson_with_json_extension_is_sniffed(tmp_path: Path) -> None:
    write(_survey_scene(), tmp_path / "survey.geojson")
    renamed = tmp_path / "survey.json"
    (tmp_path / "survey.geojson").rename(renamed)
    again = read(renamed)
    assert again["markers"].n_points == 40


def test_shapefile_round_trip_of_one_layer(tmp_path: Path) -> None:
    scene = _survey_scene()
    with pytest.warns(FeatureWarning, match="10 characters: depth_error"):
        write(scene, tmp_path / "markers.shp", layer="points")
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["markers.cpg", "markers.dbf", "markers.prj", "markers.shp", "markers.shx"]
    again = read(tmp_path / "markers.shp")
    points = again["markers"]
    assert np.array_equal(points.vertices, scene["markers"].vertices)
    np.testing.assert_array_equal(points.point_data["core"].values, np.arange(40) % 3)
    assert again.crs is not None
    assert again.crs.epsg == 32631


def test_shapefile_refuses_several_layers(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="a shapefile holds one layer"):
        write(_survey_scene(), tmp_path / "all.shp")
    assert list(tmp_path.iterdir()) == []


def test_read_one_layer(tmp_path: Path) -> None:
    path = write(_survey_scene(), tmp_path / "survey.gpkg")
    only = read(path, layer="sections_polygons")
    assert [type(e).__name__ for e in only.entities] == ["Polygon"]
    with pytest.raises(FormatError, match="no layer 'nope'"):
        read(path, layer="nope")


def test_surfaces_are_reported_not_written(tmp_path: Path, layer_cake: geobrep.Scene) -> None:
    with pytest.raises(FormatError, match="nothing to write"), pytest.warns(FeatureWarning):
        write(layer_cake, tmp_path / "cake.gpkg")
    scene = layer_cake.with_entities(geobrep.PointSet(vertices=[[450_000.0, 6_700_000.0, 0.0]]))
    with pytest.warns(FeatureWarning, match="left out: Surface 'H1'"):
        write(scene, tmp_path / "cake.gpkg")
    assert len(read(tmp_path / "cake.gpkg").entities) == 1


def test_polyline_point_data_is_reported(tmp_path: Path) -> None:
    line = geobrep.PolyLine(vertices=[[0, 0, 0], [1, 0, 0]], point_data={"t": [1.0, 2.0]})
    scene = geobrep.Scene(entities=[line], crs=geobrep.CRS(epsg=32631))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        write(scene, tmp_path / "line.gpkg")
    assert any("not written: point_data 't'" in str(w.message) for w in caught)
