"""geoh5 drillhole groups (drillholes concatenated, geoh5 2.0 and 2.1) read as Wells.

The file in tests/data/geoh5 was written by geoh5py in its own venv (tests/data/geoh5/SOURCES.md)
beside what geoh5py says it holds; geobrep's Wells must equal that array by array. The damaged
copies are edited with h5py."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import geobrep
from geobrep.errors import FormatError
from geobrep.host.capabilities import SKIPPED_ON_READ, format_losses
from geobrep.model.entities import Well
from geobrep.plugins import registries

h5py = pytest.importorskip("h5py")

DATA = Path(__file__).parent.parent / "data" / "geoh5"
FILE = DATA / "geoh5py_drillhole_group.geoh5"
HOLES = ("DH-1", "DH-2", "DH-3")


@pytest.fixture(scope="module")
def expected() -> Any:
    return np.load(DATA / "geoh5py_drillhole_group.npz")


@pytest.fixture(scope="module")
def scene() -> geobrep.Scene:
    return geobrep.read(FILE)


def _copy(tmp_path: Path) -> Path:
    target = tmp_path / "group.geoh5"
    shutil.copyfile(FILE, target)
    return target


def _concatenated(store: Any) -> Any:
    groups = store["GEOSCIENCE/Groups"].values()
    return next(g for g in groups if "Concatenated Data" in g)["Concatenated Data"]


def _records(concat: Any) -> list[dict[str, Any]]:
    return [json.loads(r) for r in concat["Attributes Jsons"].asstr()[()]]


def _set_records(concat: Any, records: list[dict[str, Any]]) -> None:
    del concat["Attributes Jsons"]
    concat.create_dataset(
        "Attributes Jsons",
        data=np.array([json.dumps(r) for r in records], dtype=object),
        dtype=h5py.string_dtype(),
    )


def test_the_file_is_a_concatenated_group() -> None:
    with h5py.File(FILE, "r") as store:
        assert float(store["GEOSCIENCE"].attrs["Version"]) == pytest.approx(2.1)
        assert len(store["GEOSCIENCE/Objects"]) == 0  # no drillhole has a group of its own
        concat = _concatenated(store)
        assert concat["Index/Surveys"].shape == (3,)


def test_every_drillhole_is_a_well(scene: geobrep.Scene) -> None:
    assert [e.name for e in scene.entities] == list(HOLES)
    assert all(isinstance(e, Well) for e in scene.entities)
    assert [e.id for e in scene.entities] == [0, 1, 2]
    assert SKIPPED_ON_READ not in scene.metadata


@pytest.mark.parametrize("name", HOLES)
def test_trajectory_equals_geoh5py(scene: geobrep.Scene, expected: Any, name: str) -> None:
    well = scene[name]
    np.testing.assert_array_equal(well.head, expected[f"{name}|collar"])
    np.testing.assert_array_equal(well.md, expected[f"{name}|md"])
    np.testing.assert_allclose(well.vertices, expected[f"{name}|stations"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(well.vertices[0], well.head)


@pytest.mark.parametrize("name", HOLES)
def test_logs_markers_zones_equal_geoh5py(scene: geobrep.Scene, expected: Any, name: str) -> None:
    well = scene[name]
    logs = sorted({k.split("|")[2] for k in expected.files if k.startswith(f"{name}|log|")})
    assert sorted(well.logs) == logs
    for log in logs:
        want_md, want = expected[f"{name}|log|{log}|md"], expected[f"{name}|log|{log}|values"]
        np.testing.assert_array_equal(well.logs[log].md, want_md)
        np.testing.assert_array_equal(well.logs[log].values, want)
        assert well.logs[log].values.dtype == want.dtype
    markers = [f"{m.name}@{m.md}" for m in well.markers]
    assert markers == list(expected[f"{name}|markers"])
    zones = [
        f"{z.name}@{z.top_md}@{z.base_md}@"
        + (repr(z.metadata["value"]) if "value" in z.metadata else z.metadata["geoh5 data"])
        for z in well.zones
    ]
    assert zones == list(expected[f"{name}|zones"])


def test_specific_content(scene: geobrep.Scene) -> None:
    """Facts of the file independent of the npz: the gap, the integer log, the picks."""
    dh1, dh2, dh3 = (scene[n] for n in HOLES)
    gr = dh1.logs["gr"]
    assert gr.md.shape == (168 - 6,)  # six samples not logged
    assert not np.isnan(gr.values).any()
    assert dh2.logs["facies"].values.dtype == np.int32
    assert [m.name for m in dh2.markers] == ["H1 top", "F1", "H1 top"]
    assert all(m.metadata == {"geoh5 data": "picks"} for m in dh2.markers)
    assert [(z.name, z.metadata.get("value")) for z in dh1.zones if z.name == "au"] == [
        ("au", 0.25),
        ("au", 1.5),
        ("au", 0.125),
    ]
    # one survey row: a vertical hole, extended to the deepest interval base
    assert dh3.md.tolist() == [0.0, 80.25]
    # (geoh5's straight runs are arcs of radius 99999.9: micrometres off the vertical)
    np.testing.assert_allclose(dh3.vertices[-1], dh3.head - [0, 0, 80.25], atol=1e-4)
    # the deepest sample lies below the last survey: the trajectory reaches it
    assert dh1.md[-1] == max(float(gr.md[-1]), 440.0)


def test_written_back_per_object(scene: geobrep.Scene, tmp_path: Path) -> None:
    """geobrep writes the per-object layout; stations, logs and markers come back exactly, the
    zones' values are reported as lost metadata."""
    target = tmp_path / "back.geoh5"
    lost = format_losses(scene, registries().formats.get("geoh5"), target)
    assert any("metadata of markers and zones dropped" in m for m in lost)
    geobrep.write(scene, target)
    back = geobrep.read(target)
    with h5py.File(target, "r") as store:
        assert len(store["GEOSCIENCE/Objects"]) == 3
    for name in HOLES:
        ours, theirs = scene[name], back[name]
        np.testing.assert_array_equal(theirs.vertices, ours.vertices)
        np.testing.assert_array_equal(theirs.md, ours.md)
        assert sorted(theirs.logs) == sorted(ours.logs)
        for log in ours.logs:
            np.testing.assert_array_equal(theirs.logs[log].values, ours.logs[log].values)
        assert [(m.name, m.md) for m in theirs.markers] == [(m.name, m.md) for m in ours.markers]
        assert [(z.name, z.top_md, z.base_md) for z in theirs.zones] == [
            (z.name, z.top_md, z.base_md) for z in ours.zones
        ]


def test_version_2_0_attributes_document(tmp_path: Path, scene: geobrep.Scene) -> None:
    """geoh5 2.0 keeps the records as one JSON document ``{"Attributes": [...]}``."""
    target = _copy(tmp_path)
    with h5py.File(target, "r+") as store:
        store["GEOSCIENCE"].attrs["Version"] = 2.0
        concat = _concatenated(store)
        document = json.dumps({"Attributes": _records(concat)})
        del concat["Attributes Jsons"]
        concat.create_dataset("Attributes", data=[document], dtype=h5py.string_dtype())
    assert geobrep.read(target) == scene


def test_trace_used_when_present(tmp_path: Path) -> None:
    """A group holding traces: the stations are the trace, not a desurveying."""
    target = _copy(tmp_path)
    xyz = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
    with h5py.File(target, "r+") as store:
        concat = _concatenated(store)
        ids = concat["Index/Surveys"][()]["Object ID"]
        trace = np.zeros(6, dtype=xyz)
        trace["x"], trace["y"], trace["z"] = np.arange(6.0), 1.0, -np.arange(6.0) * 10
        concat.create_dataset("Trace", data=trace)
        concat.create_dataset("TraceDepth", data=np.tile([0.0, 500.0], 3))
        index = concat["Index/Surveys"][()]
        index["Start index"] = [0, 2, 4]
        index["Size"] = 2
        assert list(index["Object ID"]) == list(ids)
        concat["Index"].create_dataset("Trace", data=index)
        concat["Index"].create_dataset("TraceDepth", data=index)
    back = geobrep.read(target)
    np.testing.assert_array_equal(back["DH-2"].vertices, [[2.0, 1, -20], [3.0, 1, -30]])
    np.testing.assert_array_equal(back["DH-2"].md, [0.0, 500.0])


def test_unknown_and_loose_data_are_reported(tmp_path: Path) -> None:
    target = _copy(tmp_path)
    with h5py.File(target, "r+") as store:
        concat = _concatenated(store)
        records = _records(concat)
        # take the 'au' data out of its interval table
        for record in records:
            if "Property Group Type" in record:
                names = {r["ID"]: r.get("Name") for r in records}
                record["Properties"] = [p for p in record["Properties"] if names[p] != "au"]
        records.append(
            {
                "ID": "{00000000-0000-0000-0000-00000000abcd}",
                "Name": "pts",
                "Object Type ID": "{202c5db1-a56d-4004-9cad-baafd8899406}",
            }
        )
        _set_records(concat, records)
    back = geobrep.read(target)
    skipped = back.metadata[SKIPPED_ON_READ]
    assert "drillhole 'DH-1': data 'au' in no depth or interval table" in skipped
    assert "geoh5 concatenated object 'pts': not a drillhole" in skipped
    assert not [z for z in back["DH-1"].zones if z.name == "au"]


def _damage(tmp_path: Path, edit: Any) -> Path:
    target = _copy(tmp_path)
    with h5py.File(target, "r+") as store:
        edit(_concatenated(store))
    return target


def _index_past_end(concat: Any) -> None:
    index = concat["Index/gr"][()]
    index["Size"] = 10_000
    concat["Index/gr"][...] = index


def _bad_collar(concat: Any) -> None:
    records = _records(concat)
    next(r for r in records if r.get("Name") == "DH-2")["Collar"] = "{1.0, nan}"
    _set_records(concat, records)


def _upside_down_interval(concat: Any) -> None:
    index = concat["Index/TO"][()]
    start = int(index["Start index"][0])
    to = concat["Data/TO"]
    values = to[()]
    values[start] = 1.0  # the first interval (from 10 m) now ends at 1 m
    to[...] = values


def _nan_survey(concat: Any) -> None:
    rows = concat["Surveys"][()]
    rows["Dip"][1] = np.nan
    concat["Surveys"][...] = rows


def _not_json(concat: Any) -> None:
    del concat["Attributes Jsons"]
    concat.create_dataset("Attributes Jsons", data=["{not json"], dtype=h5py.string_dtype())


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (_index_past_end, "concatenated array 'gr': rows"),
        (_bad_collar, "drillhole 'DH-2': collar"),
        (_upside_down_interval, "ends at 1.0 above its top 10.0"),
        (_nan_survey, "surveys hold non-finite values"),
        (_not_json, "damaged geoh5 workspace"),
    ],
)
def test_damaged_groups_raise_format_errors(tmp_path: Path, edit: Any, message: str) -> None:
    target = _damage(tmp_path, edit)
    with pytest.raises(FormatError, match=r"group\.geoh5") as caught:
        geobrep.read(target)
    assert message in str(caught.value)


def test_declared_sizes_count_before_reading(tmp_path: Path, monkeypatch: Any) -> None:
    """The group's datasets count against the read budget before any is read."""
    import geobrep.adapters.limits as limits

    monkeypatch.setattr(limits, "read_budget", lambda size: 1_000)
    with pytest.raises(FormatError, match="drillhole groups' datasets declares"):
        geobrep.read(FILE)


@pytest.mark.parametrize(("fmt", "suffix"), [("las", ".las"), ("deviation", ".dev")])
def test_the_wells_to_a_format_of_one_well(
    scene: geobrep.Scene, tmp_path: Path, fmt: str, suffix: str
) -> None:
    """Three wells to a one-well format: the first is written, the others reported, and the
    report does not claim they were merged."""
    target = tmp_path / f"first{suffix}"
    lost = format_losses(scene, registries().formats.get(fmt), target)
    assert not [m for m in lost if "merged" in m]
    assert "Well 'DH-2': only the first well is written" in lost
    geobrep.write(scene, target)
    back = geobrep.read(target)
    assert len(back.entities) == 1
    np.testing.assert_allclose(back.entities[0].md, scene["DH-1"].md)


def test_a_column_not_one_per_row_of_its_table_is_reported(tmp_path: Path) -> None:
    def shorten(concat: Any) -> None:
        index = concat["Index/gr"][()]
        index["Size"][0] -= 1  # the first drillhole's 'gr' now one value short of its depths
        concat["Index/gr"][...] = index

    back = geobrep.read(_damage(tmp_path, shorten))
    skipped = back.metadata[SKIPPED_ON_READ]
    short = [s for s in skipped if "depth data 'gr' not one per depth" in s]
    assert len(short) == 1
    whole = geobrep.read(FILE)
    assert sum(1 for w in back.wells for name in w.logs if name.startswith("gr")) == (
        sum(1 for w in whole.wells for name in w.logs if name.startswith("gr")) - 1
    )
