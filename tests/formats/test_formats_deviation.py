"""Well deviation tables: the reference files' station counts, the minimum-curvature method
checked against the Petrel file's own stations, exact round trips."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import FormatError, Well
from geobrep.geometry.trajectory import minimum_curvature

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


@pytest.mark.parametrize(
    ("name", "stations"), [("test_well.dev", 104), ("test_well.dat", 11), ("test_well.txt", 11)]
)
def test_reference_counts_and_round_trip(name: str, stations: int, tmp_path: Path) -> None:
    well = geobrep.read(OPENGEODE / name, format="deviation").entities[0]
    assert isinstance(well, Well)
    assert (well.n_stations, well.n_cells) == (stations, stations - 1)
    back = geobrep.read(geobrep.write(well, tmp_path / "copy.dev")).entities[0]
    assert back == well


def test_dev_header_and_columns() -> None:
    well = geobrep.read(OPENGEODE / "test_well.dev").entities[0]
    assert isinstance(well, Well)
    assert well.name == "TEST"
    assert (well.datum, well.datum_elevation) == ("GL", 127.9)
    # first row: "0.0000000000 1056340.4607 6881075.2305 167.90000000 ..."
    np.testing.assert_array_equal(well.vertices[0], [1056340.4607, 6881075.2305, 167.9])
    assert well.point_data["INCL"].unit == "deg"


def test_minimum_curvature_matches_the_surveyed_stations() -> None:
    well = geobrep.read(OPENGEODE / "test_well.dev").entities[0]
    assert isinstance(well, Well)
    incl = well.point_data["INCL"].values
    offsets = {
        az: minimum_curvature(well.md, incl, well.point_data[az].values)
        for az in ("AZIM_GN", "AZIM_TN")
    }
    surveyed = np.diff(well.vertices, axis=0)
    short = np.diff(well.md) < 10.5  # the file thins the survey: compare the 10 m intervals
    assert short.sum() == 87
    errors = {az: np.abs(np.diff(o, axis=0) - surveyed)[short] for az, o in offsets.items()}
    # X Y are printed to 0.1 mm and Z to 1 cm; each 10 m step moves ~0.4 m sideways
    assert errors["AZIM_GN"].max() < 0.06
    assert np.median(errors["AZIM_GN"][:, :2]) < 0.01
    # DX DY are "given in grid north": the true-north azimuth fits worse
    assert errors["AZIM_TN"].max() > 2 * errors["AZIM_GN"].max()


def test_a_row_that_is_not_numbers_names_its_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.dev"
    path.write_text("MD X Y Z\n0 1 2 3\n10 1 2 x\n")
    with pytest.raises(FormatError, match="not a row of numbers") as info:
        geobrep.read(path)
    assert info.value.line == 3
