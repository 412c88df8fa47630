"""The TSurf checks (duplicated and zero-area triangles, BORDERs off the TFACE borders) agree
with their definitions on random triangle soups, defects included."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from geobrep.adapters.gocad._checks import bad_triangles, borders_on_patch_borders


def _soup(seed: int) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Vertices on a coarse lattice (collinear triples happen), random triangles with some
    repeated in another vertex order and some with a repeated vertex, and patch labels."""
    rng = np.random.default_rng(seed)
    xyz = rng.integers(0, 3, size=(30, 3)).astype(np.float64) + 4.5e5
    faces = rng.integers(0, 30, size=(200, 3))
    again = rng.choice(200, 15, replace=False)
    faces = np.concatenate([faces, np.roll(faces[again], int(rng.integers(1, 3)), axis=1)])
    faces = faces[rng.permutation(faces.shape[0])]
    parts = rng.integers(0, 4, size=faces.shape[0])
    return xyz, faces.astype(np.int64), parts.astype(np.int64)


@pytest.mark.parametrize("seed", range(6))
def test_bad_triangles_are_counted_as_defined(seed: int) -> None:
    xyz, faces, _ = _soup(seed)
    seen: set[tuple[int, ...]] = set()
    duplicated, flat = [], []
    for row in faces.tolist():
        key = tuple(sorted(row))
        duplicated.append(key in seen)
        seen.add(key)
        p0, p1, p2 = xyz[row]
        flat.append(not np.cross(p1 - p0, p2 - p0).any())
    bad = [d or f for d, f in zip(duplicated, flat, strict=True)]
    found = bad_triangles(xyz, faces)
    assert found is not None
    assert (found.duplicated, found.flat, found.first) == (
        sum(duplicated),
        sum(flat),
        bad.index(True),
    )


def test_a_clean_surface_has_no_bad_triangles() -> None:
    xyz = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert bad_triangles(xyz, np.array([[0, 1, 2], [0, 2, 3]])) is None
    assert bad_triangles(xyz, np.zeros((0, 3), dtype=np.int64)) is None
    found = bad_triangles(xyz, np.array([[0, 1, 2], [0, 2, 3], [3, 0, 2]]))
    assert found is not None
    assert (found.duplicated, found.flat, found.first) == (1, 0, 2)


@pytest.mark.parametrize("seed", range(6))
def test_borders_on_patch_borders_as_defined(seed: int) -> None:
    _, faces, parts = _soup(seed)
    rng = np.random.default_rng(100 + seed)
    edges = faces[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2)
    pairs = np.concatenate([edges[rng.choice(edges.shape[0], 40)], rng.integers(0, 35, (10, 2))])
    uses: dict[tuple[int, int, int], int] = {}
    for (a, b), part in zip(edges.tolist(), np.repeat(parts, 3).tolist(), strict=True):
        key = (part, min(a, b), max(a, b))
        uses[key] = uses.get(key, 0) + 1
    border = {(lo, hi) for (_, lo, hi), count in uses.items() if count == 1}
    expected = [(min(a, b), max(a, b)) in border for a, b in pairs.tolist()]
    assert borders_on_patch_borders(faces, parts, pairs).tolist() == expected
    assert any(expected)
    assert not all(expected)


@pytest.mark.parametrize("spread", ["negative", "beyond one key"])
def test_border_answers_do_not_depend_on_how_patches_are_numbered(spread: str) -> None:
    # patch numbers below zero, or so far apart that (patch, edge) no longer fits one int64
    # key (the row-wise path), change nothing
    _, faces, parts = _soup(4)
    rng = np.random.default_rng(7)
    edges = faces[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2)
    pairs = np.concatenate([edges[rng.choice(edges.shape[0], 40)], rng.integers(0, 35, (10, 2))])
    renumbered = parts - 5 if spread == "negative" else parts * 10**16
    expected = borders_on_patch_borders(faces, parts, pairs).tolist()
    assert any(expected)
    assert not all(expected)
    assert borders_on_patch_borders(faces, renumbered, pairs).tolist() == expected


def test_32_bit_indices_give_the_same_answers() -> None:
    xyz, faces, parts = _soup(9)
    xyz = np.concatenate([xyz, np.random.default_rng(9).normal(size=(70_000, 3))])
    faces = faces + 69_990  # keys beyond 32 bits: (70k)^3
    assert bad_triangles(xyz, faces.astype(np.int32)) == bad_triangles(xyz, faces)
    pairs = faces[:5, :2]
    assert (
        borders_on_patch_borders(faces.astype(np.int32), parts, pairs.astype(np.int32)).tolist()
        == borders_on_patch_borders(faces, parts, pairs).tolist()
    )
