"""Surface clipping: closed surfaces capped and conserved, open surfaces shared and interpolated."""

from __future__ import annotations

import math

import numpy as np
import pytest
from clip_shapes import UTM, assert_closed_half, cap_area, icosphere
from shapes import make_cube

from geobrep import Plane, Property, Surface
from geobrep.errors import DegenerateGeometryError, PluginError
from geobrep.ops.clipping import clip


@pytest.mark.parametrize(
    ("plane", "section_area"),
    [
        (Plane.x(0.5), 1.0),
        (Plane.from_point_normal((0.5, 0.5, 0.5), (1, 1, 0)), math.sqrt(2.0)),
        (Plane.from_point_normal((0.5, 0.5, 0.5), (1, 1, 1)), 3 * math.sqrt(3) / 4),
        (Plane.from_point_normal((0.2, 0.2, 0.2), (1, 1, 1)), math.sqrt(3) / 2 * 0.6**2),
        (Plane.from_point_normal((0.3, 0.6, 0.25), (0.2, 0.3, 1.0)), None),
    ],
)
def test_cube_halves_are_closed_and_conserve_volume(
    plane: Plane, section_area: float | None
) -> None:
    cube = make_cube(UTM)
    shifted = Plane(
        plane.a,
        plane.b,
        plane.c,
        plane.d - float(plane.normal @ UTM) * math.hypot(plane.a, plane.b, plane.c),
    )
    negative, positive = clip(cube, shifted, keep="both")
    assert_closed_half(negative)
    assert_closed_half(positive)
    assert negative.volume + positive.volume == pytest.approx(1.0, rel=1e-9)
    if section_area is not None:
        assert cap_area(negative) == pytest.approx(section_area, rel=1e-9)
        assert cap_area(positive) == pytest.approx(section_area, rel=1e-9)
    # The cut keeps UTM coordinates exactly: every vertex is an input vertex or on the plane.
    for half in (negative, positive):
        on_plane = np.abs(shifted.signed_distance(half.vertices)) < 1e-8
        original = (half.vertices[:, None, :] == cube.vertices[None, :, :]).all(axis=2).any(axis=1)
        assert (on_plane | original).all()


def test_cube_single_side_matches_both() -> None:
    cube = make_cube()
    plane = Plane.from_point_normal((0.3, 0.6, 0.25), (0.2, 0.3, 1.0))
    negative, positive = clip(cube, plane, keep="both")
    alone = clip(cube, plane, keep="negative")
    assert alone.volume == pytest.approx(negative.volume, rel=1e-12)
    assert alone.n_faces == negative.n_faces
    assert clip(cube, plane, keep="positive").volume == pytest.approx(positive.volume, rel=1e-12)


@pytest.mark.parametrize(
    ("plane", "negative_volume"),
    [
        (Plane.x(1.0), 1.0),  # a face lies in the plane: the cube is all negative
        (Plane.x(0.0), None),  # touching the other face: all positive
        (Plane(1.0, 1.0, 0.0, -1.0), 0.5),  # through two opposite edges (diagonal)
        (Plane(1.0, 1.0, 1.0, 0.0), None),  # touching a single vertex
        (Plane(1.0, 1.0, 1.0, -1.0), 1 / 6),  # through three vertices
        (Plane.z(5.0), 1.0),  # misses it
    ],
)
def test_cube_degenerate_planes(plane: Plane, negative_volume: float | None) -> None:
    cube = make_cube()
    negative, positive = clip(cube, plane, keep="both")
    if negative_volume is None:
        assert negative is None
        assert positive is cube
        return
    assert_closed_half(negative)
    assert negative.volume == pytest.approx(negative_volume, rel=1e-12)
    if negative_volume == 1.0:
        assert negative is cube  # nothing cut, nothing lost: the input itself
        assert positive is None
    else:
        assert_closed_half(positive)
        assert negative.volume + positive.volume == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize(
    "plane",
    [
        Plane.from_point_normal((0.05, -0.1, 0.02), (1.0, 0.3, 0.2)),
        Plane.x(0.0),  # through a ring of vertices and edges of the icosphere
        Plane.from_point_normal((0.0, 0.0, 0.7), (0.1, 0.0, 1.0)),
    ],
)
def test_sphere_halves(plane: Plane) -> None:
    sphere = icosphere(4)
    negative, positive = clip(sphere, plane, keep="both")
    assert_closed_half(negative)
    assert_closed_half(positive)
    assert negative.volume + positive.volume == pytest.approx(sphere.volume, rel=1e-9)
    # The cap is the section of the polyhedron: close to the analytic circle ...
    h = float(plane.signed_distance(np.zeros(3))[0])
    circle = math.pi * (1.0 - h * h)
    assert cap_area(negative) == pytest.approx(circle, rel=2e-2)
    # ... and the same triangles on both sides.
    assert cap_area(negative) == pytest.approx(cap_area(positive), rel=1e-12)


def test_sphere_at_utm_scale_conserves_volume() -> None:
    sphere = icosphere(3, radius=250.0, centre=UTM)
    plane = Plane.from_point_normal(UTM + np.array([17.0, -3.0, 40.0]), (0.3, -0.2, 1.0))
    negative, positive = clip(sphere, plane, keep="both")
    assert_closed_half(negative)
    assert_closed_half(positive)
    assert negative.volume + positive.volume == pytest.approx(sphere.volume, rel=1e-9)


def test_two_spheres_cut_through_both() -> None:
    first = icosphere(2)
    second = icosphere(2, centre=np.array([3.0, 0.0, 0.0]))
    both = Surface(
        vertices=np.concatenate([first.vertices, second.vertices]),
        faces=np.concatenate([first.faces, second.faces + first.n_vertices]),
    )
    negative, positive = clip(both, Plane.y(0.1), keep="both")
    assert_closed_half(negative)
    assert_closed_half(positive)
    assert negative.volume + positive.volume == pytest.approx(both.volume, rel=1e-9)


def test_hollow_sphere_cap_has_a_hole() -> None:
    outer = icosphere(3, radius=2.0)
    inner = icosphere(3, radius=1.0)
    shell = Surface(
        vertices=np.concatenate([outer.vertices, inner.vertices]),
        faces=np.concatenate([outer.faces, inner.faces[:, ::-1] + outer.n_vertices]),
    )
    negative, positive = clip(shell, Plane.z(0.1), keep="both")
    assert_closed_half(negative)
    assert_closed_half(positive)
    assert negative.volume + positive.volume == pytest.approx(shell.volume, rel=1e-9)
    annulus = math.pi * (4 - 0.01) - math.pi * (1 - 0.01)
    assert cap_area(negative) == pytest.approx(annulus, rel=2e-2)


def test_open_surface_shares_new_vertices_and_interpolates() -> None:
    x, y = np.meshgrid(np.linspace(0.0, 4.0, 9), np.linspace(0.0, 3.0, 7), indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), 0.1 * x.ravel() * y.ravel()], axis=1) + UTM
    index = np.arange(x.size).reshape(x.shape)
    a, b, c = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel()
    d = index[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    labels = (faces.shape[0] // 2 > np.arange(faces.shape[0])).astype(np.int64)
    linear = 2.0 * (vertices[:, 0] - UTM[0]) - 3.0 * (vertices[:, 1] - UTM[1])
    surface = Surface(
        vertices=vertices,
        faces=faces,
        patch_labels=labels,
        patch_names=("south", "north"),
        point_data={"f": Property(values=linear, unit="m"), "code": np.arange(x.size)},
        cell_data={"id": np.arange(faces.shape[0])},
        name="horizon",
        kind="horizon",
        metadata={"source": "test"},
    )
    plane = Plane.from_point_normal(UTM + np.array([1.3, 0.0, 0.0]), (1.0, 0.4, 0.0))
    negative, positive = clip(surface, plane, keep="both")
    for half in (negative, positive):
        assert half.name == "horizon"
        assert half.kind == "horizon"
        assert half.metadata == {"source": "test"}
        assert half.patch_names == ("south", "north")
        assert half.point_data["f"].unit == "m"
        rebuilt = 2.0 * (half.vertices[:, 0] - UTM[0]) - 3.0 * (half.vertices[:, 1] - UTM[1])
        assert np.allclose(half.point_data["f"].values, rebuilt, atol=1e-6)
        assert np.unique(half.vertices, axis=0).shape[0] == half.n_vertices  # no duplicates
        assert half.is_consistently_oriented
        # Cell data and labels follow each face: the source face's centroid side agrees.
        source = half.cell_data["id"].values
        assert np.array_equal(half.patch_labels, labels[source])
    assert negative.area + positive.area == pytest.approx(surface.area, rel=1e-12)
    # No cracks: the cut line vertices are the same in both halves.
    cut_neg = negative.vertices[np.abs(plane.signed_distance(negative.vertices)) < 1e-7]
    cut_pos = positive.vertices[np.abs(plane.signed_distance(positive.vertices)) < 1e-7]
    assert np.array_equal(np.unique(cut_neg, axis=0), np.unique(cut_pos, axis=0))
    assert cut_neg.shape[0] > 0


def test_open_surface_lying_in_the_plane_belongs_to_both_sides() -> None:
    plate = Surface(
        vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], faces=[[0, 1, 2], [0, 2, 3]]
    )
    negative, positive = clip(plate, Plane.z(0.0), keep="both")
    assert negative is not None
    assert positive is not None
    assert negative.area == positive.area == 1.0


def test_quads_are_cut_as_their_triangles() -> None:
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    index = np.arange(x.size).reshape(x.shape)
    quads = np.stack(
        [
            index[:-1, :-1].ravel(),
            index[1:, :-1].ravel(),
            index[1:, 1:].ravel(),
            index[:-1, 1:].ravel(),
        ],
        1,
    )
    surface = Surface(
        vertices=vertices, faces=quads, cell_data={"q": np.arange(quads.shape[0]) * 1.5}
    )
    negative, positive = clip(surface, Plane.x(1.25), keep="both")
    assert negative.faces.shape[1] == 3
    assert negative.area == pytest.approx(1.25 * 2)
    assert positive.area == pytest.approx(1.75 * 2)
    assert set(np.unique(negative.cell_data["q"].values)) <= set(np.arange(6) * 1.5)
    untouched = clip(surface, Plane.x(10.0))
    assert untouched is surface  # nothing cut: quads kept as they are


def test_cap_cell_data_is_no_data() -> None:
    cube = make_cube().replace(cell_data={"rock": np.arange(12.0), "n": np.arange(12)})
    half = clip(cube, Plane.x(0.5))
    cap = half.patch_labels == half.patch_names.index("cap")
    assert np.isnan(half.cell_data["rock"].values[cap]).all()
    ints = half.cell_data["n"]
    assert ints.no_data_value is not None
    assert (ints.values[cap] == ints.no_data_value).all()


def test_caps_options() -> None:
    cube = make_cube()
    open_half = clip(cube, Plane.x(0.5), options={"surface": {"caps": "never"}})
    assert not open_half.is_closed
    assert "cap" not in open_half.patch_names
    plate = Surface(vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0]], faces=[[0, 1, 2]])
    with pytest.raises(DegenerateGeometryError, match="closed loops"):
        clip(plate, Plane.x(0.5), options={"surface": {"caps": "always"}})


def test_nothing_left_is_none() -> None:
    cube = make_cube()
    assert clip(cube, Plane.x(-1.0)) is None
    assert clip(cube, Plane.x(2.0), keep="positive") is None
    assert clip(cube, Plane.x(2.0), keep="both") == (cube, None)


def test_a_broken_clipper_is_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    from geobrep.ops.clipping import _registry

    spec = _registry().get("surface")
    monkeypatch.setattr(spec, "__dict__", {**spec.__dict__, "function": lambda *args: 42})
    with pytest.raises(PluginError, match="turned"):
        clip(make_cube(), Plane.x(0.5))
