"""PointSet, LinearOctree and NurbsSurface clippers."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import LinearOctree, NurbsSurface, Plane, PointSet
from geobrep.errors import DegenerateGeometryError
from geobrep.ops.clipping import clip, section
from geobrep.plugins.clip._nurbs import trimmed_mesh


def test_points_on_the_plane_belong_to_both_sides() -> None:
    points = PointSet(
        vertices=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], point_data={"v": [1.0, 2.0, 3.0]}, name="p"
    )
    left, right = clip(points, Plane.x(1.0), keep="both")
    assert left.vertices[:, 0].tolist() == [0.0, 1.0]
    assert right.point_data["v"].values.tolist() == [2.0, 3.0]
    assert clip(points, Plane.x(5.0)) is points
    assert section(points, Plane.x(1.0)).n_points == 1


def _tree(depth: int = 4) -> LinearOctree:
    return LinearOctree(
        codes=[0, 8 ** (depth - 1)],
        levels=[1, 1],
        depth=depth,
        origin=[0, 0, 0],
        size=16.0,
        labels=[3, 4],
        cell_data={"rock": [1.5, 2.5]},
    )


def test_octree_subdivision_partitions_the_leaves() -> None:
    tree = _tree()
    plane = Plane(1.0, 1.0, 0.0, -9.3)
    negative, positive = clip(tree, plane, keep="both")
    assert negative.volume + positive.volume == pytest.approx(tree.volume)
    for half in (negative, positive):
        assert np.all(np.diff(half.codes.astype(np.int64)) > 0)
        assert set(half.labels.tolist()) <= {3, 4}
        assert set(half.cell_data["rock"].values.tolist()) <= {1.5, 2.5}
    finest = negative.levels == tree.depth
    assert finest.any()
    assert (negative.levels < tree.depth).any()


def test_octree_by_centre_keeps_whole_leaves() -> None:
    tree = _tree()
    centre = {"octree": {"straddling": "centre"}}
    negative, positive = clip(tree, Plane.x(5.0), keep="both", options=centre)
    assert negative.n_leaves == 1
    assert positive.n_leaves == 1
    assert negative.levels.tolist() == [1]
    assert clip(tree, Plane.x(3.0), options=centre) is None


def test_octree_too_fine_to_subdivide() -> None:
    deep = LinearOctree(codes=[0], levels=[0], depth=21, origin=[0, 0, 0], size=1.0)
    with pytest.raises(DegenerateGeometryError, match="straddling='centre'"):
        clip(deep, Plane(1.0, 1.0, 1.0, -1.2345))


def _nurbs() -> NurbsSurface:
    u = np.linspace(0.0, 1.0, 4)
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = u[:, None], u[None, :]
    net[..., 2] = 0.2 * np.sin(3 * u[:, None])
    knots = [0, 0, 0, 0, 1, 1, 1, 1]
    return NurbsSurface(
        degree_u=3, degree_v=3, knots_u=knots, knots_v=knots, control_points=net, name="fit"
    )


def test_nurbs_is_trimmed_exactly() -> None:
    surface = _nurbs()
    negative, positive = clip(surface, Plane.x(0.3), keep="both")
    assert negative.metadata["clip_planes"] == [[1.0, 0.0, 0.0, -0.3]]
    assert np.array_equal(negative.control_points, surface.control_points)
    whole = surface.tessellate(resolution=65).area
    assert trimmed_mesh(negative).area + trimmed_mesh(positive).area == pytest.approx(
        whole, rel=1e-12
    )
    assert clip(surface, Plane.x(2.0)) is surface
    assert clip(surface, Plane.x(-1.0)) is None
    twice = clip(negative, Plane.y(0.5))
    assert len(twice.metadata["clip_planes"]) == 2
