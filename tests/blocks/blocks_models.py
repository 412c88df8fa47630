"""Small conformal (and deliberately non-conformal) surface models whose blocks are known by hand.

Every model is a box ``[0, size]³`` (shifted by ``origin``) whose six faces are structured grids
with outward normals; horizons are horizontal grids with upward normals. Grid rows are shared
wherever surfaces meet, so the models are conformal unless a builder below breaks that on
purpose. Shared by the tests of ``tests/blocks`` (``from blocks_models import ...``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from geobrep import Surface

FloatArray = NDArray[np.float64]


def grid_surface(
    points: FloatArray, name: str, kind: str | None = None, flip: bool = False
) -> Surface:
    """A surface from a (rows, cols, 3) point grid; normal = ∂(rows) × ∂(cols), or flipped."""
    rows, cols = points.shape[:2]
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    a = (i * cols + j).ravel()
    b, c, d = a + cols, a + cols + 1, a + 1
    faces = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    if flip:
        faces = faces[:, ::-1]
    return Surface(vertices=points.reshape(-1, 3), faces=faces, name=name, kind=kind)


def _plane(u: Sequence[float], v: Sequence[float], place: str, at: float) -> FloatArray:
    """Grid points of an axis-aligned plane: ``place`` is the fixed axis ('x', 'y' or 'z')."""
    uu, vv = np.meshgrid(np.asarray(u, float), np.asarray(v, float), indexing="ij")
    fixed = np.full_like(uu, at)
    if place == "z":  # u = x, v = y: normal +z
        return np.stack([uu, vv, fixed], axis=-1)
    if place == "x":  # u = y, v = z: normal +x
        return np.stack([fixed, uu, vv], axis=-1)
    return np.stack([vv, fixed, uu], axis=-1)  # y: u = z, v = x: normal +y


def box_model(
    levels: Sequence[float] = (0.5,),
    n: int = 4,
    extra_rows: Sequence[float] = (),
    size: float = 1.0,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    wall_rows: Sequence[float] | None = None,
) -> list[Surface]:
    """A box with horizontal horizons ``H1, H2, ...`` at ``levels`` (top to bottom order).

    ``wall_rows`` overrides the heights of the walls' grid rows (to break conformity).
    """
    grid = np.linspace(0.0, size, n + 1)
    rows = sorted({*grid.tolist(), *levels, *extra_rows}) if wall_rows is None else wall_rows
    shift = np.asarray(origin, dtype=np.float64)
    surfaces = [
        grid_surface(_plane(grid, grid, "z", 0.0), "bottom", "boundary", flip=True),
        grid_surface(_plane(grid, grid, "z", size), "top", "boundary"),
        grid_surface(_plane(grid, rows, "x", 0.0), "west", "boundary", flip=True),
        grid_surface(_plane(grid, rows, "x", size), "east", "boundary"),
        grid_surface(_plane(rows, grid, "y", 0.0), "south", "boundary", flip=True),
        grid_surface(_plane(rows, grid, "y", size), "north", "boundary"),
    ]
    for k, level in enumerate(sorted(levels, reverse=True), start=1):
        surfaces.append(grid_surface(_plane(grid, grid, "z", level), f"H{k}", "horizon"))
    return [s.replace(vertices=s.vertices + shift) for s in surfaces]


def vertical_fault(
    x: float, z_rows: Sequence[float], n: int = 4, size: float = 1.0, name: str = "fault"
) -> Surface:
    """A fault plane ``x = const`` across the box (y from 0 to ``size``), rows at ``z_rows``."""
    return grid_surface(_plane(np.linspace(0, size, n + 1), z_rows, "x", x), name, "fault")


def floating_square(z: float, low: float = 0.3, high: float = 0.7) -> Surface:
    """A small horizontal square touching nothing."""
    side = np.linspace(low, high, 3)
    return grid_surface(_plane(side, side, "z", z), "lens", "horizon")


def closed_cube(low: Sequence[float], size: float, name: str = "salt") -> Surface:
    """An outward-oriented closed cube (2 × 2 grid per face), touching nothing."""
    x0, y0, z0 = (float(v) for v in low)
    side = [0.0, size / 2, size]
    faces = [
        grid_surface(_plane(side, side, "z", 0.0), name, flip=True),
        grid_surface(_plane(side, side, "z", size), name),
        grid_surface(_plane(side, side, "x", 0.0), name, flip=True),
        grid_surface(_plane(side, side, "x", size), name),
        grid_surface(_plane(side, side, "y", 0.0), name, flip=True),
        grid_surface(_plane(side, side, "y", size), name),
    ]
    offsets = np.cumsum([0] + [f.n_vertices for f in faces])
    vertices = np.concatenate([f.vertices for f in faces]) + np.array([x0, y0, z0])
    triangles = np.concatenate([f.faces + o for f, o in zip(faces, offsets, strict=False)])
    return Surface(vertices=vertices, faces=triangles, name=name, kind="salt")


def wedge_model(epsilon: float) -> list[Surface]:
    """A unit box with H1 at z = 0.5 and H2 rising from H1 at x = 0.5 with slope ``epsilon``.

    H2 meets H1 at an angle of ``atan(epsilon)`` along the line x = 0.5: a thin wedge block of
    volume ``epsilon / 8`` lies between them.
    """
    grid = np.linspace(0.0, 1.0, 5)
    east = grid[grid >= 0.5]

    def h2(x: FloatArray | float) -> FloatArray:
        return np.asarray(0.5 + epsilon * (np.asarray(x, dtype=np.float64) - 0.5))

    top_of_east = float(h2(1.0))
    east_rows = [0.0, 0.25, 0.5, top_of_east, 0.75, 1.0]
    h2_points = np.stack(np.meshgrid(east, grid, indexing="ij"), axis=-1)
    h2_points = np.concatenate([h2_points, h2(h2_points[..., :1])], axis=-1)
    surfaces = [
        grid_surface(_plane(grid, grid, "z", 0.0), "bottom", "boundary", flip=True),
        grid_surface(_plane(grid, grid, "z", 1.0), "top", "boundary"),
        grid_surface(_plane(grid, [0.0, 0.25, 0.5, 0.75, 1.0], "x", 0.0), "west", "boundary", True),
        grid_surface(_plane(grid, east_rows, "x", 1.0), "east", "boundary"),
        grid_surface(_plane(grid, grid, "z", 0.5), "H1", "horizon"),
        grid_surface(h2_points, "H2", "horizon"),
    ]
    for y, name, flip in ((0.0, "south", True), (1.0, "north", False)):
        parts = []
        # Below H1: rows 0, 0.25, 0.5 over every column (u = z, v = x gives normal +y).
        parts.append(_plane([0.0, 0.25, 0.5], grid, "y", y))
        # The wedge: from z = 0.5 up to H2, over x ≥ 0.5.
        wedge = np.stack(
            [
                np.stack([east, np.full_like(east, y), np.full_like(east, 0.5)], axis=-1),
                np.stack([east, np.full_like(east, y), h2(east)], axis=-1),
            ]
        )
        parts.append(wedge)
        # Above H1 and H2, up to the top.
        floor = np.maximum(0.5, h2(grid))
        above = np.stack(
            [
                np.stack([grid, np.full_like(grid, y), floor], axis=-1),
                np.stack([grid, np.full_like(grid, y), np.full_like(grid, 0.75)], axis=-1),
                np.stack([grid, np.full_like(grid, y), np.full_like(grid, 1.0)], axis=-1),
            ]
        )
        parts.append(above)
        pieces = [grid_surface(p, name, "boundary", flip=flip) for p in parts]
        offsets = np.cumsum([0] + [p.n_vertices for p in pieces])
        vertices = np.concatenate([p.vertices for p in pieces])
        faces = np.concatenate([p.faces + o for p, o in zip(pieces, offsets, strict=False)])
        # The wedge's first quad has two corners at (0.5, y, 0.5): drop its collapsed triangle.
        area = np.linalg.norm(
            np.cross(
                vertices[faces[:, 1]] - vertices[faces[:, 0]],
                vertices[faces[:, 2]] - vertices[faces[:, 0]],
            ),
            axis=1,
        )
        keep = area > 0
        surfaces.append(Surface(vertices=vertices, faces=faces[keep], name=name, kind="boundary"))
    return surfaces
