"""Entity types: construction, derived values known by hand, and rejection of bad input.

Every malformed field must raise ``EntityValidationError`` (also a ``ValueError``) whose message
names the entity (``"Surface 'top'"``) and the field, so a user can find the fault.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from shapes import CUBE_FACES, CUBE_NORMALS, CUBE_VERTICES, UTM_ORIGIN

from geobrep import (
    Annotation,
    Block,
    EntityValidationError,
    LinearOctree,
    NurbsSurface,
    PatchSide,
    PointSet,
    Polygon,
    PolyLine,
    Property,
    Surface,
    TetMesh,
)

TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
SQUARE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]


def invalid(
    build: Callable[[], Any], label: str, field: str, *fragments: str
) -> EntityValidationError:
    """Assert ``build()`` raises EntityValidationError naming ``label`` and ``field``."""
    with pytest.raises(EntityValidationError) as info:
        build()
    error = info.value
    assert isinstance(error, ValueError)
    message = str(error)
    assert message.startswith(f"{label}: {field}: "), message
    assert error.entity == label
    assert error.field == field
    for fragment in fragments:
        assert fragment in message, message
    return error


def net_2x2() -> np.ndarray:
    """Control net of the bilinear unit square patch."""
    net = np.zeros((2, 2, 3))
    net[1, :, 0] = 1.0
    net[:, 1, 1] = 1.0
    return net


def bilinear(**fields: Any) -> NurbsSurface:
    values: dict[str, Any] = {
        "degree_u": 1,
        "degree_v": 1,
        "knots_u": [0, 0, 1, 1],
        "knots_v": [0, 0, 1, 1],
        "control_points": net_2x2(),
        "name": "n",
    }
    values.update(fields)
    return NurbsSurface(**values)


# ----------------------------------------------------------------------------- naming
class TestErrorNaming:
    def test_named_entity(self) -> None:
        invalid(
            lambda: Surface(vertices=TRIANGLE, faces=[[0, 1, 3]], name="top"),
            "Surface 'top'",
            "faces",
            "vertex 3",
        )

    def test_entity_known_by_id(self) -> None:
        invalid(lambda: Surface(vertices=TRIANGLE, faces=[[0, 1, 3]], id=4), "Surface #4", "faces")

    def test_anonymous_entity(self) -> None:
        invalid(lambda: Surface(vertices=TRIANGLE, faces=[[0, 1, 3]]), "Surface", "faces")

    def test_label_property(self) -> None:
        assert PointSet(vertices=TRIANGLE, name="wells").label == "PointSet 'wells'"
        assert PointSet(vertices=TRIANGLE, id=2).label == "PointSet #2"

    def test_missing_field(self) -> None:
        invalid(lambda: Surface(vertices=TRIANGLE, name="top"), "Surface 'top'", "faces")

    def test_extra_field(self) -> None:
        invalid(
            lambda: Surface(vertices=TRIANGLE, faces=[[0, 1, 2]], name="top", colour="red"),
            "Surface 'top'",
            "colour",
        )

    def test_negative_id(self) -> None:
        invalid(lambda: PointSet(vertices=TRIANGLE, name="p", id=-1), "PointSet 'p'", "id")


# ----------------------------------------------------------------------------- arrays
class TestArrayFields:
    @pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
    def test_non_finite_vertices(self, bad: float) -> None:
        vertices = np.array(TRIANGLE)
        vertices[2, 1] = bad
        invalid(
            lambda: Surface(vertices=vertices, faces=[[0, 1, 2]], name="top"),
            "Surface 'top'",
            "vertices",
            "non-finite",
            "index 2",
        )

    @pytest.mark.parametrize(
        ("vertices", "fragment"),
        [
            ([[0, 0], [1, 0], [0, 1]], "expected shape (N, 3), got (3, 2)"),
            ([0.0, 0.0, 0.0], "expected shape (N, 3), got (3,)"),
            (np.zeros((2, 3, 1)), "expected shape (N, 3)"),
            (3.0, "expected shape (N, 3), got ()"),
        ],
    )
    def test_wrong_vertex_shape(self, vertices: Any, fragment: str) -> None:
        invalid(lambda: PointSet(vertices=vertices, name="p"), "PointSet 'p'", "vertices", fragment)

    def test_ragged_list(self) -> None:
        invalid(
            lambda: PointSet(vertices=[[0, 0, 0], [1, 0]], name="p"),
            "PointSet 'p'",
            "vertices",
            "cannot be read as an array",
        )

    @pytest.mark.parametrize(
        "vertices",
        [
            np.ones((3, 3), dtype=bool),
            np.array([["a", "b", "c"]] * 3),
            np.array(TRIANGLE, dtype=object),
            None,
            np.array(TRIANGLE, dtype=complex),
        ],
        ids=["bool", "str", "object", "None", "complex"],
    )
    def test_non_real_vertices(self, vertices: Any) -> None:
        invalid(lambda: PointSet(vertices=vertices, name="p"), "PointSet 'p'", "vertices")

    def test_float32_becomes_float64(self) -> None:
        source = np.array(TRIANGLE, dtype=np.float32)
        points = PointSet(vertices=source)
        assert points.vertices.dtype == np.float64
        np.testing.assert_array_equal(points.vertices, source.astype(np.float64))

    def test_integer_vertices_become_float64(self) -> None:
        assert PointSet(vertices=[[1, 2, 3]]).vertices.dtype == np.float64

    def test_float64_is_not_copied(self) -> None:
        source = np.array(TRIANGLE)
        points = PointSet(vertices=source)
        assert np.shares_memory(points.vertices, source)
        assert source.flags.writeable  # the caller's array keeps its flags

    def test_arrays_are_read_only(self) -> None:
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]])
        with pytest.raises(ValueError, match="read-only"):
            surface.vertices[0, 0] = 5.0
        with pytest.raises(ValueError, match="read-only"):
            surface.faces[0, 0] = 1
        assert surface.vertices[0, 0] == 0.0

    def test_utm_coordinates_survive_exactly(self) -> None:
        vertices = np.array(
            [[450_000.123456789, 6_700_000.987654321, -1234.5], [451_234.5, 6_701_000.25, 12.0]]
        )
        points = PointSet(vertices=vertices)
        assert points.vertices.tobytes() == vertices.tobytes()

    def test_finite_points_whose_sum_overflows_are_kept(self) -> None:
        """The one-pass finiteness check sums the values: an overflowing sum of finite values
        is checked value by value, not refused; infinities of both signs are refused."""
        huge = np.full((4, 3), 1e308)
        assert PointSet(vertices=huge).vertices.tobytes() == huge.tobytes()
        assert PointSet(vertices=-huge).n_points == 4
        both = np.ones((3, 3))
        both[0, 0], both[2, 2] = np.inf, -np.inf  # the sum is NaN
        invalid(
            lambda: PointSet(vertices=both, name="p"), "PointSet 'p'", "vertices", "2 non-finite"
        )

    @given(
        hnp.arrays(
            np.float64,
            st.tuples(st.integers(1, 20), st.just(3)),
            elements=st.floats(allow_nan=True, allow_infinity=True),
        )
    )
    def test_non_finite_anywhere_is_refused(self, vertices: np.ndarray) -> None:
        if np.isfinite(vertices).all():
            assert PointSet(vertices=vertices).vertices.tobytes() == vertices.tobytes()
        else:
            with pytest.raises(EntityValidationError, match="non-finite"):
                PointSet(vertices=vertices)

    @given(
        hnp.arrays(
            np.float64,
            st.tuples(st.integers(0, 20), st.just(3)),
            elements=st.floats(-1e7, 1e7, allow_nan=False, allow_infinity=False),
        )
    )
    def test_any_finite_points_are_kept_bit_for_bit(self, vertices: np.ndarray) -> None:
        points = PointSet(vertices=vertices)
        assert points.vertices.shape == vertices.shape
        assert points.vertices.tobytes() == vertices.tobytes()
        assert points == PointSet(vertices=vertices.copy())


# ----------------------------------------------------------------------------- immutability
class TestImmutabilityAndEquality:
    def test_fields_cannot_be_assigned(self, unit_cube: Surface) -> None:
        with pytest.raises(ValueError, match="frozen"):
            unit_cube.name = "other"  # type: ignore[misc]
        with pytest.raises(ValueError, match="frozen"):
            unit_cube.vertices = np.zeros((8, 3))  # type: ignore[misc]
        assert unit_cube.name == "cube"

    def test_properties_cannot_be_added(self, unit_cube: Surface) -> None:
        with pytest.raises(TypeError, match="immutable"):
            unit_cube.point_data["x"] = Property(values=np.zeros(8))  # type: ignore[index]
        assert "x" not in unit_cube.point_data

    def test_replace_changes_one_field(self, unit_cube: Surface) -> None:
        renamed = unit_cube.replace(name="box")
        assert renamed.name == "box"
        assert unit_cube.name == "cube"
        assert np.shares_memory(renamed.vertices, unit_cube.vertices)

    def test_replace_revalidates(self, unit_cube: Surface) -> None:
        invalid(lambda: unit_cube.replace(faces=[[0, 1, 8]]), "Surface 'cube'", "faces", "vertex 8")
        invalid(
            lambda: unit_cube.replace(cell_data={"a": np.zeros(11)}),
            "Surface 'cube'",
            "cell_data['a']",
            "11 values for 12 faces",
        )

    def test_structural_equality(self, unit_cube: Surface) -> None:
        same = Surface(vertices=CUBE_VERTICES.copy(), faces=CUBE_FACES.copy(), name="cube")
        assert same == unit_cube
        assert same is not unit_cube
        assert unit_cube != unit_cube.replace(name="other")
        assert unit_cube != "cube"

    def test_one_ulp_is_a_difference(self) -> None:
        base = np.array([[450_000.0, 6_700_000.0, 0.0]])
        moved = base.copy()
        moved[0, 0] = np.nextafter(moved[0, 0], np.inf)
        assert PointSet(vertices=base) == PointSet(vertices=base.copy())
        assert PointSet(vertices=base) != PointSet(vertices=moved)

    def test_nan_no_data_is_equal_to_itself(self) -> None:
        values = np.array([1.0, np.nan, 3.0])

        def build() -> PointSet:
            return PointSet(
                vertices=np.zeros((3, 3)),
                point_data={"a": values.copy(), "b": Property(values=values, no_data_value=np.nan)},
            )

        assert build() == build()
        other = values.copy()
        other[1] = 2.0
        assert build() != build().replace(point_data={"a": other, "b": values})

    def test_dtype_is_part_of_equality(self) -> None:
        a = Surface(vertices=TRIANGLE, faces=np.array([[0, 1, 2]], dtype=np.int32))
        b = Surface(vertices=TRIANGLE, faces=np.array([[0, 1, 2]], dtype=np.int64))
        assert a.faces.dtype == np.int32
        assert a != b

    def test_entities_are_unhashable(self, unit_cube: Surface) -> None:
        with pytest.raises(TypeError):
            hash(unit_cube)


# ----------------------------------------------------------------------------- PointSet
class TestPointSet:
    def test_counts_and_bounds(self) -> None:
        points = PointSet(vertices=[[1, 5, -2], [3, 2, 7]], name="markers")
        assert points.n_points == 2
        assert points.bounds is not None
        assert points.bounds.as_tuple() == (1.0, 3.0, 2.0, 5.0, -2.0, 7.0)

    def test_empty(self) -> None:
        points = PointSet(vertices=np.zeros((0, 3)))
        assert points.n_points == 0
        assert points.bounds is None

    def test_point_data_length(self) -> None:
        invalid(
            lambda: PointSet(vertices=TRIANGLE, name="p", point_data={"z": [1.0, 2.0]}),
            "PointSet 'p'",
            "point_data['z']",
            "2 values for 3 points",
        )

    def test_no_cells(self) -> None:
        invalid(
            lambda: PointSet(vertices=TRIANGLE, name="p", cell_data={"z": [1.0]}),
            "PointSet 'p'",
            "cell_data",
        )


# ----------------------------------------------------------------------------- PolyLine
class TestPolyLine:
    def test_default_is_one_open_part(self) -> None:
        line = PolyLine(vertices=SQUARE)
        assert line.n_parts == 1
        assert line.closed.tolist() == [False]
        assert line.segments.tolist() == [[0, 1], [1, 2], [2, 3]]
        assert line.n_cells == 3
        assert line.length == 3.0

    def test_closed_part(self) -> None:
        line = PolyLine.from_parts(SQUARE, [[0, 1, 2, 3]], closed=True)
        assert line.segments.tolist() == [[0, 1], [1, 2], [2, 3], [3, 0]]
        assert line.length == 4.0

    def test_multi_part_with_shared_vertices(self) -> None:
        vertices = [*SQUARE, [2.0, 0.0, 0.0]]
        line = PolyLine.from_parts(
            vertices, [[0, 1, 2], [2, 3], [1, 4, 2]], closed=[False, False, True]
        )
        assert line.n_parts == 3
        assert line.part_lengths.tolist() == [3, 2, 3]
        assert line.segments.tolist() == [[0, 1], [1, 2], [2, 3], [1, 4], [4, 2], [2, 1]]
        assert line.n_cells == 6
        # lengths: 1 + 1 | 1 | 1 + sqrt(2) + 1
        assert line.length == pytest.approx(5.0 + math.sqrt(2.0))
        np.testing.assert_array_equal(line.part(1), [[1, 1, 0], [0, 1, 0]])

    def test_segments_are_read_only(self) -> None:
        line = PolyLine(vertices=SQUARE)
        with pytest.raises(ValueError, match="read-only"):
            line.segments[0, 0] = 3

    def test_from_point_lists(self) -> None:
        line = PolyLine.from_point_lists([SQUARE, [[0, 0, 1], [0, 0, 3]]], closed=[True, False])
        assert line.n_points == 6
        assert line.segments.tolist() == [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5]]
        assert line.length == 6.0

    def test_cell_data_is_per_segment(self) -> None:
        line = PolyLine.from_parts(
            SQUARE, [[0, 1, 2, 3]], closed=True, cell_data={"s": np.arange(4)}
        )
        assert len(line.cell_data["s"]) == 4
        invalid(
            lambda: PolyLine.from_parts(
                SQUARE, [[0, 1, 2, 3]], closed=True, name="f1", cell_data={"s": [1, 2, 3]}
            ),
            "PolyLine 'f1'",
            "cell_data['s']",
            "3 values for 4 segments",
        )

    def test_bad_parts(self) -> None:
        invalid(
            lambda: PolyLine.from_parts(SQUARE, [[0], [1, 2]], name="f1"),
            "PolyLine 'f1'",
            "part_offsets",
            "part 0 has 1 vertex",
        )
        invalid(
            lambda: PolyLine.from_parts(SQUARE, [[0, 1]], closed=True, name="f1"),
            "PolyLine 'f1'",
            "closed",
            "< 3 vertices",
        )
        invalid(
            lambda: PolyLine(vertices=SQUARE, indices=[0, 1, 2], part_offsets=[0, 2], name="f1"),
            "PolyLine 'f1'",
            "part_offsets",
        )
        invalid(
            lambda: PolyLine(
                vertices=SQUARE, indices=[0, 1, 2], part_offsets=[0, 3], closed=[1], name="f1"
            ),
            "PolyLine 'f1'",
            "closed",
            "booleans",
        )
        invalid(
            lambda: PolyLine(
                vertices=SQUARE,
                indices=[0, 1, 2],
                part_offsets=[0, 3],
                closed=[True, False],
                name="f1",
            ),
            "PolyLine 'f1'",
            "closed",
            "2 flags for 1 parts",
        )

    @pytest.mark.parametrize("index", [4, -1])
    def test_index_out_of_range(self, index: int) -> None:
        invalid(
            lambda: PolyLine.from_parts(SQUARE, [[0, index]], name="f1"),
            "PolyLine 'f1'",
            "indices",
            "outside 0..3",
        )

    def test_float_indices(self) -> None:
        invalid(
            lambda: PolyLine(vertices=SQUARE, indices=[0.0, 1.0], part_offsets=[0, 2], name="f1"),
            "PolyLine 'f1'",
            "indices",
            "integers",
        )

    @given(
        st.lists(
            st.tuples(st.integers(2, 6), st.booleans()),
            min_size=1,
            max_size=5,
        )
    )
    def test_segment_count_matches_parts(self, parts: list[tuple[int, bool]]) -> None:
        lists, closed, start = [], [], 0
        for length, is_closed in parts:
            lists.append(list(range(start, start + length)))
            closed.append(is_closed and length >= 3)
            start += length
        vertices = np.arange(start * 3, dtype=float).reshape(-1, 3)
        line = PolyLine.from_parts(vertices, lists, closed=closed)
        # each part's open segments, then its closing segment, parts in order
        ordered: list[tuple[int, int]] = []
        for part, is_closed in zip(lists, closed, strict=True):
            ordered += list(itertools.pairwise(part))
            if is_closed:
                ordered.append((part[-1], part[0]))
        assert [tuple(s) for s in line.segments.tolist()] == ordered
        assert line.n_cells == len(ordered)


# ----------------------------------------------------------------------------- Polygon
HOLE = [[0.5, 0.5, 0.0], [0.5, 1.5, 0.0], [1.5, 1.5, 0.0], [1.5, 0.5, 0.0]]
SQUARE2 = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]]


class TestPolygon:
    def test_square_with_hole(self) -> None:
        polygon = Polygon.from_rings(SQUARE2, holes=[HOLE], name="map")
        assert polygon.n_polygons == 1
        assert polygon.n_rings == 2
        assert polygon.ring_offsets.tolist() == [0, 4, 8]
        assert polygon.area == pytest.approx(4.0 - 1.0, abs=1e-12)
        np.testing.assert_array_equal(polygon.ring(1), HOLE)

    def test_several_polygons(self) -> None:
        shifted = np.array(SQUARE) + np.array([10.0, 0.0, 0.0])
        polygon = Polygon.from_polygons([(SQUARE2, [HOLE]), (shifted, [])])
        assert polygon.n_polygons == 2
        assert polygon.polygon_offsets.tolist() == [0, 2, 3]
        np.testing.assert_allclose(polygon.polygon_areas, [3.0, 1.0], rtol=1e-12)
        assert polygon.area == pytest.approx(4.0)

    def test_two_holes(self) -> None:
        big = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]]
        hole_a = [[1, 1, 0], [1, 2, 0], [2, 2, 0], [2, 1, 0]]
        hole_b = [[3, 3, 0], [3, 3.5, 0], [3.5, 3.5, 0], [3.5, 3, 0]]
        assert Polygon.from_rings(big, holes=[hole_a, hole_b]).area == pytest.approx(16 - 1 - 0.25)

    def test_closing_vertex_is_dropped(self) -> None:
        polygon = Polygon.from_rings([*SQUARE2, SQUARE2[0]])
        assert polygon.n_points == 4
        assert polygon.area == pytest.approx(4.0)

    def test_vertical_polygon(self) -> None:
        wall = [[0, 0, 0], [3, 0, 0], [3, 0, 2], [0, 0, 2]]
        assert Polygon.from_rings(wall).area == pytest.approx(6.0)

    def test_utm_scale_area(self) -> None:
        shifted = np.array(SQUARE2) + UTM_ORIGIN
        assert Polygon.from_rings(shifted).area == pytest.approx(4.0, rel=1e-12)

    def test_single_ring_default(self) -> None:
        polygon = Polygon(vertices=SQUARE)
        assert polygon.ring_offsets.tolist() == [0, 4]
        assert polygon.polygon_offsets.tolist() == [0, 1]
        assert polygon.area == pytest.approx(1.0)

    def test_cell_data_per_polygon(self) -> None:
        invalid(
            lambda: Polygon.from_rings(SQUARE, name="map", cell_data={"c": [1, 2]}),
            "Polygon 'map'",
            "cell_data['c']",
            "2 values for 1 polygons",
        )

    def test_bad_offsets(self) -> None:
        invalid(
            lambda: Polygon(vertices=SQUARE, ring_offsets=[0, 2, 4], name="map"),
            "Polygon 'map'",
            "ring_offsets",
            "ring 0 has 2 vertices",
        )
        invalid(
            lambda: Polygon(vertices=SQUARE, ring_offsets=[0, 3], name="map"),
            "Polygon 'map'",
            "ring_offsets",
        )
        invalid(
            lambda: Polygon(
                vertices=SQUARE, ring_offsets=[0, 4], polygon_offsets=[0, 2], name="map"
            ),
            "Polygon 'map'",
            "polygon_offsets",
        )
        invalid(
            lambda: Polygon(
                vertices=SQUARE + SQUARE,
                ring_offsets=[0, 4, 8],
                polygon_offsets=[0, 0, 2],
                name="map",
            ),
            "Polygon 'map'",
            "polygon_offsets",
            "outer ring",
        )

    def test_nan_vertex(self) -> None:
        invalid(
            lambda: Polygon.from_rings([[0, 0, np.nan], [1, 0, 0], [1, 1, 0]], name="map"),
            "Polygon 'map'",
            "vertices",
        )

    @given(
        st.floats(0.5, 1e3),
        st.floats(0.5, 1e3),
        st.floats(0.05, 0.45),
        st.floats(-1e6, 1e6),
        st.floats(-1e6, 1e6),
    )
    def test_rectangle_with_hole_area(
        self, width: float, height: float, ratio: float, x0: float, y0: float
    ) -> None:
        outer = np.array([[0, 0, 0], [width, 0, 0], [width, height, 0], [0, height, 0]])
        hole = outer * ratio + np.array([width * 0.25, height * 0.25, 0])
        shift = np.array([x0, y0, 0.0])
        polygon = Polygon.from_rings(outer + shift, holes=[(hole + shift)[::-1]])
        expected = width * height * (1 - ratio**2)
        assert polygon.area == pytest.approx(expected, rel=1e-7)


# ----------------------------------------------------------------------------- Surface
class TestSurface:
    def test_unit_cube(self, unit_cube: Surface) -> None:
        assert unit_cube.n_vertices == 8
        assert unit_cube.n_faces == 12
        assert unit_cube.area == pytest.approx(6.0)
        assert unit_cube.volume == pytest.approx(1.0)
        assert unit_cube.is_closed
        assert unit_cube.is_consistently_oriented
        np.testing.assert_allclose(unit_cube.face_normals, CUBE_NORMALS, atol=1e-15)
        np.testing.assert_allclose(unit_cube.face_areas, np.full(12, 0.5))
        assert unit_cube.bounds is not None
        assert unit_cube.bounds.as_tuple() == (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)

    def test_flipped_cube(self, unit_cube: Surface) -> None:
        flipped = unit_cube.flipped()
        assert flipped.volume == pytest.approx(-1.0)
        np.testing.assert_allclose(flipped.face_normals, -CUBE_NORMALS, atol=1e-15)

    def test_cube_at_utm_keeps_precision(self, unit_cube_at: Callable[..., Surface]) -> None:
        cube = unit_cube_at(UTM_ORIGIN)
        assert cube.volume == pytest.approx(1.0, rel=1e-12)
        assert cube.area == pytest.approx(6.0, rel=1e-9)
        assert cube.vertices.tobytes() == (CUBE_VERTICES + UTM_ORIGIN).tobytes()

    def test_tetrahedron(self, tetra: Surface) -> None:
        assert tetra.volume == pytest.approx(1.0 / 6.0)
        assert tetra.area == pytest.approx(1.5 + math.sqrt(3) / 2)
        assert tetra.is_closed
        assert tetra.is_consistently_oriented

    def test_open_and_badly_oriented(self, unit_cube: Surface) -> None:
        assert not unit_cube.replace(faces=CUBE_FACES[:-1]).is_closed
        faces = CUBE_FACES.copy()
        faces[0] = faces[0, ::-1]
        assert not unit_cube.replace(faces=faces).is_consistently_oriented

    def test_quads(self) -> None:
        plate = Surface(
            vertices=[*SQUARE, [2, 0, 0], [2, 1, 0]], faces=[[0, 1, 2, 3], [1, 4, 5, 2]], name="q"
        )
        assert plate.faces.shape == (2, 4)
        assert plate.area == pytest.approx(2.0)
        np.testing.assert_allclose(plate.face_normals, [[0, 0, 1], [0, 0, 1]])
        assert not plate.is_closed

    def test_quad_cube(self) -> None:
        quads = [
            [0, 3, 2, 1],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [3, 7, 6, 2],
            [0, 4, 7, 3],
            [1, 2, 6, 5],
        ]
        cube = Surface(vertices=CUBE_VERTICES, faces=quads)
        assert cube.volume == pytest.approx(1.0)
        assert cube.area == pytest.approx(6.0)
        assert cube.is_closed
        assert cube.is_consistently_oriented

    def test_patches(self, unit_cube: Surface) -> None:
        labels = np.repeat([0, 1, 2], 4)
        cube = unit_cube.replace(patch_labels=labels, patch_names=("zsides", "ysides", "xsides"))
        assert cube.n_patches == 3
        assert cube.patch_name(1) == "ysides"
        assert cube.patch_faces(2).tolist() == [8, 9, 10, 11]
        assert cube.patch_faces(2).dtype == np.int64

    def test_unlabelled_patches(self, unit_cube: Surface) -> None:
        assert unit_cube.n_patches == 1
        assert unit_cube.patch_faces(0).tolist() == list(range(12))
        assert unit_cube.patch_name(0) == "0"
        numbered = unit_cube.replace(patch_labels=np.repeat([0, 1], 6))
        assert numbered.n_patches == 2
        assert numbered.patch_name(1) == "1"

    @pytest.mark.parametrize("label", [3, -1])
    def test_missing_patch(self, unit_cube: Surface, label: int) -> None:
        cube = unit_cube.replace(patch_labels=np.repeat([0, 1, 2], 4))
        invalid(
            lambda: cube.patch_faces(label), "Surface 'cube'", "patch_labels", f"no patch {label}"
        )

    def test_extract_faces(self, unit_cube: Surface) -> None:
        cube = unit_cube.replace(
            patch_labels=np.repeat([0, 1, 2], 4),
            patch_names=("z", "y", "x"),
            point_data={"h": np.arange(8.0) * 10},
            cell_data={"f": np.arange(12)},
        )
        top = cube.extract_faces(np.array([2, 3]))
        assert top.n_faces == 2
        assert top.n_vertices == 4
        # only the vertices of z = 1 remain, in their original order
        np.testing.assert_array_equal(top.vertices, CUBE_VERTICES[[4, 5, 6, 7]])
        np.testing.assert_array_equal(top.vertices[top.faces], CUBE_VERTICES[CUBE_FACES[[2, 3]]])
        assert top.point_data["h"].values.tolist() == [40.0, 50.0, 60.0, 70.0]
        assert top.cell_data["f"].values.tolist() == [2, 3]
        assert top.patch_labels is not None
        assert top.patch_labels.tolist() == [0, 0]
        assert top.patch_names == ("z", "y", "x")
        assert top.name == "cube"
        assert top.area == pytest.approx(1.0)
        renamed = cube.extract_faces(np.array([0]), name="bottom")
        assert renamed.name == "bottom"

    def test_empty_surface(self) -> None:
        empty = Surface(vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), dtype=np.int64))
        assert empty.n_faces == 0
        assert empty.area == 0.0
        assert empty.bounds is None

    @pytest.mark.parametrize(
        ("faces", "fragment"),
        [
            ([[0, 1, 3]], "face 0 refers to vertex 3 but there are only 3 vertices"),
            ([[0, 1, 2], [0, 1, -1]], "face 1 has a negative vertex index"),
            ([[0, 1]], "expected 3 or 4 columns, got shape (1, 2)"),
            ([[0, 1, 2, 0, 1]], "expected 3 or 4 columns"),
            ([0, 1, 2], "expected shape"),
            ([[0.0, 1.0, 2.0]], "expected integers, got dtype float64"),
            (np.ones((1, 3), dtype=bool), "expected integers, got dtype bool"),
            ([["0", "1", "2"]], "expected integers"),
            ([[0, 1, 2], [0, 1]], "cannot be read as an array"),
            (np.array([[0, 1, 2**63 + 5]], dtype=np.uint64), "does not fit"),
        ],
    )
    def test_bad_faces(self, faces: Any, fragment: str) -> None:
        invalid(
            lambda: Surface(vertices=TRIANGLE, faces=faces, name="top"),
            "Surface 'top'",
            "faces",
            fragment,
        )

    @pytest.mark.parametrize("dtype", [np.int8, np.uint16, np.uint32, np.uint64, np.int32])
    def test_integer_face_dtypes(self, dtype: type) -> None:
        surface = Surface(vertices=TRIANGLE, faces=np.array([[0, 1, 2]], dtype=dtype))
        assert surface.faces.dtype in (np.int32, np.int64)
        assert surface.faces.tolist() == [[0, 1, 2]]

    def test_bad_patch_labels(self) -> None:
        def build(**fields: Any) -> Surface:
            return Surface(vertices=TRIANGLE, faces=[[0, 1, 2]], name="top", **fields)

        invalid(lambda: build(patch_labels=[0, 1]), "Surface 'top'", "patch_labels", "2 labels")
        invalid(lambda: build(patch_labels=[-1]), "Surface 'top'", "patch_labels", "≥ 0")
        invalid(
            lambda: build(patch_labels=[1], patch_names=("a",)),
            "Surface 'top'",
            "patch_labels",
            "label 1 has no name",
        )
        invalid(lambda: build(patch_names=("a", "b")), "Surface 'top'", "patch_names")

    def test_property_lengths(self) -> None:
        invalid(
            lambda: Surface(
                vertices=TRIANGLE, faces=[[0, 1, 2]], name="top", point_data={"a": [1, 2]}
            ),
            "Surface 'top'",
            "point_data['a']",
            "2 values for 3 points",
        )
        invalid(
            lambda: Surface(
                vertices=TRIANGLE, faces=[[0, 1, 2]], name="top", cell_data={"a": [1, 2]}
            ),
            "Surface 'top'",
            "cell_data['a']",
            "2 values for 1 faces",
        )

    @given(
        st.tuples(
            st.floats(-1e6, 1e6),
            st.floats(-1e7, 1e7),
            st.floats(-5e3, 5e3),
        ),
        st.floats(0.01, 100.0),
    )
    def test_translated_scaled_cube_volume(
        self, offset: tuple[float, float, float], scale: float
    ) -> None:
        vertices = CUBE_VERTICES * scale + np.array(offset)
        # rounding to the offset's ulp leaves an exact box; its edges are exact differences
        dx, dy, dz = vertices[6] - vertices[0]
        cube = Surface(vertices=vertices, faces=CUBE_FACES)
        assert cube.volume == pytest.approx(dx * dy * dz, rel=1e-9)
        assert cube.area == pytest.approx(2 * (dx * dy + dy * dz + dz * dx), rel=1e-9)


# ----------------------------------------------------------------------------- NurbsSurface
class TestNurbsSurface:
    def test_bilinear_patch(self) -> None:
        surface = bilinear()
        assert surface.shape == (2, 2)
        assert surface.n_points == 4
        assert not surface.is_rational
        np.testing.assert_array_equal(surface.weights, np.ones((2, 2)))
        assert surface.bounds is not None
        assert surface.bounds.as_tuple() == (0.0, 1.0, 0.0, 1.0, 0.0, 0.0)

    def test_rational(self) -> None:
        assert bilinear(weights=[[1, 1], [1, 2]]).is_rational
        assert not bilinear(weights=[[3, 3], [3, 3]]).is_rational

    def test_point_data_per_control_point(self) -> None:
        assert len(bilinear(point_data={"w": [1, 2, 3, 4]}).point_data["w"]) == 4
        invalid(
            lambda: bilinear(point_data={"w": [1, 2, 3]}),
            "NurbsSurface 'n'",
            "point_data['w']",
            "3 values for 4 points",
        )

    def test_cubic_clamped(self) -> None:
        net = np.zeros((4, 5, 3))
        net[..., 0] = np.arange(4)[:, None]
        net[..., 1] = np.arange(5)[None, :]
        surface = NurbsSurface(
            degree_u=3,
            degree_v=2,
            knots_u=[0, 0, 0, 0, 1, 1, 1, 1],
            knots_v=[0, 0, 0, 0.5, 1, 1, 1, 1],
            control_points=net,
        )
        assert surface.shape == (4, 5)

    @pytest.mark.parametrize(
        ("fields", "field", "fragment"),
        [
            ({"knots_u": [0, 0, 1]}, "knots_u", "has 3 values"),
            ({"knots_v": [0, 0, 1, 1, 1]}, "knots_v", "need 4"),
            ({"knots_u": [0, 1, 0, 1]}, "knots_u", "non-decreasing"),
            ({"knots_u": [0, 0, 0, 0]}, "knots_u", "domain is empty"),
            ({"knots_u": [0, 0, np.nan, 1]}, "knots_u", "non-finite"),
            ({"degree_u": 2, "knots_u": [0, 0, 0, 1, 1]}, "control_points", "degree ≤ 1"),
            ({"degree_u": 0}, "degree_u", "greater than or equal to 1"),
            ({"weights": [[1, 1], [1, 0]]}, "weights", "positive"),
            ({"weights": [[1, 1], [1, -2]]}, "weights", "positive"),
            ({"weights": [[1, 1, 1], [1, 1, 1]]}, "weights", "does not match"),
            ({"weights": [[1, 1], [1, np.inf]]}, "weights", "non-finite"),
            ({"control_points": np.zeros((2, 2, 2))}, "control_points", "expected shape"),
            ({"cell_data": {"a": [1]}}, "cell_data", "no cells"),
        ],
    )
    def test_bad_fields(self, fields: dict[str, Any], field: str, fragment: str) -> None:
        invalid(lambda: bilinear(**fields), "NurbsSurface 'n'", field, fragment)


# ----------------------------------------------------------------------------- Annotation
class TestAnnotation:
    def test_defaults(self) -> None:
        label = Annotation(text="Fault F1", anchor=[450000.0, 6700000.0, 10.0], height=25)
        assert label.kind == "annotation"
        assert label.baseline.tolist() == [1.0, 0.0, 0.0]
        assert label.up.tolist() == [0.0, 0.0, 1.0]
        assert label.height == 25.0
        assert label.bounds is not None
        assert label.bounds.as_tuple() == (450000.0, 450000.0, 6700000.0, 6700000.0, 10.0, 10.0)

    def test_oblique_orientation(self) -> None:
        label = Annotation(text="x", anchor=[0, 0, 0], baseline=[1, 1, 0], up=[0, 0, 2])
        assert label.up.tolist() == [0.0, 0.0, 2.0]

    @pytest.mark.parametrize(
        ("fields", "field", "fragment"),
        [
            ({"baseline": [0, 0, 0]}, "baseline", "non-zero"),
            ({"up": [0, 0, 0]}, "up", "non-zero"),
            ({"up": [-3, 0, 0]}, "up", "parallel"),
            ({"height": 0}, "height", "greater than 0"),
            ({"height": math.nan}, "height", "finite"),
            ({"anchor": [1, 2]}, "anchor", "expected shape (3)"),
            ({"anchor": [1, 2, math.inf]}, "anchor", "non-finite"),
            ({"point_data": {"x": [1]}}, "point_data", "not properties"),
        ],
    )
    def test_bad_fields(self, fields: dict[str, Any], field: str, fragment: str) -> None:
        values: dict[str, Any] = {"text": "F1", "anchor": [1, 2, 3], "name": "a", **fields}
        invalid(lambda: Annotation(**values), "Annotation 'a'", field, fragment)


# ----------------------------------------------------------------------------- Block
class TestBlock:
    def test_sides(self) -> None:
        block = Block(sides=[(0, 1), (3, -1), (5, 1), (5, -1)], name="B1", unit_name="Jurassic")
        assert block.sides[1] == PatchSide(3, -1)
        assert block.sides[1].side == -1
        assert block.patch_ids == (0, 3, 5, 5)
        assert block.internal_patches == frozenset({5})
        assert block.kind == "unit"
        assert not block.is_universe
        assert block.bounds is None

    def test_universe(self) -> None:
        assert Block(kind="universe").is_universe

    @pytest.mark.parametrize(
        ("sides", "field", "fragment"),
        [
            ([(0, 1), (0, 1)], "sides", "listed twice"),
            ([(-1, 1)], "sides", "negative"),
            ([(1, 0)], "sides[0][1]", "1 or -1"),
            ([(1, 2)], "sides[0][1]", "1 or -1"),
        ],
    )
    def test_bad_sides(self, sides: list[tuple[int, int]], field: str, fragment: str) -> None:
        invalid(lambda: Block(sides=sides, name="B"), "Block 'B'", field, fragment)

    def test_no_properties(self) -> None:
        invalid(lambda: Block(name="B", point_data={"a": []}), "Block 'B'", "point_data")


# ----------------------------------------------------------------------------- LinearOctree
def octree(**fields: Any) -> LinearOctree:
    values: dict[str, Any] = {"depth": 2, "origin": [0, 0, 0], "size": 4.0, "name": "o"}
    values.update(fields)
    return LinearOctree(**values)


class TestLinearOctree:
    def test_finest_leaves(self) -> None:
        tree = octree(codes=[0, 8, 16], levels=[2, 2, 2])
        assert tree.codes.dtype == np.uint64
        assert tree.levels.dtype == np.uint8
        assert tree.n_leaves == 3
        np.testing.assert_array_equal(tree.leaf_sizes, [1.0, 1.0, 1.0])
        assert tree.volume == 3.0
        assert tree.leaf_count_per_level().tolist() == [0, 0, 3]

    def test_mixed_levels(self) -> None:
        # a level-1 octant (2 m edge, codes 0..7) then finest cells 8 and 9
        tree = octree(codes=[0, 8, 9, 56], levels=[1, 2, 2, 1])
        assert tree.volume == 8.0 + 1.0 + 1.0 + 8.0
        assert tree.leaf_count_per_level().tolist() == [0, 2, 2]
        assert tree.memory_bytes == 4 * 8 + 4 * 1

    def test_root_leaf(self) -> None:
        assert octree(codes=[0], levels=[0], size=3.0).volume == 27.0

    def test_bounds(self) -> None:
        bounds = octree(codes=[0], levels=[2], origin=[1, 2, 3]).bounds
        assert bounds is not None
        assert bounds.as_tuple() == (1.0, 5.0, 2.0, 6.0, 3.0, 7.0)

    def test_labels_and_cell_data(self) -> None:
        tree = octree(codes=[0, 1], levels=[2, 2], labels=[3, 4], cell_data={"p": [0.5, 0.25]})
        assert tree.labels is not None
        assert tree.labels.tolist() == [3, 4]
        invalid(
            lambda: octree(codes=[0, 1], levels=[2, 2], labels=[1]),
            "LinearOctree 'o'",
            "labels",
            "1 labels for 2 leaves",
        )
        invalid(
            lambda: octree(codes=[0], levels=[2], cell_data={"p": [1, 2]}),
            "LinearOctree 'o'",
            "cell_data['p']",
            "2 values for 1 leaves",
        )

    def test_deepest_octree(self) -> None:
        last = 8**21 - 1  # the last finest cell of a depth-21 tree
        tree = LinearOctree(
            codes=np.array([0, last], dtype=np.uint64),
            levels=[21, 21],
            depth=21,
            origin=[0, 0, 0],
            size=2.0**21,
        )
        assert tree.volume == 2.0
        invalid(
            lambda: LinearOctree(
                codes=np.array([2**63], dtype=np.uint64),
                levels=[21],
                depth=21,
                origin=[0, 0, 0],
                size=1.0,
                name="o",
            ),
            "LinearOctree 'o'",
            "codes",
            "outside an octree of depth 21",
        )

    @pytest.mark.parametrize(
        ("codes", "levels", "field", "fragment"),
        [
            ([1], [1], "codes", "not aligned to its level 1"),
            ([8, 12], [2, 1], "codes", "leaf 1 code is not aligned"),
            ([0, 1], [1, 2], "codes", "leaf 0 overlaps leaf 1"),
            ([8, 0], [2, 2], "codes", "strictly ascending"),
            ([8, 8], [2, 2], "codes", "strictly ascending"),
            ([64], [2], "codes", "outside an octree of depth 2"),
            ([0], [3], "levels", "exceeds depth 2"),
            ([0, 1], [2], "levels", "one level per code"),
            ([-1], [2], "codes", "non-negative"),
            ([0.0], [2], "codes", "integers"),
            ([True], [2], "codes", "integers"),
            ([0], [22], "levels", "≤ 21"),
            ([[0]], [[0]], "codes", "1-D"),
        ],
    )
    def test_bad_leaves(self, codes: Any, levels: Any, field: str, fragment: str) -> None:
        invalid(lambda: octree(codes=codes, levels=levels), "LinearOctree 'o'", field, fragment)

    @pytest.mark.parametrize(
        ("fields", "field"),
        [({"size": 0}, "size"), ({"depth": 22}, "depth"), ({"depth": -1}, "depth")],
    )
    def test_bad_scalars(self, fields: dict[str, Any], field: str) -> None:
        invalid(lambda: octree(codes=[0], levels=[0], **fields), "LinearOctree 'o'", field)

    @given(st.sets(st.integers(0, 63), min_size=1, max_size=20), st.floats(0.5, 100.0))
    def test_finest_cells_volume(self, cells: set[int], size: float) -> None:
        codes = sorted(cells)
        tree = octree(codes=codes, levels=[2] * len(codes), size=size)
        assert tree.volume == pytest.approx(len(codes) * (size / 4) ** 3)
        assert tree.leaf_count_per_level()[2] == len(codes)


# ----------------------------------------------------------------------------- TetMesh
# The unit cube split into 6 tetrahedra around its diagonal 0-6 (each of volume 1/6).
CUBE_TETS = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]


class TestTetMesh:
    def test_single_tetrahedron(self) -> None:
        tet = TetMesh(vertices=CUBE_VERTICES[[0, 1, 3, 4]], cells=[[0, 1, 2, 3]])
        assert tet.n_cells == 1
        assert tet.n_regions == 1
        assert tet.cell_volumes.tolist() == pytest.approx([1 / 6])
        assert tet.volume == pytest.approx(1 / 6)
        assert tet.region_cells(0).tolist() == [0]

    def test_cube_of_six(self) -> None:
        mesh = TetMesh(vertices=CUBE_VERTICES + UTM_ORIGIN, cells=CUBE_TETS, name="box")
        np.testing.assert_allclose(np.abs(mesh.cell_volumes), 1 / 6, rtol=1e-9)
        assert mesh.volume == pytest.approx(1.0, rel=1e-9)

    def test_orientation_is_signed(self) -> None:
        tet = TetMesh(vertices=CUBE_VERTICES[[0, 1, 3, 4]], cells=[[1, 0, 2, 3]])
        assert tet.cell_volumes.tolist() == pytest.approx([-1 / 6])
        assert tet.volume == pytest.approx(1 / 6)

    def test_regions(self) -> None:
        mesh = TetMesh(
            vertices=CUBE_VERTICES,
            cells=CUBE_TETS,
            region_labels=[0, 0, 0, 1, 1, 1],
            region_names=("lower", "upper"),
            cell_data={"rock": np.arange(6)},
        )
        assert mesh.n_regions == 2
        assert mesh.region_cells(1).tolist() == [3, 4, 5]
        invalid(
            lambda: mesh.replace(name="m").region_cells(2),
            "TetMesh 'm'",
            "region_labels",
            "no region 2",
        )

    @pytest.mark.parametrize(
        ("fields", "field", "fragment"),
        [
            ({"cells": [[0, 1, 2, 8]]}, "cells", "tetrahedron 0 refers to vertex 8"),
            (
                {"cells": [[0, 1, 2, 3], [0, -1, 2, 3]]},
                "cells",
                "tetrahedron 1 refers to vertex -1",
            ),
            ({"cells": [[0, 1, 2]]}, "cells", "expected shape"),
            ({"cells": [[0.0, 1.0, 2.0, 3.0]]}, "cells", "integers"),
            ({"region_labels": [0, 1]}, "region_labels", "2 labels for 1 cells"),
            ({"region_labels": [-1]}, "region_labels", "≥ 0"),
            ({"region_labels": [2], "region_names": ("a", "b")}, "region_labels", "no name"),
            ({"region_names": ("a", "b")}, "region_names", "need region_labels"),
            ({"cell_data": {"a": [1, 2]}}, "cell_data['a']", "2 values for 1 tetrahedra"),
        ],
    )
    def test_bad_fields(self, fields: dict[str, Any], field: str, fragment: str) -> None:
        values: dict[str, Any] = {"vertices": CUBE_VERTICES, "cells": [[0, 1, 3, 4]], "name": "t"}
        values.update(fields)
        invalid(lambda: TetMesh(**values), "TetMesh 't'", field, fragment)


def test_structural_equality_of_plain_leaves_and_their_subclasses() -> None:
    from geobrep.model.base import structurally_equal

    class Loose(str):
        def __eq__(self, other: object) -> bool:
            return True

        __hash__ = str.__hash__

    assert structurally_equal({"a": (1, "x", None)}, {"a": [True, "x", None]})
    assert not structurally_equal({"a": (1, "x", None)}, {"a": (1, "y", None)})
    assert not structurally_equal("1", 1)
    assert structurally_equal(Loose("a"), "b")  # a subclass keeps its own equality
    assert structurally_equal(math.nan, math.nan)
    assert not structurally_equal(np.zeros(2), "x")
    assert not structurally_equal("x", np.zeros(2))


def _constructed_surface(faces: list[list[int]], **extra: Any) -> Surface:
    """A Surface made as a reader makes one whose fields are in their validated form."""
    from geobrep.model.arrays import as_readonly

    count = len(faces)
    fields: dict[str, Any] = {
        "vertices": as_readonly(np.array(SQUARE)),
        "faces": as_readonly(np.array(faces, dtype=np.int64)),
        "patch_labels": as_readonly(np.zeros(count, dtype=np.int64)),
        "patch_names": ("0",),
        "name": "made",
    }
    return Surface.model_construct(**{**fields, **extra})


@pytest.mark.parametrize(
    ("faces", "extra", "field"),
    [
        ([[0, 1, 4]], {}, "faces"),
        ([[0, 1, 2]], {"patch_labels": np.array([1], dtype=np.int64)}, "patch_labels"),
        (
            [[0, 1, 2], [0, 2, 3]],
            {"cell_data": {"rock": Property(values=np.zeros(3))}},
            "cell_data['rock']",
        ),
    ],
)
def test_check_fields_of_a_constructed_entity_raises_what_validation_raises(
    faces: list[list[int]], extra: dict[str, Any], field: str
) -> None:
    """``check_fields`` (what a reader calls on an entity it built by ``model_construct``)
    raises the error that building the same entity by validation raises."""
    from geobrep.model.properties import PropertyMap

    if "cell_data" in extra:
        extra = {"cell_data": PropertyMap(extra["cell_data"])}
    with pytest.raises(EntityValidationError) as validated:
        Surface(**{**_constructed_surface(faces, **extra).__dict__})
    error = invalid(
        lambda: _constructed_surface(faces, **extra).check_fields(), "Surface 'made'", field
    )
    assert str(error) == str(validated.value)


def test_check_fields_passes_and_marks_a_sound_constructed_entity() -> None:
    surface = _constructed_surface([[0, 1, 2], [0, 2, 3]])
    surface.check_fields()
    assert surface._checked
    assert surface == Surface(
        vertices=SQUARE,
        faces=[[0, 1, 2], [0, 2, 3]],
        name="made",
        patch_labels=[0, 0],
        patch_names=("0",),
    )
