"""Octree volumes of bodies with analytic volumes: within 1 % at depth 7, converging with depth."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import voxel_bodies as vb

from geobrep import Surface
from geobrep.ops.voxelization import VoxelizationWarning, voxelize

RADII = (1.3, 0.8, 0.5)
SHIFT = np.array([450_000.0, 6_700_000.0, -1_200.0])
CASES = {
    "sphere": (lambda: vb.ellipsoid((1.0, 1.0, 1.0)), vb.ellipsoid_volume((1.0, 1.0, 1.0))),
    "ellipsoid": (lambda: vb.ellipsoid(RADII), vb.ellipsoid_volume(RADII)),
    "torus": (lambda: vb.torus(1.0, 0.4), vb.torus_volume(1.0, 0.4)),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def body(request: pytest.FixtureRequest) -> tuple[str, Surface, float]:
    make, volume = CASES[request.param]
    return request.param, make(), volume


def test_volume_within_one_percent_at_depth_7(body: tuple[str, Surface, float]) -> None:
    name, surface, analytic = body
    for method in ("depth-buffer", "exact", "auto"):
        tree = voxelize(surface, depth=7, method=method)
        assert tree.depth == 7
        assert abs(tree.volume - analytic) / analytic < 0.01, (name, method, tree.volume)


def test_volume_converges_with_depth(body: tuple[str, Surface, float]) -> None:
    _, surface, analytic = body
    errors = [abs(voxelize(surface, depth=d).volume - analytic) / analytic for d in (3, 5, 7)]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.002


def test_modes_agree_on_bodies_convex_along_the_axes(body: tuple[str, Surface, float]) -> None:
    # Sphere and ellipsoid are convex; the torus about z has at most two crossings on z rays,
    # so the depth buffers are exact for all three and must equal the exact mode leaf by leaf.
    _, surface, _ = body
    with warnings.catch_warnings():
        warnings.simplefilter("error", VoxelizationWarning)
        buffers = voxelize(surface, depth=6, method="depth-buffer")
        auto = voxelize(surface, depth=6, method="auto")
    exact = voxelize(surface, depth=6, method="exact")
    np.testing.assert_array_equal(buffers.codes, exact.codes)
    np.testing.assert_array_equal(buffers.levels, exact.levels)
    assert vb.body_report(auto)["method"] == "depth-buffer"


def test_tilted_torus_needs_the_exact_mode() -> None:
    # Axis along (1, 1, 1): rays along x, y and z all pass the tube, the hole, the tube.
    surface = vb.torus(1.0, 0.7)
    turn = vb.rotation((-1.0, 1.0, 0.0), float(np.arccos(1 / np.sqrt(3))))
    turned = surface.replace(vertices=surface.vertices @ turn.T)
    analytic = vb.torus_volume(1.0, 0.7)
    with pytest.warns(VoxelizationWarning, match="exact mode"):
        auto = voxelize(turned, depth=7, method="auto")
    assert vb.body_report(auto)["method"] == "exact"
    assert abs(auto.volume - analytic) / analytic < 0.01
    with pytest.warns(VoxelizationWarning, match="may be wrong"):
        buffers = voxelize(turned, depth=7, method="depth-buffer")
    assert buffers.volume > auto.volume  # the buffers fill part of the hole
    assert not np.array_equal(buffers.codes, auto.codes)


def test_utm_coordinates_give_the_same_octree() -> None:
    sphere = vb.ellipsoid((100.0, 100.0, 100.0), rings=48, segments=96)
    shifted = sphere.replace(vertices=sphere.vertices + SHIFT)
    here, there = voxelize(sphere, depth=7), voxelize(shifted, depth=7)
    np.testing.assert_array_equal(here.codes, there.codes)
    np.testing.assert_array_equal(here.levels, there.levels)
    np.testing.assert_allclose(there.origin, here.origin + SHIFT)
    assert there.origin[0] == pytest.approx(449_900.0, abs=1e-6)
