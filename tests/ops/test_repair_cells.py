"""``geobrep.repair`` on polylines and tet meshes: what ``inspect`` reports there is mended, the
cell and point data follow their cells and vertices."""

from __future__ import annotations

import numpy as np

import geobrep
from geobrep import PolyLine, TetMesh

MESH_CHECKS = ["colocated_vertices", "degenerate_elements", "duplicated_elements"]


def test_polyline_duplicates_and_zero_length_segments_are_mended() -> None:
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [4, 0, 0], [5, 0, 0]])
    # part 0 runs 0-1-2-3-4 (1 and 2 colocated: a zero-length segment); part 1 runs 3-4-5-6 (its
    # first segment repeats part 0's last)
    line = PolyLine.from_parts(
        points.astype(float),
        [[0, 1, 2, 3, 4], [3, 4, 5, 6]],
        name="well",
        cell_data={"k": np.arange(7.0)},
        point_data={"x": points[:, 0].astype(float)},
    )
    before = geobrep.inspect(line, MESH_CHECKS).counts()
    assert before == {"colocated_vertices": 1, "degenerate_elements": 1, "duplicated_elements": 1}
    repaired, report = geobrep.repair(line)
    assert geobrep.inspect(repaired).ok
    fixed = repaired.polylines[0]
    assert fixed.name == "well"
    assert fixed.part_offsets.tolist() == [0, 4, 7]
    # the zero-length segment (k = 1) and the repeated one (k = 4) are gone; the others keep k
    assert fixed.cell_data["k"].values.tolist() == [0.0, 2.0, 3.0, 5.0, 6.0]
    assert np.allclose(fixed.point_data["x"].values, fixed.vertices[:, 0])
    assert np.isclose(fixed.length, 3.0 + 2.0)
    assert report.after == dict.fromkeys(report.before, 0)


def test_a_zero_length_closing_segment_and_a_dropped_segment_of_a_ring() -> None:
    ring = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1e-9]], dtype=float)
    line = PolyLine.from_parts(
        ring, [[0, 1, 2, 3, 4]], closed=True, cell_data={"k": np.arange(5.0)}
    )
    repaired, _ = geobrep.repair(line, ["drop_degenerate", "drop_isolated"], tolerance=1e-6)
    fixed = repaired.polylines[0]
    assert fixed.closed.tolist() == [True]
    assert fixed.n_cells == 4
    assert np.isclose(fixed.length, 4.0)
    assert geobrep.inspect(repaired, MESH_CHECKS, tolerance=1e-6).ok


def _tets() -> TetMesh:
    grid = np.array(
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [0.5, 0.5, 0.0]], dtype=float
    )
    cells = np.array(
        [
            [0, 1, 2, 3],  # positive
            [2, 1, 3, 4],  # negative: inverted
            [0, 1, 2, 5],  # flat: 5 lies in the plane of 0, 1, 2
            [3, 2, 1, 0],  # the first tet again, corners reordered
        ]
    )
    return TetMesh(vertices=grid, cells=cells, name="solid", cell_data={"k": np.arange(4.0)})


def test_tet_mesh_inverted_flat_and_duplicated_tets_are_mended() -> None:
    tets = _tets()
    assert tets.cell_volumes[1] < 0
    before = geobrep.inspect(tets, ["degenerate_elements", "duplicated_elements", "inverted_tets"])
    assert before.counts() == {
        "degenerate_elements": 1,
        "duplicated_elements": 1,
        "inverted_tets": 1,
    }
    repaired, report = geobrep.repair(tets)
    fixed = repaired.tet_meshes[0]
    assert geobrep.inspect(repaired).ok, geobrep.inspect(repaired).table()
    assert fixed.cell_data["k"].values.tolist() == [0.0, 1.0]
    assert (fixed.cell_volumes > 0).all()
    assert np.isclose(fixed.cell_volumes.sum(), 1.0 / 6.0 + abs(tets.cell_volumes[1]))
    assert fixed.vertices.shape[0] == 5  # vertex 5 only served the flat tet
    counts = {a.action: a.count for a in report.actions if a.count}
    assert counts == {"drop_degenerate": 1, "drop_duplicates": 1, "drop_isolated": 1, "orient": 1}
