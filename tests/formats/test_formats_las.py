"""LAS 2.0 / 3.0 well logs through lasio: two hand-written files read value by value, logs put on
a deviated well (attach_las), exact round trips, logs on different depths, and FormatErrors."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import FormatError, Scene, Well, WellLog
from geobrep.adapters.wells import attach_las
from geobrep.geometry.trajectory import minimum_curvature

pytest.importorskip("lasio")

DATA = Path(__file__).resolve().parent.parent / "data" / "wells"


def test_an_upward_las2_file_reads_on_increasing_depth() -> None:
    (well,) = geobrep.read(DATA / "upward_las2.las").wells
    assert well.name == "ANY ET AL 12-34-12-34"
    np.testing.assert_array_equal(well.head, [451234.5, 6701234.0, 123.4])
    assert (well.datum, well.datum_elevation) == ("KB", 123.4)
    dt, rhob = well.logs["DT"], well.logs["RHOB"]
    # rows 1670.000 .. 1669.500 (logged upwards), turned to increasing depth
    np.testing.assert_array_equal(dt.md, [1669.5, 1669.625, 1669.75, 1669.875, 1670.0])
    np.testing.assert_array_equal(dt.values, [123.45, -999.25, 123.45, 123.45, 123.45])
    np.testing.assert_array_equal(rhob.values, [2550.0, 2550.0, 2550.0, -999.25, 2550.0])
    assert (dt.unit, dt.no_data_value) == ("US/M", -999.25)
    assert dt.metadata["las"]["description"] == "2  SONIC TRANSIT TIME"
    assert well.metadata["las"] == {"version": "2.0", "md_unit": "M"}


def test_a_comma_delimited_las3_file() -> None:
    (well,) = geobrep.read(DATA / "comma_las3.las").wells
    assert well.name == "LAS3 TEST WELL"
    assert set(well.logs) == {"GR", "NPHI"}
    np.testing.assert_array_equal(well.logs["GR"].md, [1500.0, 1500.5, 1501.0])
    np.testing.assert_array_equal(well.logs["GR"].values, [55.1, -999.25, 57.3])
    np.testing.assert_array_equal(well.logs["NPHI"].values, [0.25, 0.26, 0.27])
    assert well.metadata["las"]["version"] == "3.0"


def deviated_well() -> Well:
    md = np.arange(0.0, 2001.0, 100.0)
    xyz = np.array([1000.0, 2000.0, 150.0]) + minimum_curvature(
        md, np.clip(md / 40.0, 0.0, 45.0), np.full(md.shape, 30.0)
    )
    return Well(name="W-7", head=xyz[0], vertices=xyz, md=md, datum="KB", datum_elevation=150.0)


def test_logs_attached_to_a_deviated_well_sit_on_its_trajectory() -> None:
    well = attach_las(deviated_well(), DATA / "upward_las2.las")
    log = well.logs["DT"]
    positions = well.position_at(log.md)
    assert np.isfinite(positions).all()
    # 1669.5 .. 1670 m lie between the stations at MD 1600 and 1700, where position_at follows
    # the chord: samples 0.125 m of MD apart are 0.125 x chord / 100 m apart in space
    chord = np.linalg.norm(well.vertices[17] - well.vertices[16])
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    np.testing.assert_allclose(steps, 0.125 * chord / 100.0, rtol=1e-9)
    assert chord < 100.0  # the hole curves there


def _write(scene: Scene, path: Path) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.write(scene, path)


@pytest.mark.parametrize("name", ["upward_las2.las", "comma_las3.las"])
def test_read_write_read_is_exact(tmp_path: Path, name: str) -> None:
    first = geobrep.read(DATA / name)
    again = geobrep.read(_write(first, tmp_path / name))
    (one,), (two,) = first.wells, again.wells
    assert (one.name, one.datum, one.datum_elevation) == (two.name, two.datum, two.datum_elevation)
    np.testing.assert_array_equal(one.head, two.head)
    assert set(one.logs) == set(two.logs)
    for key, log in one.logs.items():
        np.testing.assert_array_equal(log.md, two.logs[key].md)
        np.testing.assert_array_equal(log.values, two.logs[key].values)
        assert (log.unit, log.no_data_value) == (two.logs[key].unit, two.logs[key].no_data_value)


def test_generated_logs_keep_every_float64_bit(tmp_path: Path) -> None:
    md = np.linspace(1000.0, 1003.0, 31) + 1e-9
    values = np.sin(md) * 1e5 + np.pi
    well = deviated_well().replace(logs={"SYN": WellLog(md=md, values=values, unit="ohm.m")})
    (back,) = geobrep.read(_write(Scene(entities=[well]), tmp_path / "syn.las")).wells
    np.testing.assert_array_equal(back.logs["SYN"].md, md)
    np.testing.assert_array_equal(back.logs["SYN"].values, values)
    # the stations come back from ~Other, the head from X / Y / ZHEAD
    np.testing.assert_array_equal(back.vertices, well.vertices)
    np.testing.assert_array_equal(back.md, well.md)
    np.testing.assert_array_equal(back.head, well.head)
    assert (back.datum, back.datum_elevation) == ("KB", 150.0)


def test_logs_on_different_depths_share_one_nulled_index(tmp_path: Path) -> None:
    well = deviated_well().replace(
        logs={
            "A": WellLog(md=[10.0, 20.0, 30.0], values=[1.0, 2.0, 3.0], no_data_value=-999.25),
            "B": WellLog(md=[15.0, 20.0], values=[7.5, 8.5], no_data_value=-999.25),
        }
    )
    with pytest.warns(UserWarning, match="share one index"):
        path = geobrep.write(Scene(entities=[well]), tmp_path / "two.las")
    (back,) = geobrep.read(path).wells
    np.testing.assert_array_equal(back.logs["A"].md, [10.0, 15.0, 20.0, 30.0])
    np.testing.assert_array_equal(back.logs["A"].values, [1.0, -999.25, 2.0, 3.0])
    np.testing.assert_array_equal(back.logs["B"].values, [-999.25, 7.5, 8.5, -999.25])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("~V\nVERS. 2.0:\nWRAP. NO:\n~W\nNULL. -999.25:\n~A\n", "no curves"),
        ("~V\nVERS. 2.0:\n~C\nTIME.S :\nGR.API :\n~A\n1 2\n", "not a depth index"),
        (
            "~V\nVERS. 2.0:\n~W\nNULL. -999.25:\n~C\nDEPT.M :\nGR.API :\n~A\n-999.25 2\n1 2\n",
            "null",
        ),
    ],
)
def test_bad_las_files_are_format_errors(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.las"
    path.write_text(text)
    with pytest.raises(FormatError, match=message):
        geobrep.read(path)
