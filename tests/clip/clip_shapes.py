"""Shapes and checks shared by the clipping tests (``from clip_shapes import ...``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep import Surface

#: A UTM-scale origin: clipping must keep full precision there.
UTM = np.array([450_000.0, 6_700_000.0, -250.0])


def icosphere(
    subdivisions: int = 3, radius: float = 1.0, centre: NDArray[np.float64] | None = None
) -> Surface:
    """A closed, outward-oriented icosphere (trimesh's construction)."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    offset = np.zeros(3) if centre is None else centre
    return Surface(vertices=sphere.vertices + offset, faces=sphere.faces, name="sphere")


def assert_closed_half(surface: Surface | None) -> None:
    """A half of a closed surface: closed, consistently oriented, positive volume."""
    assert surface is not None
    assert surface.is_closed
    assert surface.is_consistently_oriented
    assert surface.volume > 0


def cap_area(surface: Surface) -> float:
    """Area of the faces of the surface's ``cap`` patch."""
    label = surface.patch_names.index("cap")
    assert surface.patch_labels is not None
    return float(surface.face_areas[surface.patch_labels == label].sum())
