"""The embedded-disk shortcut of the self-intersection check: it answers ``True`` only for
surfaces the pairwise search finds clean, and the check's results do not change with it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import Surface
from geobrep.geometry import mesh
from geobrep.plugins.checks import _intersections
from geobrep.plugins.checks._embedding import embedded_disk

DATA = Path(__file__).resolve().parents[1] / "data" / "gocad"


def _grid(n: int = 12, jitter: float = 0.0, seed: int = 0) -> Surface:
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.sin(xs.ravel()) * 0.3])
    vertices[:, :2] += rng.uniform(-jitter, jitter, (vertices.shape[0], 2))
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    faces = np.concatenate(
        [np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])]
    )
    return Surface(vertices=vertices, faces=faces, name="grid")


def _embedded(surface: Surface) -> bool:
    tris = np.asarray(surface.faces, dtype=np.int64)
    merged = mesh.merge_close_vertices(surface.vertices, 1e-9)[1]
    return embedded_disk(surface.vertices, tris, mesh.edge_face_incidence(tris), merged)


def _pairwise(surface: Surface, monkeypatch: pytest.MonkeyPatch) -> int:
    with monkeypatch.context() as patch:
        patch.setattr(_intersections, "embedded_disk", lambda *args, **kwargs: False)
        report = geobrep.inspect(surface, ["self_intersections"])
    return report.section("self_intersections").count


def test_a_height_field_grid_is_an_embedded_disk() -> None:
    assert _embedded(_grid())


@pytest.mark.parametrize("jitter", [0.2, 0.45, 0.9, 2.5])
@pytest.mark.parametrize("seed", range(4))
def test_true_only_when_no_triangles_cross(
    jitter: float, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    surface = _grid(jitter=jitter, seed=seed)
    if _embedded(surface):
        assert _pairwise(surface, monkeypatch) == 0
    report = geobrep.inspect(surface, ["self_intersections"])
    assert report.section("self_intersections").count == _pairwise(surface, monkeypatch)


def test_small_jitter_keeps_the_shortcut() -> None:
    assert all(_embedded(_grid(jitter=0.2, seed=seed)) for seed in range(4))


def _spiral(turns: float, k: int = 60) -> Surface:
    """A strip winding ``turns`` times about the z axis while climbing: apart in space, but
    its projection overlaps itself after a turn."""
    angle = np.linspace(0.0, 2.0 * np.pi * turns, k)
    inner = np.column_stack([np.cos(angle), np.sin(angle), angle])
    outer = np.column_stack([2.0 * np.cos(angle), 2.0 * np.sin(angle), angle])
    vertices = np.vstack([inner, outer])
    a = np.arange(k - 1)
    faces = np.concatenate(
        [np.column_stack([a, a + k, a + 1]), np.column_stack([a + 1, a + k, a + k + 1])]
    )
    return Surface(vertices=vertices, faces=faces)


def test_a_strip_overlapping_itself_in_projection_is_not_taken() -> None:
    assert _embedded(_spiral(0.6))
    assert not _embedded(_spiral(1.5))


def test_a_vertex_wound_twice_is_not_taken() -> None:
    k = 10  # ten triangles about the centre turning twice, climbing so none meet
    angle = 4.0 * np.pi * np.arange(k) / k
    ring = np.column_stack([np.cos(angle), np.sin(angle), np.arange(k, dtype=float)])
    vertices = np.vstack([[0.0, 0.0, 0.0], ring])
    faces = np.column_stack([np.zeros(k, int), 1 + np.arange(k), 1 + (np.arange(k) + 1) % k])
    assert not _embedded(Surface(vertices=vertices, faces=faces))


def test_holes_welds_folds_and_steep_triangles_are_not_taken() -> None:
    grid = _grid()
    faces = np.asarray(grid.faces)
    centre = np.flatnonzero(np.isin(faces, [6 * 13 + 6]).any(axis=1))
    holed = grid.replace(faces=np.delete(faces, centre, axis=0))
    assert not _embedded(holed)  # an annulus
    copy = np.vstack([grid.vertices, grid.vertices[[50]]])
    split = faces.copy()
    row = int(np.flatnonzero((split == 50).any(axis=1))[0])
    split[row][split[row] == 50] = copy.shape[0] - 1
    assert not _embedded(grid.replace(vertices=copy, faces=split))  # a weld inside
    folded = grid.vertices.copy()
    folded[50, :2] += [3.0, 0.0]
    assert not _embedded(grid.replace(vertices=folded))  # triangles turned over
    wall = grid.vertices.copy()
    wall[:, 2] = np.abs(wall[:, 0] - 6.0) * 1e7  # a V of two near-vertical walls
    assert not _embedded(grid.replace(vertices=wall))  # steep against the mean normal


@pytest.mark.parametrize("name", ["surf2d.ts", "2triangles.ts", "Fault_without_crs.ts"])
def test_the_check_agrees_with_the_pairwise_search_on_files(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = geobrep.read(DATA / name, repair=False)
    with monkeypatch.context() as patch:
        patch.setattr(_intersections, "embedded_disk", lambda *args, **kwargs: False)
        slow = geobrep.inspect(scene, ["self_intersections"])
    fast = geobrep.inspect(scene, ["self_intersections"])
    assert fast.section("self_intersections").defects == slow.section("self_intersections").defects
