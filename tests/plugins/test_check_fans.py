"""non_manifold_vertices against a slow independent answer: per vertex, the faces around it
walked across the edges they share (a breadth-first search in Python), on random soups with
repeated and non-manifold faces, and on pinched meshes."""

from __future__ import annotations

import numpy as np
import pytest

import geobrep
from geobrep import Surface


def _fans_by_walking(faces: np.ndarray) -> dict[int, int]:
    """Vertex -> fans: faces at the vertex joined when they share an edge through it."""
    fans: dict[int, int] = {}
    for v in np.unique(faces).tolist():
        around = [k for k, f in enumerate(faces.tolist()) if v in f]
        seen: set[int] = set()
        count = 0
        for start in around:
            if start in seen:
                continue
            count += 1
            todo = [start]
            seen.add(start)
            while todo:
                f = faces[todo.pop()].tolist()
                here = {(f[s], f[(s + 1) % 3]) for s in range(3)}
                ends = {b if a == v else a for a, b in here if v in (a, b) and a != b}
                for g in around:
                    if g in seen:
                        continue
                    other = faces[g].tolist()
                    theirs = {
                        other[(s + 1) % 3] if other[s] == v else other[s]
                        for s in range(3)
                        if v in (other[s], other[(s + 1) % 3]) and other[s] != other[(s + 1) % 3]
                    }
                    if ends & theirs:
                        seen.add(g)
                        todo.append(g)
        fans[v] = count
    return fans


def _reported(faces: np.ndarray) -> dict[int, int]:
    n = int(faces.max()) + 1
    vertices = np.random.default_rng(0).random((n, 3))
    report = geobrep.inspect(Surface(vertices=vertices, faces=faces), ["non_manifold_vertices"])
    return {d.ids[0]: int(d.value) for d in report.section("non_manifold_vertices").defects}


@pytest.mark.parametrize("seed", range(40))
def test_fans_of_random_soups(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 10))
    faces = np.array([rng.choice(n, 3, replace=False) for _ in range(int(rng.integers(2, 16)))])
    expected = {v: k for v, k in _fans_by_walking(faces).items() if k > 1}
    assert _reported(faces) == expected


def test_two_cones_and_a_bowtie() -> None:
    cones = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [0, 4, 5], [0, 5, 6], [0, 6, 4]])
    assert _reported(cones) == {0: 2}
    bowtie = np.array([[0, 1, 2], [0, 3, 4], [0, 4, 5], [0, 5, 3], [0, 6, 7]])
    assert _fans_by_walking(bowtie)[0] == 3
    assert _reported(bowtie) == {0: 3}
