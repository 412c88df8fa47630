"""geobrep.geometry.sorting: radix passes give numpy's stable order and sort, whatever the
width of the keys; the incidence built on them is the one of the packed sort."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep.geometry import mesh
from geobrep.geometry.sorting import radix_order, radix_pays, sorted_keys


@pytest.mark.parametrize("bits", [1, 7, 16, 17, 33, 48])
def test_radix_order_is_the_stable_argsort(bits: int) -> None:
    rng = np.random.default_rng(bits)
    keys = rng.integers(0, 2**bits, 20_000)
    keys[::7] = keys[0]  # ties keep their order
    order = radix_order(keys, bits)
    assert order.dtype == np.int64
    np.testing.assert_array_equal(order, np.argsort(keys, kind="stable"))


@pytest.mark.parametrize(
    ("n", "low", "high"), [(10, -5, 5), (9_000, -(2**40), 2**40), (50_000, 0, 2**62)]
)
def test_sorted_keys_is_np_sort(n: int, low: int, high: int) -> None:
    keys = np.random.default_rng(n).integers(low, high, n)
    found = sorted_keys(keys)
    np.testing.assert_array_equal(found, np.sort(keys))
    assert found.dtype == keys.dtype


def test_radix_pays_for_many_narrow_keys_only() -> None:
    assert radix_pays(100_000, 30)
    assert radix_pays(100_000, 48)
    assert not radix_pays(100_000, 49)
    assert not radix_pays(100, 30)


@pytest.mark.parametrize("vertices", [300, 70_000, 3_000_000])
def test_incidence_by_radix_is_the_packed_sorts(vertices: int) -> None:
    faces = np.random.default_rng(vertices).integers(0, vertices, (20_000, 3))
    faces[:500] = faces[500:1000]  # shared edges
    vertex_bits = int(faces.max()).bit_length()
    side_bits = (faces.size - 1).bit_length()
    expected = mesh._incidence_by_bits(faces, vertex_bits, side_bits)
    found = mesh._incidence_by_radix(faces, vertex_bits)
    for mine, theirs in zip(found, expected, strict=True):
        assert mine.dtype == theirs.dtype
        np.testing.assert_array_equal(mine, theirs)
