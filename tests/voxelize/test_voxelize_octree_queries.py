"""LinearOctree queries (point containment, labels, neighbours) and conversions."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from geobrep import LinearOctree
from geobrep.errors import EntityValidationError, MissingDependencyError, OptionsError
from geobrep.geometry.morton import morton_decode, morton_encode, octant_span
from geobrep.plugins.voxelize._emission import Leaves
from geobrep.plugins.voxelize._merge import merge_full_siblings

UTM = np.array([450_000.0, 6_700_000.0, -800.0])


def tree_from_dense(
    labels: np.ndarray, size: float = 8.0, origin: np.ndarray = UTM
) -> LinearOctree:
    """A labelled octree from a dense ``(n, n, n)`` array (-1 = empty), merged bottom-up."""
    n = labels.shape[0]
    depth = int(np.log2(n))
    codes = np.arange(n**3, dtype=np.uint64)  # every finest cell, in Morton order
    i, j, k = morton_decode(codes)
    values = labels[i, j, k]
    keep = values >= 0
    leaves = merge_full_siblings(
        Leaves(codes[keep], np.full(int(keep.sum()), depth, np.uint8), values[keep]), depth
    )
    return LinearOctree(
        codes=leaves.codes,
        levels=leaves.levels,
        depth=depth,
        origin=origin,
        size=size,
        labels=leaves.bodies,
    )


def blocky_labels(seed: int, n: int = 8) -> np.ndarray:
    """Random labels that are constant on random octants, so leaves of many levels appear."""
    rng = np.random.default_rng(seed)
    labels = np.full((n, n, n), -1, dtype=np.int64)
    for _ in range(12):
        edge = int(2 ** rng.integers(0, int(np.log2(n))))
        corner = rng.integers(0, n // edge, size=3) * edge
        labels[tuple(slice(c, c + edge) for c in corner)] = rng.integers(-1, 3)
    return labels


@given(st.integers(0, 10_000))
def test_contains_and_label_at_match_the_dense_grid(seed: int) -> None:
    labels = blocky_labels(seed)
    tree = tree_from_dense(labels)
    rng = np.random.default_rng(seed)
    points = UTM + rng.uniform(-1.0, 9.0, size=(300, 3))
    cell = np.floor(points - UTM).astype(int)
    inside_cube = np.all((cell >= 0) & (cell < 8), axis=1)
    expected = np.full(len(points), -1)
    expected[inside_cube] = labels[tuple(cell[inside_cube].T)]
    np.testing.assert_array_equal(tree.label_at(points), expected)
    np.testing.assert_array_equal(tree.contains(points), expected >= 0)
    volumes = tree.label_volumes()
    for label in range(3):
        assert volumes.get(label, 0.0) == float(np.count_nonzero(labels == label))


def test_contains_edge_cases() -> None:
    tree = LinearOctree(codes=[0], levels=[1], depth=2, origin=[0, 0, 0], size=4.0)
    # half-open cells: the face x = 2 belongs to the next octant; the cube's far faces are out
    points = [[0, 0, 0], [1.999, 1, 1], [2, 1, 1], [4, 1, 1], [-1e-9, 1, 1], [np.nan, 1, 1]]
    assert tree.contains(points).tolist() == [True, True, False, False, False, False]
    assert tree.contains([1.0, 1.0, 1.0]).tolist() == [True]  # one point as a (3,) array
    empty = LinearOctree(codes=[], levels=[], depth=3, origin=[0, 0, 0], size=1.0)
    assert empty.contains([[0.5, 0.5, 0.5]]).tolist() == [False]
    with pytest.raises(EntityValidationError, match="points"):
        tree.contains([[1, 2]])


def _touch(lo: np.ndarray, hi: np.ndarray, a: int, b: int) -> int:
    """Number of axes on which boxes a and b only touch (0-3), or -1 if they are apart."""
    touching = 0
    for axis in range(3):
        overlap = min(hi[a, axis], hi[b, axis]) - max(lo[a, axis], lo[b, axis])
        if overlap < 0:
            return -1
        touching += overlap == 0
    return touching


@given(st.integers(0, 10_000), st.sampled_from([6, 18, 26]))
def test_neighbours_match_brute_force(seed: int, connectivity: int) -> None:
    tree = tree_from_dense(blocky_labels(seed))
    cells, edges = tree.leaf_cells()
    lo, hi = cells, cells + edges[:, None]
    allowed = {6: 1, 18: 2, 26: 3}[connectivity]
    for leaf in range(0, tree.n_leaves, max(1, tree.n_leaves // 12)):
        expected = [
            other
            for other in range(tree.n_leaves)
            if other != leaf and 1 <= _touch(lo, hi, leaf, other) <= allowed
        ]
        assert tree.neighbours(leaf, connectivity).tolist() == expected


def test_neighbours_errors() -> None:
    tree = LinearOctree(codes=[0], levels=[1], depth=2, origin=[0, 0, 0], size=4.0)
    assert tree.neighbours(0).tolist() == []
    with pytest.raises(EntityValidationError, match="leaf"):
        tree.neighbours(3)
    with pytest.raises(EntityValidationError, match="connectivity"):
        tree.neighbours(0, 8)


def test_leaf_geometry() -> None:
    tree = LinearOctree(codes=[0, 8, 9], levels=[1, 2, 2], depth=2, origin=UTM, size=4.0)
    cells, edges = tree.leaf_cells()
    assert cells.tolist() == [[0, 0, 0], [2, 0, 0], [3, 0, 0]]
    assert edges.tolist() == [2, 1, 1]
    mins, maxs = tree.leaf_bounds()
    np.testing.assert_array_equal(mins[1], UTM + np.array([2.0, 0.0, 0.0]))
    np.testing.assert_array_equal(maxs[0], UTM + np.array([2.0, 2.0, 2.0]))
    np.testing.assert_array_equal(tree.leaf_centers()[2], UTM + np.array([3.5, 0.5, 0.5]))
    assert tree.spans.tolist() == [8, 1, 1]


@given(st.lists(st.integers(0, 2**21 - 1), min_size=3, max_size=3))
def test_morton_round_trip(ijk: list[int]) -> None:
    code = morton_encode(*([v] for v in ijk))
    assert [int(a[0]) for a in morton_decode(code)] == ijk
    expected = sum(((ijk[a] >> bit) & 1) << (3 * bit + a) for bit in range(21) for a in range(3))
    assert int(code[0]) == expected


def test_morton_order_is_z_order() -> None:
    codes = morton_encode(*np.indices((2, 2, 2)).reshape(3, -1))
    assert sorted(codes.tolist()) == list(range(8))
    assert octant_span([0, 3], 3).tolist() == [512, 1]


def test_to_pyvista_hexahedra_and_image() -> None:
    pv = pytest.importorskip("pyvista")
    labels = blocky_labels(5)
    tree = tree_from_dense(labels)
    grid = tree.to_pyvista()
    assert isinstance(grid, pv.UnstructuredGrid)
    assert grid.n_cells == tree.n_leaves
    assert set(np.unique(grid.celltypes)) == {pv.CellType.HEXAHEDRON}
    assert grid.volume == pytest.approx(tree.volume)
    np.testing.assert_array_equal(grid.cell_data["label"], tree.labels)
    np.testing.assert_array_equal(grid.cell_data["level"], tree.levels)
    assert grid.points.dtype == np.float64
    np.testing.assert_allclose(grid.bounds[::2], UTM)  # UTM coordinates kept
    image = tree.to_pyvista("image")
    assert image.dimensions == (9, 9, 9)
    dense = np.asarray(image.cell_data["label"]).reshape((8, 8, 8), order="F")
    np.testing.assert_array_equal(dense, labels)
    with pytest.raises(OptionsError, match="hexahedra"):
        tree.to_pyvista("points")


def test_missing_pyvista_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    tree = LinearOctree(codes=[0], levels=[0], depth=1, origin=[0, 0, 0], size=1.0)
    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(MissingDependencyError, match=r"geobrep\[viz\]"):
        tree.to_pyvista()
    monkeypatch.setitem(sys.modules, "open3d", None)
    with pytest.raises(MissingDependencyError, match=r"geobrep\[open3d\]"):
        tree.to_open3d()


def _open3d():
    try:
        import open3d
    except ImportError as exc:  # e.g. libusb-1.0 missing: apt-get install libusb-1.0-0
        pytest.skip(f"open3d cannot be imported here: {exc}")
    return open3d


def test_to_open3d_voxel_grid_and_octree() -> None:
    o3d = _open3d()
    labels = blocky_labels(9)
    tree = tree_from_dense(labels)
    grid = tree.to_open3d()
    assert isinstance(grid, o3d.geometry.VoxelGrid)
    voxels = grid.get_voxels()
    assert len(voxels) == int(np.count_nonzero(labels >= 0))
    indices = np.array([v.grid_index for v in voxels])
    assert labels[tuple(indices.T)].min() >= 0
    np.testing.assert_allclose(grid.origin, UTM)
    assert grid.voxel_size == pytest.approx(1.0)
    coarse = tree.to_open3d(level=2)
    assert len(coarse.get_voxels()) == int(
        np.count_nonzero((labels >= 0).reshape(4, 2, 4, 2, 4, 2).any(axis=(1, 3, 5)))
    )
    octree = tree.to_open3d_octree()
    assert isinstance(octree, o3d.geometry.Octree)
    inside = np.argwhere(labels >= 0)[0]
    node, _ = octree.locate_leaf_node(UTM + inside + 0.5)
    assert node is not None
