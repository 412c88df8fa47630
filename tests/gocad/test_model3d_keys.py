"""A TFACE's key triangle is found as its definition says: the first triangle of the patch
whose corners are the key's points within the tolerance, in the same cyclic order, else in
the reverse order (then ``reversed``), for the one-patch search and the per-surface one."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Surface
from geobrep.adapters.gocad._model3d import _PatchCorners, find_key_triangle


def _expected(
    surface: Surface, label: int, key: np.ndarray, tolerance: float
) -> tuple[int | None, bool]:
    faces = np.flatnonzero(np.asarray(surface.patch_labels) == label)
    for reverse in (False, True):
        target = key[::-1] if reverse else key
        for shift in range(3):
            rolled = np.roll(target, shift, axis=0)
            for face in faces.tolist():
                corners = surface.vertices[surface.faces[face]]
                if (np.abs(corners - rolled) <= tolerance).all():
                    return face, reverse
    return None, False


@pytest.mark.parametrize("seed", range(4))
def test_key_triangles_are_found_as_defined(seed: int) -> None:
    rng = np.random.default_rng(seed)
    vertices = rng.integers(0, 4, size=(40, 3)).astype(np.float64)  # repeated points happen
    faces = rng.integers(0, 40, size=(150, 3))
    labels = rng.integers(0, 5, size=150)
    surface = Surface(vertices=vertices, faces=faces, patch_labels=labels)
    per_surface = _PatchCorners(surface)
    tolerance = 1e-6
    found = {None: 0, False: 0, True: 0}
    for face in rng.choice(150, 60).tolist():
        key = vertices[faces[face]]
        key = np.roll(key, int(rng.integers(0, 3)), axis=0)
        if rng.random() < 0.4:
            key = key[::-1]
        key = key + rng.uniform(-0.5e-6, 0.5e-6, key.shape) * (rng.random() < 0.5)
        if rng.random() < 0.2:
            key[1, 0] += 0.5  # no triangle there
        label = int(labels[face]) if rng.random() < 0.8 else int(rng.integers(0, 5))
        expected = _expected(surface, label, key, tolerance)
        assert find_key_triangle(surface, label, key, tolerance) == expected
        assert per_surface.find(label, key, tolerance) == expected
        found[expected[1] if expected[0] is not None else None] += 1
    assert all(found.values())  # same order, reversed and absent keys all met
