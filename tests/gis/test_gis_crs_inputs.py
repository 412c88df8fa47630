"""Every place that takes a CRS accepts what ``pyproj.CRS.from_user_input`` accepts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.cli.main import main
from geobrep.gis.crs_ops import CRSError, from_geodataframe, to_crs, to_geodataframe

pyproj = pytest.importorskip("pyproj")

UTM33 = pyproj.CRS.from_epsg(32633)


class _HasWkt:
    """A CRS object of another library (rasterio, ...): it only offers its WKT."""

    def to_wkt(self) -> str:
        return str(UTM33.to_wkt())


@pytest.mark.parametrize(
    "value",
    [
        "EPSG:32633",
        "epsg:32633",
        32633,
        "32633",
        ("EPSG", 32633),
        ("EPSG", "32633"),
        UTM33,
        UTM33.to_wkt(),
        UTM33.to_json_dict(),
        "urn:ogc:def:crs:EPSG::32633",
        _HasWkt(),
    ],
    ids=repr,
)
def test_scene_takes_every_pyproj_input(value: object) -> None:
    scene = geobrep.Scene(crs=value)
    assert scene.crs is not None
    assert scene.crs.epsg == 32633  # what pyproj says the input is
    assert pyproj.CRS.from_user_input(scene.crs.label).equals(UTM33)
    again = geobrep.Scene().replace(crs=value)
    assert again.crs is not None
    assert again.crs.epsg == 32633


def test_proj_strings_and_compound_crs_keep_what_pyproj_reads() -> None:
    proj = "+proj=tmerc +lat_0=0 +lon_0=15 +k=0.9996 +x_0=500000 +datum=WGS84 +units=m"
    scene = geobrep.Scene(crs=proj)
    assert scene.crs is not None
    assert scene.crs.wkt is not None
    assert pyproj.CRS.from_wkt(scene.crs.wkt).equals(pyproj.CRS.from_user_input(proj))
    feet = geobrep.Scene(crs="EPSG:2263+6360").crs
    assert feet is not None
    assert feet.axis_units == ("ftUS", "ftUS", "ftUS")
    assert feet.vertical_datum == "North American Vertical Datum 1988"


@pytest.mark.parametrize(
    ("value", "named"),
    [
        ("EPSG:999999+5703", "EPSG:999999+5703"),
        ("+proj=nonsense", "+proj=nonsense"),
        ("not a crs", "not a crs"),
        (("EPSG", "x"), "EPSG"),
        (-5, "-5"),
        (2.5, "2.5"),
        ("", "empty string"),
    ],
)
def test_an_invalid_crs_is_a_geobrep_error_naming_it(value: object, named: str) -> None:
    with pytest.raises(CRSError, match="not a") as caught:
        geobrep.Scene(crs=value)
    assert named in str(caught.value)
    assert isinstance(caught.value, geobrep.GeobrepError)
    assert isinstance(caught.value, ValueError)


def test_an_unknown_epsg_code_is_refused_where_it_is_used(layer_cake: geobrep.Scene) -> None:
    """A bare EPSG code is taken without pyproj; pyproj judges it when it is first used."""
    unknown = layer_cake.replace(crs="EPSG:999999")
    assert unknown.crs == geobrep.CRS(epsg=999999)
    with pytest.raises(CRSError, match="source CRS: EPSG code 'EPSG:999999' is not a valid CRS"):
        unknown.to_crs(4326)


def test_an_epsg_code_is_read_without_pyproj() -> None:
    """No pyproj for ``EPSG:xxxx`` or an int: checked in a fresh interpreter."""
    import subprocess
    import sys

    probe = (
        "import sys, geobrep\n"
        "a = geobrep.Scene(crs='EPSG:32633').crs\n"
        "b = geobrep.Scene(crs=32633).crs\n"
        "c = geobrep.Scene(crs=('EPSG', 32633)).crs\n"
        "assert a == b == c == geobrep.CRS(epsg=32633), (a, b, c)\n"
        "print('pyproj' in sys.modules)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120
    )
    assert result.stdout.strip() == "False"


def test_to_crs_takes_every_pyproj_input(layer_cake: geobrep.Scene) -> None:
    expected = to_crs(layer_cake, "EPSG:32632")
    for target in (32632, ("EPSG", 32632), pyproj.CRS.from_epsg(32632), "EPSG:32632"):
        moved = layer_cake.to_crs(target)
        assert moved.crs is not None
        assert moved.crs.epsg == 32632
        assert np.array_equal(moved["top"].vertices, expected["top"].vertices)
    bare = layer_cake.replace(crs=None)
    back = to_crs(bare, 32632, source=pyproj.CRS.from_epsg(32631))
    assert np.array_equal(back["top"].vertices, expected["top"].vertices)
    with pytest.raises(CRSError, match="target CRS: CRS 'EPSG:999999' is not a valid CRS"):
        layer_cake.to_crs("EPSG:999999")


def test_reproject_cli_and_pipeline_take_a_bare_epsg_code(
    tmp_path: Path, layer_cake: geobrep.Scene
) -> None:
    source = geobrep.write(layer_cake, tmp_path / "cake.geobrep")
    expected = to_crs(layer_cake, "EPSG:32632")["top"].vertices
    assert main(["reproject", str(source), str(tmp_path / "cli.geobrep"), "--to", "32632"]) == 0
    assert np.array_equal(geobrep.read(tmp_path / "cli.geobrep")["top"].vertices, expected)
    steps = [{"reproject": {"to": 32632}}, {"write": {"format": "native"}}]
    summary = run_pipeline({"steps": steps}, inputs=[source], output=tmp_path / "out")
    assert summary.ok, summary.table()
    moved = geobrep.read(tmp_path / "out" / "cake.geobrep")
    assert moved.crs is not None
    assert moved.crs.epsg == 32632
    assert np.array_equal(moved["top"].vertices, expected)


def test_geodataframe_bridge_takes_any_crs_input() -> None:
    points = geobrep.PointSet(vertices=[[500_000.0, 6_000_000.0, 1.0]], name="p")
    frame = to_geodataframe(points, crs=32633)
    assert frame.crs.equals(UTM33)
    assert from_geodataframe(frame).crs == geobrep.Scene(crs=UTM33).crs
