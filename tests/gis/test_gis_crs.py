"""CRS parsing and reprojection against direct pyproj.Transformer results."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.cli.main import main
from geobrep.gis.crs_ops import CRSError, crs_from_user_input, describe_crs, parse_crs, to_crs
from geobrep.ops.io import read, write

pyproj = pytest.importorskip("pyproj")

#: NAD83 / New York Long Island (US survey feet) + NAVD88 height (US survey feet).
NY_FEET = "EPSG:2263+6360"
#: WGS 84 / UTM 18N + NAVD88 height (metres).
UTM_METRES = "EPSG:32618+5703"


def _ny_scene() -> geobrep.Scene:
    rng = np.random.default_rng(3)
    xyz = np.column_stack(
        [
            980_000.0 + rng.uniform(0, 5000, 200),
            190_000.0 + rng.uniform(0, 5000, 200),
            rng.uniform(-2000, 300, 200),
        ]
    )
    points = geobrep.PointSet(
        vertices=xyz, point_data={"gr": rng.uniform(0, 150, 200)}, name="logs"
    )
    surface = geobrep.Surface(
        vertices=xyz[:4], faces=[[0, 1, 2], [0, 2, 3]], name="top", kind="horizon"
    )
    return geobrep.Scene(entities=[points, surface], crs=crs_from_user_input(NY_FEET))


def test_parse_epsg_wkt_and_proj() -> None:
    utm = parse_crs("EPSG:32631")
    assert parse_crs(32631) == utm
    assert parse_crs(utm.to_wkt()) == utm
    assert parse_crs(geobrep.CRS(epsg=32631)) == utm
    assert parse_crs("+proj=utm +zone=31 +datum=WGS84 +units=m +no_defs").is_projected
    crs = crs_from_user_input(NY_FEET)
    assert crs.axis_units == ("ftUS", "ftUS", "ftUS")
    assert crs.z_positive == "up"
    assert crs.vertical_datum == "North American Vertical Datum 1988"
    assert crs_from_user_input("EPSG:4326").axis_names[:2] == ("Lon", "Lat")  # x first
    info = describe_crs(crs)
    assert info["vertical_units"] == "US survey foot"


def test_invalid_crs_is_a_clear_error() -> None:
    with pytest.raises(CRSError, match="EPSG code 'EPSG:999999' is not a valid CRS"):
        parse_crs(geobrep.CRS(epsg=999999))
    with pytest.raises(CRSError, match="is not a valid CRS"):
        parse_crs("+proj=nonsense")
    with pytest.raises(CRSError, match="the CRS is unknown"):
        parse_crs(geobrep.CRS())


def test_reprojection_matches_pyproj_with_a_vertical_unit_change() -> None:
    scene = _ny_scene()
    moved = to_crs(scene, UTM_METRES)
    direct = pyproj.Transformer.from_crs(NY_FEET, UTM_METRES, always_xy=True)
    original = scene["logs"].vertices
    expected = np.column_stack(direct.transform(original[:, 0], original[:, 1], original[:, 2]))
    got = moved["logs"].vertices
    assert np.abs(got - expected).max() <= 1e-3
    # the vertical unit really changed: US survey feet to metres
    np.testing.assert_allclose(got[:, 2], original[:, 2] * 1200 / 3937, rtol=0, atol=1e-6)
    # properties, ids, names kept
    assert moved["logs"].id == scene["logs"].id
    np.testing.assert_array_equal(
        moved["logs"].point_data["gr"].values, scene["logs"].point_data["gr"].values
    )
    assert moved.crs is not None
    assert moved.crs.axis_units == ("m", "m", "m")
    back = to_crs(moved, NY_FEET)
    assert np.abs(back["logs"].vertices - original).max() <= 1e-3
    assert np.abs(back["top"].vertices - scene["top"].vertices).max() <= 1e-3


def test_two_d_crs_with_vertical_units_in_feet() -> None:
    points = geobrep.PointSet(vertices=[[450_000.0, 6_700_000.0, -1000.0]], name="p")
    crs = geobrep.CRS(epsg=32631, axis_units=("m", "m", "ft"))
    moved = to_crs(geobrep.Scene(entities=[points], crs=crs), "EPSG:32632")
    direct = pyproj.Transformer.from_crs(32631, 32632, always_xy=True)
    x, y = direct.transform(450_000.0, 6_700_000.0)
    np.testing.assert_allclose(moved["p"].vertices[0], [x, y, -304.8], rtol=0, atol=1e-6)


def test_layer_cake_keeps_topology_and_comes_back(layer_cake: geobrep.Scene) -> None:
    lonlat = to_crs(layer_cake, "EPSG:4326")
    assert lonlat.topology == layer_cake.topology
    assert [b.sides for b in lonlat.blocks] == [b.sides for b in layer_cake.blocks]
    fault = lonlat["fault"]
    assert 2.0 < fault.vertices[:, 0].min() < 3.0
    assert 60.0 < fault.vertices[:, 1].min() < 61.0
    back = to_crs(lonlat, "EPSG:32631")
    for before, after in zip(layer_cake.surfaces, back.surfaces, strict=True):
        assert np.abs(after.vertices - before.vertices).max() < 1e-3
    assert back.block_mesh(back.blocks[0]).volume == pytest.approx(
        layer_cake.block_mesh(layer_cake.blocks[0]).volume, rel=1e-9
    )


def test_unknown_source_crs_is_refused(layer_cake: geobrep.Scene) -> None:
    with pytest.raises(CRSError, match="the scene's CRS is unknown"):
        to_crs(layer_cake.replace(crs=None), "EPSG:4326")
    with pytest.raises(CRSError, match="source CRS"):
        to_crs(layer_cake.replace(crs=geobrep.CRS(name="local grid")), "EPSG:4326")
    moved = to_crs(layer_cake.replace(crs=None), "EPSG:32632", source="EPSG:32631")
    assert moved.crs is not None
    assert moved.crs.epsg == 32632


def test_points_outside_the_projection_are_named() -> None:
    points = geobrep.PointSet(vertices=[[0.0, 0.0, 0.0], [1e12, 1e12, 0.0]], name="far")
    scene = geobrep.Scene(entities=[points], crs=geobrep.CRS(epsg=32631))
    with pytest.raises(CRSError, match="PointSet 'far': 1 point"):
        to_crs(scene, "EPSG:4326")


def test_mirroring_targets_are_refused() -> None:
    points = geobrep.PointSet(vertices=[[450_000.0, 6_700_000.0, 0.0]], name="p")
    scene = geobrep.Scene(entities=[points], crs=geobrep.CRS(epsg=32631))
    mirrored = "+proj=utm +zone=31 +datum=WGS84 +axis=wnu"
    with pytest.raises(CRSError, match="mirrors the map"):
        to_crs(scene, mirrored)


def test_scene_to_crs_method(layer_cake: geobrep.Scene) -> None:
    moved = layer_cake.to_crs("EPSG:32632")
    assert moved.crs is not None
    assert moved.crs.epsg == 32632


def test_cli_reproject_and_info(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = write(_ny_scene(), tmp_path / "ny.geobrep")
    assert main(["reproject", str(source), str(tmp_path / "utm.geobrep"), "--to", UTM_METRES]) == 0
    moved = read(tmp_path / "utm.geobrep")
    assert moved.crs is not None
    assert moved.crs.axis_units[2] == "m"
    assert main(["info", str(tmp_path / "utm.geobrep")]) == 0
    out = capsys.readouterr().out
    assert "WGS 84 / UTM zone 18N + NAVD88 height" in out
    assert "vertical datum North American Vertical Datum 1988" in out
    unknown = write(geobrep.PointSet(vertices=[[0.0, 0.0, 0.0]]), tmp_path / "bare.geobrep")
    assert main(["reproject", str(unknown), str(tmp_path / "x.geobrep"), "--to", "EPSG:4326"]) == 1
    assert "CRS is unknown" in capsys.readouterr().err
