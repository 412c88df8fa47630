"""Cross-checks against pyvista (clip_closed_surface, clip) and trimesh (slice_plane with caps)."""

from __future__ import annotations

import numpy as np
import pytest
from clip_shapes import assert_closed_half, cap_area, icosphere

from geobrep import Plane, Surface
from geobrep.ops.clipping import clip

pv = pytest.importorskip("pyvista")
trimesh = pytest.importorskip("trimesh")
pytest.importorskip("shapely")  # trimesh's capping needs it

PLANES = [
    Plane.from_point_normal((0.05, -0.1, 0.02), (1.0, 0.3, 0.2)),
    Plane.from_point_normal((0.0, 0.3, 0.4), (-0.2, 1.0, 0.5)),
]


def _polydata(surface: Surface) -> pv.PolyData:
    faces = np.hstack([np.full((surface.n_faces, 1), 3), surface.faces]).ravel()
    return pv.PolyData(np.asarray(surface.vertices), faces)


def _torus() -> Surface:
    """A closed torus (genus 1): its cut can have two loops or a loop with a hole."""
    u, v = np.meshgrid(
        np.linspace(0, 2 * np.pi, 48, endpoint=False),
        np.linspace(0, 2 * np.pi, 24, endpoint=False),
        indexing="ij",
    )
    x = (2 + 0.7 * np.cos(v)) * np.cos(u)
    y = (2 + 0.7 * np.cos(v)) * np.sin(u)
    z = 0.7 * np.sin(v)
    index = np.arange(u.size).reshape(u.shape)
    a, b = index, np.roll(index, -1, axis=0)
    c, d = np.roll(b, -1, axis=1), np.roll(a, -1, axis=1)
    faces = np.concatenate(
        [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    )
    return Surface(vertices=np.stack([x, y, z], -1).reshape(-1, 3), faces=faces, name="torus")


@pytest.mark.parametrize("plane", PLANES)
@pytest.mark.parametrize("shape", ["sphere", "torus"])
def test_same_volumes_and_areas_as_pyvista(plane: Plane, shape: str) -> None:
    surface = icosphere(3) if shape == "sphere" else _torus()
    if surface.volume < 0:
        surface = surface.flipped()
    negative = clip(surface, plane, keep="negative")
    positive = clip(surface, plane, keep="positive")
    assert_closed_half(negative)
    assert_closed_half(positive)
    mesh = _polydata(surface)
    origin = plane.point
    # clip_closed_surface keeps the side the normal points to; clip(invert=True) the other.
    closed = mesh.clip_closed_surface(normal=plane.normal, origin=origin)
    assert positive.volume == pytest.approx(closed.volume, rel=1e-9)
    assert positive.area == pytest.approx(closed.area, rel=1e-9)
    open_negative = mesh.clip(normal=plane.normal, origin=origin, invert=True)
    side_area = negative.area - cap_area(negative)
    assert side_area == pytest.approx(open_negative.area, rel=1e-9)


@pytest.mark.parametrize("plane", PLANES)
def test_same_volumes_and_areas_as_trimesh(plane: Plane) -> None:
    surface = icosphere(3)
    sphere = trimesh.Trimesh(np.asarray(surface.vertices), np.asarray(surface.faces), process=False)
    origin = plane.point
    # slice_plane keeps the side its normal points to: pass -n for our negative side.
    theirs = sphere.slice_plane(origin, -plane.normal, cap=True)
    ours = clip(surface, plane, keep="negative")
    assert theirs.is_watertight
    assert ours.volume == pytest.approx(theirs.volume, rel=1e-9)
    assert ours.area == pytest.approx(theirs.area, rel=1e-9)
