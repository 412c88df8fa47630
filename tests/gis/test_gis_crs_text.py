"""One CRS-text rule for the GIS writers and the geopandas bridge (geobrep.gis.crs_ops.crs_text)."""

from __future__ import annotations

from pathlib import Path

import pytest

import geobrep
from geobrep.gis.crs_ops import CRSError, crs_text, to_geodataframe

pyproj = pytest.importorskip("pyproj")
pytest.importorskip("geopandas")
pytest.importorskip("pyogrio")

UNREADABLE = 'FOO["not a CRS"]'


def test_crs_text_is_epsg_wkt_or_the_stored_text() -> None:
    assert crs_text(None) is None
    assert crs_text(geobrep.CRS(epsg=32631)) == "EPSG:32631"
    compound = crs_text(geobrep.CRS(epsg=32631, vertical_datum="EPSG:5773"))
    assert compound is not None
    assert pyproj.CRS.from_wkt(compound).equals(
        pyproj.CRS.from_user_input("EPSG:32631+5773"), ignore_axis_order=True
    )
    proj = "+proj=tmerc +lon_0=3 +k=0.9996 +x_0=500000 +datum=WGS84 +units=m"
    assert pyproj.CRS.from_wkt(crs_text(geobrep.CRS(proj=proj)) or "").equals(proj)
    assert crs_text(geobrep.CRS(wkt=UNREADABLE)) == UNREADABLE
    assert crs_text(geobrep.CRS(proj="+proj=nonsense")) == "+proj=nonsense"
    assert crs_text(geobrep.CRS(name="a local grid nobody knows")) is None


def _scene(crs: geobrep.CRS) -> geobrep.Scene:
    wells = geobrep.PointSet(vertices=[[1.0, 2.0, 3.0]], name="wells")
    return geobrep.Scene(entities=[wells], crs=crs)


@pytest.mark.parametrize("suffix", [".gpkg", ".geojson"])
def test_gis_writer_refuses_a_crs_it_cannot_store(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"wells{suffix}"
    with pytest.raises(geobrep.FormatError, match="Could not set CRS"):
        geobrep.write(_scene(geobrep.CRS(wkt=UNREADABLE)), path)
    assert not path.exists()


def test_gis_writer_and_geodataframe_agree_on_a_readable_crs(tmp_path: Path) -> None:
    scene = _scene(geobrep.CRS(epsg=32631))
    back = geobrep.read(geobrep.write(scene, tmp_path / "wells.gpkg"))
    assert back.crs is not None
    assert back.crs.epsg == 32631
    assert to_geodataframe(scene).crs.to_epsg() == 32631


def test_geodataframe_refuses_a_crs_it_cannot_use() -> None:
    with pytest.raises(CRSError, match="geopandas cannot use the CRS"):
        to_geodataframe(_scene(geobrep.CRS(wkt=UNREADABLE)))
