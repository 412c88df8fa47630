"""A Model3d member's TFACEs each declare the vertices their triangles use.

GOCAD writes Model3d files so (a vertex an earlier TFACE declared comes again as an ``ATOM``
line), and OpenGeode-GeosciencesIO builds each TFACE from its own vertex range: it crashed on
the layer cake geobrep wrote before, whose patches shared their border vertices across TFACEs.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from gocad_files import DATA, read_quietly, write_quietly

import geobrep

_ID_LINE = re.compile(rb"^(?:P?VRTX|P?ATOM) (\d+)", re.MULTILINE)


def _tface_ranges_hold_their_triangles(text: bytes) -> int:
    """Check every TRGL of every member TFACE against the ids that TFACE declared; the
    number of TFACEs checked."""
    checked = 0
    for member in text.split(b"GOCAD TSurf")[1:]:
        for part in re.split(rb"^TFACE[^\n]*\n", member, flags=re.MULTILINE)[1:]:
            declared = {int(m) for m in _ID_LINE.findall(part)}
            used = {
                int(v)
                for row in re.findall(rb"^TRGL (.*)$", part, re.MULTILINE)
                for v in row.split()[:3]
            }
            assert used <= declared, f"TRGL ids {sorted(used - declared)[:5]} of another TFACE"
            checked += 1
    return checked


@pytest.fixture(scope="module")
def cake() -> geobrep.Scene:
    return geobrep.datasets.faulted_layer_cake(n_horizons=2, resolution=60.0)


def _shares_vertices(surface: geobrep.Surface) -> bool:
    """Whether a vertex is used by triangles of two patches."""
    labels = np.repeat(np.asarray(surface.patch_labels), 3)
    pairs = np.unique(np.column_stack([surface.faces.ravel(), labels]), axis=0)
    return bool(len(np.unique(pairs[:, 0])) < len(pairs))


def test_each_tface_declares_its_vertices(cake: geobrep.Scene, tmp_path: Path) -> None:
    assert any(map(_shares_vertices, cake.surfaces))  # patches that share border vertices
    path = write_quietly(cake, tmp_path / "cake.ml")
    text = path.read_bytes()
    assert _tface_ranges_hold_their_triangles(text) == len(cake.patches)
    assert b"\nATOM " in text  # the shared vertices come again as ATOMs


def test_shared_vertices_on_request(cake: geobrep.Scene, tmp_path: Path) -> None:
    path = write_quietly(cake, tmp_path / "cake.ml", tface_vertices="shared")
    assert b"\nATOM " not in path.read_bytes()
    again = read_quietly(path)
    for before, after in zip(cake.surfaces, again.surfaces, strict=True):
        assert np.array_equal(after.vertices, before.vertices)
        assert np.array_equal(after.faces, before.faces)


def test_a_tsurf_file_keeps_one_vertex_per_position(cake: geobrep.Scene, tmp_path: Path) -> None:
    surface = next(s for s in cake.surfaces if _shares_vertices(s))
    scene = geobrep.Scene(entities=[surface.replace(id=None)], crs=cake.crs)
    again = read_quietly(write_quietly(scene, tmp_path / "s.ts")).surfaces[0]
    assert again.n_vertices == surface.n_vertices
    own = read_quietly(write_quietly(scene, tmp_path / "own.ts", tface_vertices="own"))
    assert own.surfaces[0].n_vertices > surface.n_vertices
    assert np.array_equal(
        own.surfaces[0].vertices[own.surfaces[0].faces], surface.vertices[surface.faces]
    )


def test_the_model_reads_back_the_same(cake: geobrep.Scene, tmp_path: Path) -> None:
    again = read_quietly(write_quietly(cake, tmp_path / "cake.ml"))
    assert len(again.blocks) == len(cake.blocks)
    assert len(again.topology.corners) == len(cake.topology.corners)
    assert len(again.topology.arcs) == len(cake.topology.arcs)
    assert len(again.patches) == len(cake.patches)
    for before, after in zip(cake.surfaces, again.surfaces, strict=True):
        assert after.n_faces == before.n_faces
        # the same triangles, corner for corner, though border vertices now come once per patch
        assert np.array_equal(after.vertices[after.faces], before.vertices[before.faces])
        assert set(map(tuple, after.vertices)) == set(map(tuple, before.vertices))
    assert sorted(len(b.sides) for b in again.blocks) == sorted(len(b.sides) for b in cake.blocks)


def test_a_file_read_from_gocad_is_written_as_before(tmp_path: Path) -> None:
    scene = read_quietly(DATA / "modelA1.ml")
    text = write_quietly(scene, tmp_path / "a1.ml").read_bytes()
    assert _tface_ranges_hold_their_triangles(text) == len(scene.patches)
    assert read_quietly(tmp_path / "a1.ml").surfaces[0].n_vertices == scene.surfaces[0].n_vertices


_OPENGEODE = """
import sys, opengeode, opengeode_geosciences, opengeode_geosciencesio
opengeode_geosciencesio.OpenGeodeGeosciencesIOModelLibrary.initialize()
opengeode.Logger.set_level(opengeode.Logger.LEVEL.critical)
m = opengeode_geosciences.load_structural_model(sys.argv[1])
print(m.nb_corners(), m.nb_lines(), m.nb_surfaces(), m.nb_blocks())
"""


def test_opengeode_reads_the_written_cake(cake: geobrep.Scene, tmp_path: Path) -> None:
    pytest.importorskip("opengeode_geosciencesio")
    path = write_quietly(cake, tmp_path / "cake.ml")
    done = subprocess.run(  # a child process: a crash of the C++ reader fails the test only
        [sys.executable, "-c", _OPENGEODE, str(path)],
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    counts = tuple(int(v) for v in done.stdout.split())
    expected = (len(cake.topology.corners), len(cake.topology.arcs), len(cake.patches))
    assert counts == (*expected, len(cake.blocks))


def test_convert_reports_the_copies_and_verifies(tmp_path: Path) -> None:
    source = DATA / "cube_model_equi.so"
    report = geobrep.convert(source, tmp_path / "cube.ml", verify=True).reports[0]
    assert report.status == "converted", report.error
    said = [line for line in report.lost if "copies of vertices its patches share" in line]
    assert said
    again = read_quietly(tmp_path / "cube.ml")
    for line in said:
        name, count = re.match(r"Surface '(.+)': .* (\d+) points read back$", line).groups()  # type: ignore[union-attr]
        assert again[name].n_points == int(count)
