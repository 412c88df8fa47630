"""geobrep.model.arcs: the patch order around every arc (sorted for all arcs at once) and the
BSTONE corners (exact vertices found without a search) agree with the one-arc-at-a-time rule."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Scene, Surface
from geobrep.errors import DegenerateGeometryError
from geobrep.geometry import mesh
from geobrep.model.arcs import (
    ArcChains,
    _around,
    _corner_hints,
    _nearest,
    _patch_orders,
    build_corners_and_arcs,
    chain_arc_edges,
)
from geobrep.model.topology import Topology


def _blades(angles: list[float], sliver: bool = False) -> Scene:
    """Half-planes about the z axis (two triangles each, along (0,0,0)-(0,0,1)-(0,0,2)), one
    surface per angle; with ``sliver`` the first blade's lower triangle lies almost along the
    axis, so the order must be read on the axis' second edge."""
    surfaces = []
    for k, angle in enumerate(angles):
        outer = [2 * np.cos(angle), 2 * np.sin(angle), 0.8 + 0.05 * k]
        vertices = [[0, 0, 0], [0, 0, 1], [0, 0, 2], outer, [1e-15, 0.0, 0.5]]
        faces = [[0, 1, 3], [1, 2, 3]]
        if sliver and k == 0:
            faces = [[0, 1, 4], [1, 2, 3], [1, 3, 4]]
        surfaces.append(Surface(vertices=vertices, faces=faces, name=f"blade{k}", id=k))
    return Scene(entities=surfaces)


def _expected_order(scene: Scene, topology: Topology, points: np.ndarray) -> tuple[int, ...]:
    """The patches around the first edge of ``points`` that sorts (the rule, one edge at a
    time), found by coordinates among all triangles of the scene."""
    patch_of = {(p.surface, p.label): p.id for p in topology.patches}
    members: list[int] | None = None
    for k in range(points.shape[0] - 1):
        origin, tip = points[k], points[k + 1]
        thirds, patches = [], []
        for surface in scene.surfaces:
            corners = surface.vertices[surface.faces]  # (F, 3, 3)
            at_origin = (corners == origin).all(axis=2)
            at_tip = (corners == tip).all(axis=2)
            for face in np.flatnonzero(at_origin.any(axis=1) & at_tip.any(axis=1)):
                third = np.flatnonzero(~at_origin[face] & ~at_tip[face])[0]
                thirds.append(corners[face, third])
                label = 0 if surface.patch_labels is None else int(surface.patch_labels[face])
                patches.append(patch_of[(int(surface.id or 0), label)])
        if members is None:
            members = patches
        if len(patches) < 2:
            return tuple(patches)
        try:
            order = mesh.sort_around_axis(origin, tip - origin, np.array(thirds) - origin)
        except DegenerateGeometryError:
            continue
        return tuple(patches[i] for i in order)
    return tuple(members or ())


def _cyclic_equal(a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    return len(a) == len(b) and any(a == b[i:] + b[:i] for i in range(len(b)))


@pytest.mark.parametrize("sliver", [False, True])
def test_patches_about_each_arc_follow_the_right_hand_rule(sliver: bool) -> None:
    rng = np.random.default_rng(7)
    scene = _blades(sorted(rng.uniform(0, 2 * np.pi, 7).tolist()), sliver=sliver)
    topology = build_corners_and_arcs(scene)
    axis = [a for a in topology.arcs if len(a.patches) == 7]
    assert len(axis) == 1  # the z axis, shared by every blade
    for arc in topology.arcs:
        expected = _expected_order(scene, topology, arc.points)
        assert _cyclic_equal(arc.patches, expected), (arc.id, arc.patches, expected)
    # counter-clockwise seen from the axis tip: the angles of the blades increase
    upward = axis[0].points[-1][2] > axis[0].points[0][2]
    ccw = tuple(range(7)) if upward else (0, *range(6, 0, -1))
    assert _cyclic_equal(axis[0].patches, ccw)


def _fan_inputs(
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, ArcChains]:
    """A soup of random triangles fanned about shared edges (each triangle its own patch), and
    the arc chains of its edges."""
    points = rng.normal(size=(40, 3))
    points[:5] = [[0, 0, 0], [0, 0, 1], [0, 0, 1 + 1e-16], [1, 0, 0], [0, 1, 0]]
    tri: list[list[int]] = []
    for _ in range(120):
        a, b = rng.choice(8, size=2, replace=False)
        tri.append([int(a), int(b), int(rng.integers(8, 40))])
    tri.append([0, 1, 2])  # a sliver along the edge 0-1
    tri_array = np.unique(np.array(tri, dtype=np.int64), axis=0)
    tri_array = tri_array[
        (tri_array[:, 0] != tri_array[:, 1]) & (tri_array[:, 1] != tri_array[:, 2])
    ]
    edges, offsets, incident, sides = mesh.edge_face_incidence(tri_array)
    owners = np.arange(tri_array.shape[0], dtype=np.int64)
    incident_patch = owners[incident]
    arc_edges = np.arange(edges.shape[0], dtype=np.int64)
    chains = chain_arc_edges(
        edges, offsets, incident_patch, arc_edges, points.shape[0], points=points
    )
    return points, tri_array, offsets, incident, sides, incident_patch, chains


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_patch_orders_of_all_arcs_equal_the_one_arc_rule(seed: int) -> None:
    points, tri, offsets, incident, sides, incident_patch, chains = _fan_inputs(
        np.random.default_rng(seed)
    )
    orders = _patch_orders(chains, points, tri, offsets, incident, sides, incident_patch)
    assert len(orders) == chains.n_arcs
    several = 0
    for a, order in enumerate(orders):
        expected = _around(chains, a, points, tri, offsets, incident, sides, incident_patch)
        assert order.tolist() == expected.tolist(), a
        several += order.shape[0] > 2
    assert several  # some arcs have three patches or more about them


def test_corner_hints_equal_the_nearest_search() -> None:
    rng = np.random.default_rng(3)
    merged = np.round(rng.uniform(-1e5, 1e5, size=(500, 3)), 2) + np.array([4.5e5, 6.7e6, 0])
    tolerance = 1e-3
    exact = merged[rng.choice(500, 40, replace=False)]
    exact[:3, 2] = np.where(exact[:3, 2] == 0, -0.0, exact[:3, 2])
    near = merged[rng.choice(500, 20, replace=False)] + rng.uniform(-4e-4, 4e-4, (20, 3))
    far = merged[rng.choice(500, 10, replace=False)] + 0.5
    wanted = np.concatenate([exact, near, far, exact[:5]])  # a BSTONE listed twice
    centre = 0.5 * (merged.min(axis=0) + merged.max(axis=0))
    expected = np.zeros(500, dtype=bool)
    expected[_nearest(merged - centre, wanted - centre, tolerance * 1.0000001)] = True
    hints = _corner_hints(merged, wanted, tolerance)
    assert hints.tolist() == expected.tolist()
    assert 40 <= int(hints.sum()) <= 60
    # no tolerance: only exact coordinates count, found by the search itself
    assert _corner_hints(merged, wanted, 0.0).sum() == 40
