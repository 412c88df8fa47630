"""geoh5 drillholes <-> Wells: exact round trips, the geoh5py layout, geoh5's own desurveying
against analytic arcs and minimum curvature, and what is reported as lost (geoh5py itself reads
and writes drillholes in ``make geoh5-check``)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.adapters.geoh5._desurvey import desurvey, station_surveys
from geobrep.errors import FormatError
from geobrep.geometry.trajectory import minimum_curvature
from geobrep.host.capabilities import format_losses
from geobrep.model.entities import Well, WellLog, WellMarker, WellZone
from geobrep.plugins import registries

h5py = pytest.importorskip("h5py")

DRILLHOLE_TYPE = "{7CAEBF0E-D16E-11E3-BC69-E4632694AA37}"


def _well(**changes: object) -> Well:
    md = np.arange(0.0, 1801.0, 100.0)
    head = np.array([451000.0, 6701000.0, 140.0])
    stations = head + minimum_curvature(md, np.clip(md / 35.0, 0, 50), 10.0 + md / 30.0)
    rng = np.random.default_rng(11)
    fields: dict[str, object] = {
        "name": "W-2",
        "head": head,
        "vertices": stations,
        "md": md,
        "markers": [
            WellMarker(name="H1", md=300.25, surface="H1"),
            WellMarker(name="F1", md=300.25, surface="F1"),
            WellMarker(name="H2", md=1100.0),
        ],
        "zones": [
            WellZone(name="U1", top_md=300.25, base_md=1100.0),
            WellZone(name="U2", top_md=1100.0, base_md=1800.0),
            WellZone(name="U1", top_md=1500.0, base_md=1600.0),
        ],
        "logs": {
            "GR": WellLog(md=np.arange(3.0, 1797.0, 0.25), values=rng.normal(70, 12, 7176)),
            "FACIES": WellLog(
                md=np.arange(50.0, 1700.0, 10.0), values=(np.arange(165) % 5).astype(np.int32)
            ),
        },
    }
    fields.update(changes)
    return Well(**fields)  # type: ignore[arg-type]


def _round_trip(well: Well, tmp_path: Path) -> Well:
    (back,) = geobrep.read(
        geobrep.write(geobrep.Scene(entities=[well]), tmp_path / "w.geoh5")
    ).entities
    assert isinstance(back, Well)
    return back


def test_a_well_comes_back_exactly(tmp_path: Path) -> None:
    well = _well()
    back = _round_trip(well, tmp_path)
    assert back.name == well.name
    assert back.vertices.tobytes() == well.vertices.tobytes()
    assert back.md.tobytes() == well.md.tobytes()
    assert back.head.tolist() == well.head.tolist()
    assert back.markers == well.markers
    assert back.zones == well.zones
    assert list(back.logs) == list(well.logs)
    for name, log in well.logs.items():
        assert back.logs[name].md.tobytes() == log.md.tobytes()
        assert back.logs[name].values.tobytes() == log.values.tobytes()
        assert back.logs[name].values.dtype == log.values.dtype


def test_a_well_without_logs_markers_or_zones_is_its_trajectory(tmp_path: Path) -> None:
    well = _well(logs={}, markers=(), zones=())
    back = _round_trip(well, tmp_path)
    assert back.vertices.tobytes() == well.vertices.tobytes()
    assert (back.logs, back.markers, back.zones) == ({}, (), ())


def test_the_drillhole_is_laid_out_as_geoh5py_lays_it_out(tmp_path: Path) -> None:
    well = _well()
    path = geobrep.write(geobrep.Scene(entities=[well]), tmp_path / "w.geoh5")
    with h5py.File(path, "r") as store:
        (obj,) = store["GEOSCIENCE/Objects"].values()
        assert obj["Type"].attrs["ID"] == DRILLHOLE_TYPE
        collar = obj.attrs["Collar"]
        assert [collar["x"], collar["y"], collar["z"]] == well.head.tolist()
        assert obj.attrs["End of hole"] == 1800.0
        surveys = obj["Surveys"][()]
        assert surveys.dtype.names == ("Depth", "Azimuth", "Dip")
        assert surveys.dtype["Dip"] == np.float32
        assert surveys["Depth"].tolist() == well.md.tolist()
        data = {d.attrs["Name"]: d for d in obj["Data"].values()}
        depth = data["DEPTH"]["Data"][()]
        assert data["DEPTH"].attrs["Association"] == "Vertex"
        assert (np.diff(depth) >= 0).all()  # geoh5py would sort the vertices otherwise
        vertices = obj["Vertices"][()].view("<f8").reshape(-1, 3)
        np.testing.assert_allclose(vertices, well.position_at(depth), rtol=0, atol=1e-9)
        assert data["MARKER"]["Type"].attrs["Primitive type"] == "Referenced"
        names = data["MARKER"]["Type"]["Value map"][()]
        assert [n.decode() for n in names["Value"]] == ["Unknown", "H1", "F1", "H2"]
        marker_rows = np.flatnonzero(data["MARKER"]["Data"][()])
        assert depth[marker_rows].tolist() == [300.25, 300.25, 1100.0]  # one vertex each
        assert np.isnan(data["GR"]["Data"][()][marker_rows]).sum() == 0  # geoh5 no-data there
        cells = obj["Cells"][()]
        assert cells.dtype == np.uint32
        assert depth[cells].tolist() == [[300.25, 1100.0], [1100.0, 1800.0], [1500.0, 1600.0]]
        assert data["FROM"]["Data"][()].tolist() == [300.25, 1100.0, 1500.0]
        assert data["ZONE"]["Data"][()].tolist() == [1, 2, 1]


def test_geoh5_desurveys_a_constant_build_as_the_circle_it_is() -> None:
    # inclination 0 -> 90 degrees over 300 m of hole, azimuth 90: a quarter circle to the east
    length = 300.0
    radius = length / (math.pi / 2)
    md = np.linspace(0.0, length, 13)
    surveys = np.column_stack([md, np.full(13, 90.0), -90.0 + 90.0 * md / length])
    theta = md / radius
    offsets = np.column_stack([radius * (1 - np.cos(theta)), np.zeros(13), -radius * np.sin(theta)])
    circle = offsets + np.array([10.0, 20.0, 30.0])
    got = desurvey([10.0, 20.0, 30.0], surveys, length, md)
    np.testing.assert_allclose(got, circle, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        got - [10.0, 20.0, 30.0], minimum_curvature(md, 90.0 * md / length, 90.0), atol=1e-9
    )


def test_geoh5_desurveying_and_minimum_curvature_part_where_it_densifies() -> None:
    """geoh5 interpolates azimuth and dip linearly every 50 m of a long interval; minimum
    curvature follows one arc: on 200 m stations turning 60 degrees in azimuth they part."""
    md = np.array([0.0, 200.0, 400.0, 600.0])
    inclination, azimuth = np.array([0.0, 30.0, 45.0, 60.0]), np.array([0.0, 60.0, 120.0, 180.0])
    surveys = np.column_stack([md, azimuth, inclination - 90.0])
    arcs = minimum_curvature(md, inclination, azimuth)
    ours = desurvey([0.0, 0.0, 0.0], surveys, 600.0, md)
    apart = np.linalg.norm(ours - arcs, axis=1)
    assert apart[0] == 0.0
    assert 1.0 < apart.max() < 50.0  # metres: reported, not hidden
    # straight down: both methods agree to the micrometre
    vertical = np.column_stack([md, np.zeros(4), np.full(4, -90.0)])
    np.testing.assert_allclose(
        desurvey([0, 0, 0], vertical, 600.0, md)[:, 2], -md, rtol=0, atol=1e-6
    )


def test_a_drillhole_without_trace_is_where_geoh5_desurveys_it(tmp_path: Path) -> None:
    well = _well()
    path = geobrep.write(geobrep.Scene(entities=[well]), tmp_path / "w.geoh5")
    with h5py.File(path, "r+") as store:
        (obj,) = store["GEOSCIENCE/Objects"].values()
        del obj["Trace"], obj["TraceDepth"]
    (back,) = geobrep.read(path).entities
    assert isinstance(back, Well)
    rows = station_surveys(well.vertices, well.md)
    table = np.column_stack([rows[k] for k in ("Depth", "Azimuth", "Dip")]).astype(np.float64)
    assert back.md.tolist() == well.md.tolist()
    np.testing.assert_array_equal(back.vertices, desurvey(well.head, table, 1800.0, well.md))
    # as far from the stations as the loss report says
    lost = format_losses(geobrep.Scene(entities=[well]), registries().formats.get("geoh5"), path)
    (said,) = [line for line in lost if "desurveys" in line]
    metres = float(re.search(r"within ([0-9.e+-]+) m", said).group(1))  # type: ignore[union-attr]
    apart = np.linalg.norm(back.vertices - well.vertices, axis=1).max()
    assert 0.0 < apart <= metres * 1.001
    assert back.markers == well.markers
    assert back.zones == well.zones


def test_what_a_drillhole_cannot_hold_is_reported(tmp_path: Path) -> None:
    gr = np.r_[np.nan, np.arange(9.0)]
    well = _well(
        datum="KB",
        datum_elevation=140.0,
        logs={"GR": WellLog(md=np.arange(10.0, 20.0), values=gr, unit="gAPI")},
        markers=[WellMarker(name="b", md=900.0), WellMarker(name="a", md=400.0, metadata={"q": 1})],
    )
    lost = " | ".join(
        format_losses(
            geobrep.Scene(entities=[well]), registries().formats.get("geoh5"), tmp_path / "w"
        )
    )
    for expected in (
        "Well 'W-2': datum 'KB' at 140.0 dropped",
        "Well 'W-2' log 'GR': unit, no-data value and metadata dropped",
        "Well 'W-2' log 'GR': 1 NaN samples dropped",
        "Well 'W-2': metadata of markers and zones dropped",
        "Well 'W-2': markers read back in MD order",
        "Well 'W-2': geoh5 desurveys its float32 surveys to within",
    ):
        assert expected in lost
    back = _round_trip(well, tmp_path)
    assert back.logs["GR"].values.tolist() == list(range(9))
    assert [m.name for m in back.markers] == ["a", "b"]


def test_logs_below_the_stations_sit_where_geoh5_extends_the_hole(tmp_path: Path) -> None:
    well = _well(logs={"GR": WellLog(md=np.array([1700.0, 1900.0]), values=np.array([1.0, 2.0]))})
    path = geobrep.write(geobrep.Scene(entities=[well]), tmp_path / "w.geoh5")
    with h5py.File(path, "r") as store:
        (obj,) = store["GEOSCIENCE/Objects"].values()
        vertices = obj["Vertices"][()].view("<f8").reshape(-1, 3)
    assert np.isfinite(vertices).all()
    # 100 m past the last station, on along the hole's last direction (geoh5's "straight" is
    # an arc of radius 99,999.9 m: 100 m of it is a chord 17 micrometres shorter)
    last = well.vertices[-1] - well.vertices[-2]
    ahead = vertices[-1] - well.vertices[-1]
    assert abs(np.linalg.norm(ahead) - 100.0) < 2e-5
    assert np.dot(ahead, last) / (np.linalg.norm(ahead) * np.linalg.norm(last)) > 0.999
    assert _round_trip(well, tmp_path).logs["GR"].md.tolist() == [1700.0, 1900.0]


def test_a_log_named_as_the_layout_is_refused(tmp_path: Path) -> None:
    well = _well(logs={"depth": WellLog(md=np.array([10.0]), values=np.array([1.0]))})
    with pytest.raises(FormatError, match=r"'depth'.*rename the log"):
        geobrep.write(geobrep.Scene(entities=[well]), tmp_path / "w.geoh5")
