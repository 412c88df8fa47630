"""A shapefile set is replaced whole: the old .shp goes first, the new one comes last."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.errors import FormatError
from geobrep.ops.io import read, write

pytest.importorskip("pyogrio")

from geobrep.adapters.gis import _formats as gis_formats


def markers(n: int, crs: str | None = "EPSG:32631") -> geobrep.Scene:
    points = geobrep.PointSet(name="markers", vertices=np.arange(3.0 * n).reshape(n, 3))
    return geobrep.Scene(entities=[points], crs=geobrep.CRS(epsg=32631) if crs else None)


def quiet_write(scene: geobrep.Scene, path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        write(scene, path)


def test_a_rewrite_leaves_exactly_the_new_set(tmp_path: Path) -> None:
    target = tmp_path / "markers.shp"
    quiet_write(markers(5), target)
    (tmp_path / "markers.qix").write_bytes(b"a spatial index of the old geometry")
    quiet_write(markers(8, crs=None), target)  # no CRS: no .prj in the new set
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "markers.cpg",
        "markers.dbf",
        "markers.shp",
        "markers.shx",
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        again = read(target)
    assert again.crs is None  # the old .prj would have claimed EPSG:32631
    assert len(again.entities[0].vertices) == 8


def test_the_old_shp_goes_first_and_the_new_one_comes_last(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "markers.shp"
    quiet_write(markers(5), target)
    moves: list[tuple[str, str]] = []
    real_replace = os.replace

    def recording(source: str | Path, destination: str | Path) -> None:
        moves.append((Path(source).name, Path(destination).name))
        real_replace(source, destination)

    monkeypatch.setattr(os, "replace", recording)
    quiet_write(markers(8), target)
    assert moves[0] == ("markers.shp", "replaced.shp")  # no .shp while sidecars change
    assert moves[-1][1] == "markers.shp"  # atomic_write renames the new .shp in last
    sidecars = [destination for _, destination in moves[1:-2]]
    assert sorted(sidecars) == ["markers.cpg", "markers.dbf", "markers.prj", "markers.shx"]
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a_mixed_set_is_refused(tmp_path: Path) -> None:
    quiet_write(markers(5), tmp_path / "five.shp")
    quiet_write(markers(8), tmp_path / "eight.shp")
    (tmp_path / "eight.dbf").replace(tmp_path / "five.dbf")  # 8 attribute rows for 5 points
    with pytest.raises(FormatError, match=r"five\.dbf: 8 records\): a mix of two writes"):
        read(tmp_path / "five.shp")
    gis_formats.check_shapefile_set(tmp_path / "eight.shp")  # missing .dbf: left to GDAL
