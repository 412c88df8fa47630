"""Closed test bodies with known volumes for the voxelizer tests (outward-oriented triangles)."""

from __future__ import annotations

from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from geobrep import LinearOctree, Surface
from geobrep.geometry import signed_volume

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def body_report(tree: LinearOctree, index: int = 0) -> dict[str, Any]:
    """The voxelizer's report on one body (``metadata["voxelization"]["bodies"][index]``)."""
    report = cast("dict[str, Any]", tree.metadata["voxelization"])
    return cast("dict[str, Any]", report["bodies"][index])


def _grid_faces(rows: int, cols: int, wrap_rows: bool, wrap_cols: bool) -> IntArray:
    """Two triangles per cell of a ``rows × cols`` vertex grid (indices ``r * cols + c``)."""
    r_max = rows if wrap_rows else rows - 1
    c_max = cols if wrap_cols else cols - 1
    r, c = np.meshgrid(np.arange(r_max), np.arange(c_max), indexing="ij")
    r, c = r.ravel(), c.ravel()
    a = r * cols + c
    b = r * cols + (c + 1) % cols
    d = ((r + 1) % rows) * cols + c
    e = ((r + 1) % rows) * cols + (c + 1) % cols
    return np.concatenate([np.stack([a, b, e], 1), np.stack([a, e, d], 1)]).astype(np.int64)


def _outward(vertices: FloatArray, faces: IntArray, name: str) -> Surface:
    if signed_volume(vertices, faces) < 0:
        faces = faces[:, ::-1]
    return Surface(vertices=vertices, faces=faces, name=name)


def ellipsoid(
    radii: tuple[float, float, float] = (1.0, 1.0, 1.0),
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0),
    rings: int = 96,
    segments: int = 192,
    name: str = "ellipsoid",
) -> Surface:
    """A UV ellipsoid (sphere when the radii are equal) with two pole vertices."""
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]  # latitudes without the poles
    phi = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    unit = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    poles = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    vertices = np.concatenate([unit, poles]) * np.asarray(radii) + np.asarray(centre)
    body = _grid_faces(rings - 1, segments, wrap_rows=False, wrap_cols=True)
    north, south = len(unit), len(unit) + 1
    c = np.arange(segments)
    top = np.stack([np.full(segments, north), (c + 1) % segments, c], 1)
    last = (rings - 2) * segments
    bottom = np.stack([np.full(segments, south), last + c, last + (c + 1) % segments], 1)
    return _outward(vertices, np.concatenate([body, top, bottom]).astype(np.int64), name)


def ellipsoid_volume(radii: tuple[float, float, float]) -> float:
    return 4.0 / 3.0 * np.pi * radii[0] * radii[1] * radii[2]


def torus(
    major: float = 1.0,
    minor: float = 0.4,
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0),
    around: int = 192,
    tube: int = 96,
    name: str = "torus",
) -> Surface:
    """A torus around the z axis."""
    u = np.linspace(0, 2 * np.pi, around, endpoint=False)
    v = np.linspace(0, 2 * np.pi, tube, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ring = major + minor * np.cos(vv)
    vertices = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(vv)], -1)
    vertices = vertices.reshape(-1, 3) + np.asarray(centre)
    faces = _grid_faces(around, tube, wrap_rows=True, wrap_cols=True)
    return _outward(vertices, faces, name)


def torus_volume(major: float, minor: float) -> float:
    return 2.0 * np.pi**2 * major * minor**2


def rotation(axis: tuple[float, float, float], angle: float) -> FloatArray:
    """Rotation matrix about ``axis`` by ``angle`` radians (Rodrigues)."""
    k = np.asarray(axis, dtype=np.float64)
    k = k / np.linalg.norm(k)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


C_INNER, C_OUTER, C_LENGTH, C_OPENING, C_SEGMENTS = 0.45, 1.0, 2.4, 0.9, 64


def _c_frame() -> FloatArray:
    """Rotation taking the C's local frame (axis z) to the model frame (axis (1, 1, 1))."""
    axis_to_diagonal = np.cross([0.0, 0.0, 1.0], [1.0, 1.0, 1.0])
    turn = rotation(
        (float(axis_to_diagonal[0]), float(axis_to_diagonal[1]), 0.0), np.arccos(1 / np.sqrt(3))
    )
    spin = rotation((0.0, 0.0, 1.0), 0.3)
    return turn @ spin


def c_shape(name: str = "fold") -> Surface:
    """A folded, C-shaped body: an annulus sector (mouth ``C_OPENING`` radians) extruded along
    its axis, then turned so the axis is the diagonal (1, 1, 1): the fold core is walled on both
    sides along x, y and z, where depth buffers fill it in."""
    angles = np.linspace(C_OPENING / 2, 2 * np.pi - C_OPENING / 2, C_SEGMENTS + 1)
    outer_ring = np.stack([C_OUTER * np.cos(angles), C_OUTER * np.sin(angles)], 1)
    inner_ring = np.stack([C_INNER * np.cos(angles), C_INNER * np.sin(angles)], 1)
    profile = np.concatenate([outer_ring, inner_ring[::-1]])  # closed loop, counter-clockwise
    m = len(profile)
    bottom = np.column_stack([profile, np.full(m, -C_LENGTH / 2)])
    top = np.column_stack([profile, np.full(m, C_LENGTH / 2)])
    vertices = np.concatenate([bottom, top])
    i = np.arange(C_SEGMENTS)
    o0, o1 = i, i + 1  # outer ring indices
    n0, n1 = m - 1 - i, m - 2 - i  # inner ring indices at the same angles
    cap = np.concatenate([np.stack([o0, o1, n1], 1), np.stack([o0, n1, n0], 1)])
    j = np.arange(m)
    k = (j + 1) % m
    walls = np.concatenate([np.stack([j, k, k + m], 1), np.stack([j, k + m, j + m], 1)])
    faces = np.concatenate([cap[:, ::-1], cap + m, walls]).astype(np.int64)
    return _outward(vertices @ _c_frame().T, faces, name)


def c_shape_inside(points: FloatArray) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Analytic containment for :func:`c_shape`: ``(inside, certain)``.

    Caps and mouth walls are planes of the mesh; the arcs are polygons inscribed in their
    circles, so only points between a circle and its polygon are uncertain.
    """
    local = np.asarray(points) @ _c_frame()  # inverse rotation
    rho = np.hypot(local[:, 0], local[:, 1])
    angle = np.mod(np.arctan2(local[:, 1], local[:, 0]), 2 * np.pi)
    chord = np.cos((2 * np.pi - C_OPENING) / C_SEGMENTS / 2)
    in_slab = np.abs(local[:, 2]) < C_LENGTH / 2
    in_sector = (angle > C_OPENING / 2) & (angle < 2 * np.pi - C_OPENING / 2)
    inside = in_slab & in_sector & (rho > C_INNER) & (rho < C_OUTER * chord)
    band = ((rho >= C_OUTER * chord) & (rho <= C_OUTER)) | (
        (rho >= C_INNER * chord) & (rho <= C_INNER)
    )
    return inside, ~(band & in_slab & in_sector)


def convex_inside(
    surface: Surface, centre: FloatArray, points: FloatArray
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """``(inside, certain)`` for a convex mesh around ``centre``: inside the ball touching its
    nearest face plane, outside the ball through its farthest vertex; between is uncertain."""
    v, f = surface.vertices - centre, surface.faces
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    nearest = np.abs(np.einsum("ij,ij->i", normals, v[f[:, 0]])).min()
    farthest = np.linalg.norm(v, axis=1).max()
    r = np.linalg.norm(np.asarray(points) - centre, axis=1)
    return r < nearest, (r < nearest) | (r > farthest)


def hollow_sphere(outer: float = 1.0, inner: float = 0.55, name: str = "shell") -> Surface:
    """A sphere with a spherical cavity: two shells, the inner one facing inwards."""
    a = ellipsoid((outer,) * 3, rings=24, segments=48)
    b = ellipsoid((inner,) * 3, rings=16, segments=32)
    vertices = np.concatenate([a.vertices, b.vertices])
    faces = np.concatenate([a.faces, b.faces[:, ::-1] + a.n_vertices])
    return Surface(vertices=vertices, faces=faces, name=name)


def box(
    lo: tuple[float, float, float], hi: tuple[float, float, float], name: str = "box"
) -> Surface:
    """An axis-aligned box as 12 outward triangles (each face split along a diagonal)."""
    corners = np.array(
        [[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])],
        dtype=np.float64,
    )
    faces = np.array(
        [
            [0, 2, 3], [0, 3, 1],  # z = lo
            [4, 5, 7], [4, 7, 6],  # z = hi
            [0, 1, 5], [0, 5, 4],  # y = lo
            [2, 6, 7], [2, 7, 3],  # y = hi
            [0, 4, 6], [0, 6, 2],  # x = lo
            [1, 3, 7], [1, 7, 5],  # x = hi
        ],
        dtype=np.int64,
    )  # fmt: skip
    return _outward(corners, faces, name)


def octahedron(centre: tuple[float, float, float], radius: float, name: str = "octa") -> Surface:
    """A regular octahedron (its vertices on the axes through ``centre``)."""
    c = np.asarray(centre, dtype=np.float64)
    vertices = c + radius * np.array(
        [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64
    )
    faces = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
        dtype=np.int64,
    )
    return _outward(vertices, faces, name)
