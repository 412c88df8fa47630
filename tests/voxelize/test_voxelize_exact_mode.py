"""Exact mode on folded, hollow and overlapping bodies; auto mode switching and saying so."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import voxel_bodies as vb
from test_voxelize_structure import centres, inside_truth

from geobrep import Surface
from geobrep.ops.voxelization import VoxelizationWarning, voxelize

DEPTH = 5


def misclassified(tree_inside: np.ndarray, truth: np.ndarray) -> tuple[int, int]:
    """(voxels wrongly inside, voxels wrongly outside)."""
    return int(np.count_nonzero(tree_inside & ~truth)), int(np.count_nonzero(~tree_inside & truth))


@pytest.fixture(scope="module")
def fold() -> Surface:
    return vb.c_shape()


def test_exact_mode_matches_containment_on_a_folded_body(fold: Surface) -> None:
    exact = voxelize(fold, depth=DEPTH, method="exact")
    points = centres(exact)
    truth = inside_truth("fold", fold, points)
    assert misclassified(exact.contains(points), truth) == (0, 0)
    report = vb.body_report(exact)
    assert report["method"] == "exact"
    assert report["depth_buffers_exact"] is None  # only z rays were cast


def test_depth_buffer_error_on_the_fold_is_reported(
    fold: Surface, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.warns(VoxelizationWarning, match="fold.*may be wrong") as caught:
        buffers = voxelize(fold, depth=DEPTH, method="depth-buffer")
    message = str(caught[0].message)
    assert "rays along every axis cross it more than twice" in message
    points = centres(buffers)
    truth = inside_truth("fold", fold, points)
    wrong_in, wrong_out = misclassified(buffers.contains(points), truth)
    cell = (buffers.size / 2**DEPTH) ** 3
    error = wrong_in * cell / fold.volume
    print(
        f"depth-buffer mode on the fold: {wrong_in} voxels filled in the fold core, "
        f"{wrong_out} missed; volume error {error:+.1%} of the body"
    )
    assert wrong_out == 0  # each axis test keeps every inside voxel
    assert wrong_in > 0  # the fold core is filled in: the error the exact mode removes
    exact = voxelize(fold, depth=DEPTH, method="exact")
    assert buffers.volume == pytest.approx(exact.volume + wrong_in * cell)
    assert "volume error" in capsys.readouterr().out


def test_auto_switches_to_exact_and_says_so(fold: Surface) -> None:
    with pytest.warns(VoxelizationWarning, match="exact mode .all crossings. was used"):
        auto = voxelize(fold, depth=DEPTH, method="auto")
    exact = voxelize(fold, depth=DEPTH, method="exact")
    np.testing.assert_array_equal(auto.codes, exact.codes)
    report = vb.body_report(auto)
    assert report["method"] == "exact"
    assert report["depth_buffers_exact"] is False
    assert report["max_crossings"] >= 4
    assert min(report["rays_over_two"].values()) > 0


def test_auto_uses_one_axis_of_depth_buffers_when_it_suffices() -> None:
    # A ring about the x axis: z and y rays cross it four times, x rays at most twice, so the
    # depth buffers of the x axis alone are exact.
    ring = vb.torus(1.0, 0.3)
    turned = ring.replace(vertices=ring.vertices[:, [2, 0, 1]])
    with warnings.catch_warnings():
        warnings.simplefilter("error", VoxelizationWarning)
        tree = voxelize(turned, depth=DEPTH, method="auto")
    report = vb.body_report(tree)
    assert report["method"] == "depth-buffer"
    assert report["depth_buffer_axes"] == ["x"]
    assert report["depth_buffers_exact"] is True
    assert report["rays_over_two"]["z"] > 0
    assert report["rays_over_two"]["x"] == 0
    assert report["rays_over_two"]["y"] is None  # not needed, not cast
    np.testing.assert_array_equal(tree.codes, voxelize(turned, depth=DEPTH, method="exact").codes)
    upright = vb.body_report(voxelize(ring, depth=DEPTH, method="auto"))
    assert upright["depth_buffer_axes"] == ["z"]
    patent = vb.body_report(voxelize(ring, depth=DEPTH, method="depth-buffer"))
    assert patent["depth_buffer_axes"] == ["x", "y", "z"]
    assert patent["rays_over_two"]["x"] > 0


def test_hollow_body() -> None:
    shell = vb.hollow_sphere()
    exact = voxelize(shell, depth=DEPTH, method="exact")
    points = centres(exact)
    truth = inside_truth("shell", shell, points)
    assert misclassified(exact.contains(points), truth) == (0, 0)
    assert exact.contains([[0.0, 0.0, 0.0]]).tolist() == [False]  # the cavity stays empty
    with pytest.warns(VoxelizationWarning):
        buffers = voxelize(shell, depth=DEPTH, method="depth-buffer")
    assert buffers.contains([[0.0, 0.0, 0.0]]).tolist() == [True]  # depth buffers fill it
    outer = voxelize(vb.ellipsoid((1.0, 1.0, 1.0), rings=24, segments=48), depth=DEPTH)
    assert buffers.volume == pytest.approx(outer.volume, rel=0.01)
    assert exact.volume == pytest.approx(abs(shell.volume), rel=0.03)


def test_fill_rules_on_overlapping_shells() -> None:
    # Two overlapping outward spheres in one surface: parity leaves the overlap empty,
    # the non-zero winding rule fills the union.
    a = vb.ellipsoid((1.0, 1.0, 1.0), centre=(-0.4, 0.0, 0.0), rings=24, segments=48)
    b = vb.ellipsoid((1.0, 1.0, 1.0), centre=(0.4, 0.0, 0.0), rings=24, segments=48)
    both = Surface(
        vertices=np.concatenate([a.vertices, b.vertices]),
        faces=np.concatenate([a.faces, b.faces + a.n_vertices]),
        name="pair",
    )
    parity = voxelize(both, depth=DEPTH, method="exact", fill_rule="parity")
    union = voxelize(both, depth=DEPTH, method="exact", fill_rule="nonzero")
    middle = [[0.0, 0.0, 0.0]]
    assert parity.contains(middle).tolist() == [False]
    assert union.contains(middle).tolist() == [True]
    assert union.contains([[-1.2, 0.0, 0.0], [1.2, 0.0, 0.0]]).all()
    one = voxelize(a, depth=DEPTH, method="exact", origin=tuple(parity.origin), size=parity.size)
    cap = 2 * one.volume - union.volume  # the lens where the spheres overlap
    assert parity.volume == pytest.approx(union.volume - cap, rel=0.02)
    flipped = both.replace(faces=both.faces[:, ::-1])  # inward: winding -1 inside, still filled
    np.testing.assert_array_equal(
        voxelize(flipped, depth=DEPTH, method="exact", fill_rule="nonzero").codes, union.codes
    )


def test_exact_mode_agrees_with_trimesh_contains(fold: Surface) -> None:
    trimesh = pytest.importorskip("trimesh")
    exact = voxelize(fold, depth=DEPTH, method="exact")
    rng = np.random.default_rng(7)
    points = centres(exact)
    sample = points[rng.choice(len(points), 400, replace=False)]
    mesh = trimesh.Trimesh(fold.vertices, fold.faces, process=False)
    np.testing.assert_array_equal(exact.contains(sample), mesh.contains(sample))
