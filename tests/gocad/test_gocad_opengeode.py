"""Cross-checks against OpenGeode-GeosciencesIO, the most complete open GOCAD reader (C++).

Skipped when ``opengeode-geosciencesio`` is not installed (a test/benchmark extra).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from gocad_files import DATA, read_quietly, write_quietly

og = pytest.importorskip("opengeode")
ogio = pytest.importorskip("opengeode_geosciencesio")
geosciences = pytest.importorskip("opengeode_geosciences")


@pytest.fixture(scope="module", autouse=True)
def _libraries() -> None:
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    ogio.OpenGeodeGeosciencesIOModelLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)


def _points(mesh: Any) -> np.ndarray:
    return np.array(
        [mesh.point(v).string().split() for v in range(mesh.nb_vertices())], dtype=float
    )


@pytest.mark.parametrize("name", ["Fault_without_crs.ts", "2triangles.ts", "ts-2props.ts"])
def test_tsurf_geometry_matches_opengeode(name: str, tmp_path: Path) -> None:
    ours = read_quietly(DATA / name).surfaces[0]
    theirs = og.load_triangulated_surface3D(str(DATA / name))
    assert (theirs.nb_vertices(), theirs.nb_polygons()) == (ours.n_vertices, ours.n_faces)
    assert np.array_equal(_points(theirs), ours.vertices)  # same doubles, Depth negated alike
    # and OpenGeode reads what geobrep writes
    written = write_quietly(read_quietly(DATA / name), tmp_path / name)
    again = og.load_triangulated_surface3D(str(written))
    assert np.array_equal(_points(again), ours.vertices)


def test_model3d_counts_match_opengeode(tmp_path: Path) -> None:
    ours = read_quietly(DATA / "modelA4.ml")
    theirs = geosciences.load_structural_model(str(DATA / "modelA4.ml"))
    assert theirs.nb_surfaces() == len(ours.patches)
    assert theirs.nb_blocks() == len(ours.blocks)
    assert theirs.nb_lines() == len(ours.topology.arcs)
    assert theirs.nb_corners() == len(ours.topology.corners)
    # the Model3d geobrep writes is read by OpenGeode with the same counts
    written = write_quietly(ours, tmp_path / "modelA4.ml")
    again = geosciences.load_structural_model(str(written))
    assert (again.nb_surfaces(), again.nb_blocks(), again.nb_lines(), again.nb_corners()) == (
        55,
        8,
        98,
        52,
    )
