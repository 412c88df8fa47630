"""Per-vertex and per-cell properties: Property, PropertyMap, and their use by entities."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from geobrep import EntityValidationError, PointSet, Property, Surface
from geobrep.model.properties import PropertyMap

TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


def points(**fields: Any) -> PointSet:
    return PointSet(vertices=np.zeros((4, 3)), name="p", **fields)


class TestProperty:
    def test_plain_array_is_wrapped(self) -> None:
        prop = points(point_data={"z": [1.0, 2.0, 3.0, 4.0]}).point_data["z"]
        assert isinstance(prop, Property)
        assert prop.unit is None
        assert prop.no_data_value is None
        assert prop.values.tolist() == [1.0, 2.0, 3.0, 4.0]

    def test_property_object_keeps_its_meaning(self) -> None:
        given_prop = Property(values=[0.1, -999.0, 0.3, 0.4], unit="1", no_data_value=-999.0)
        prop = points(point_data={"porosity": given_prop}).point_data["porosity"]
        assert prop == given_prop
        assert prop.unit == "1"
        assert prop.no_data_value == -999.0

    def test_mapping_form(self) -> None:
        prop = points(point_data={"t": {"values": [1, 2, 3, 4], "unit": "degC"}}).point_data["t"]
        assert prop.unit == "degC"
        assert prop.values.tolist() == [1, 2, 3, 4]

    def test_scalar_shape_and_size(self) -> None:
        prop = Property(values=np.arange(5.0))
        assert prop.element_size == 1
        assert prop.shape == (5,)
        assert prop.dtype == np.float64
        assert len(prop) == 5
        assert prop[3] == 3.0

    def test_vector_property(self) -> None:
        velocity = np.arange(12.0).reshape(4, 3)
        entity = points(point_data={"v": Property(values=velocity, unit="m/s")})
        prop = entity.point_data["v"]
        assert prop.element_size == 3
        assert len(prop) == 4
        assert prop.shape == (4, 3)
        np.testing.assert_array_equal(prop[1], [3.0, 4.0, 5.0])

    def test_vector_property_length_is_rows(self) -> None:
        with pytest.raises(EntityValidationError, match=r"point_data\['v'\]: has 3 values"):
            points(point_data={"v": np.zeros((3, 4))})

    @pytest.mark.parametrize(
        ("values", "fragment"),
        [
            (np.zeros((4, 1, 1)), "values must be (N,) or (N, k)"),
            (5.0, "values must be (N,) or (N, k), got shape ()"),
            (np.zeros((4, 0)), "element size of at least 1"),
            (["a", "b", "c", "d"], "expected numbers"),
            (np.array([1j, 2, 3, 4]), "expected numbers"),
            ([[1], [2, 3], [4], [5]], "cannot be read as an array"),
        ],
    )
    def test_bad_values(self, values: Any, fragment: str) -> None:
        with pytest.raises(EntityValidationError) as info:
            points(point_data={"a": values})
        message = str(info.value)
        assert message.startswith("PointSet 'p': point_data.a")
        assert fragment in message

    def test_property_names_must_be_strings(self) -> None:
        with pytest.raises(EntityValidationError, match="non-empty strings"):
            points(point_data={"": [1, 2, 3, 4]})

    @pytest.mark.parametrize(
        "dtype", [np.int8, np.uint8, np.int32, np.int64, np.float32, np.float64, np.bool_]
    )
    def test_dtype_is_kept(self, dtype: type) -> None:
        source = np.array([0, 1, 0, 1], dtype=dtype)
        prop = points(point_data={"a": source}).point_data["a"]
        assert prop.dtype == dtype
        assert np.shares_memory(prop.values, source)

    def test_values_are_read_only(self) -> None:
        source = np.arange(4.0)
        prop = points(point_data={"a": source}).point_data["a"]
        with pytest.raises(ValueError, match="read-only"):
            prop.values[0] = 10.0
        assert source.flags.writeable

    def test_property_is_frozen(self) -> None:
        prop = Property(values=[1.0])
        with pytest.raises(ValueError, match="frozen"):
            prop.unit = "m"  # type: ignore[misc]

    def test_asarray(self) -> None:
        prop = Property(values=np.arange(4.0))
        array = np.asarray(prop)
        assert np.shares_memory(array, prop.values)
        assert np.asarray(prop, dtype=np.float32).dtype == np.float32
        assert float(np.sum(prop)) == 6.0

    def test_repr(self) -> None:
        text = repr(Property(values=np.zeros((3, 2)), unit="m", no_data_value=-1.0))
        assert text == "Property(shape=(3, 2), dtype=float64, unit='m', no_data_value=-1.0)"


class TestMasked:
    def test_no_data_value_is_masked(self) -> None:
        prop = Property(values=[1.0, -999.0, 3.0], no_data_value=-999.0)
        masked = prop.masked()
        assert masked.mask.tolist() == [False, True, False]
        assert float(masked.mean()) == 2.0

    def test_nan_is_always_masked(self) -> None:
        masked = Property(values=[1.0, math.nan, 5.0]).masked()
        assert masked.mask.tolist() == [False, True, False]
        assert float(masked.mean()) == 3.0

    def test_nan_no_data_value(self) -> None:
        prop = Property(values=[math.nan, 2.0], no_data_value=math.nan)
        assert prop.masked().mask.tolist() == [True, False]
        assert prop == Property(values=[math.nan, 2.0], no_data_value=math.nan)
        assert prop != Property(values=[math.nan, 2.0], no_data_value=-1.0)

    def test_integer_no_data(self) -> None:
        prop = Property(values=np.array([1, -1, 3], dtype=np.int32), no_data_value=-1)
        assert prop.masked().mask.tolist() == [False, True, False]
        assert int(prop.masked().sum()) == 4

    def test_vector_masking_is_per_component(self) -> None:
        prop = Property(values=[[1.0, -9.0], [2.0, 3.0]], no_data_value=-9.0)
        assert prop.masked().mask.tolist() == [[False, True], [False, False]]

    def test_nothing_masked(self) -> None:
        assert not Property(values=[1, 2, 3]).masked().mask.any()

    @given(
        hnp.arrays(
            np.float64,
            st.integers(1, 50),
            elements=st.one_of(st.just(-999.0), st.floats(-10, 10), st.just(math.nan)),
        )
    )
    def test_mask_marks_exactly_no_data_and_nan(self, values: np.ndarray) -> None:
        masked = Property(values=values, no_data_value=-999.0).masked()
        expected = (values == -999.0) | np.isnan(values)
        np.testing.assert_array_equal(np.ma.getmaskarray(masked), expected)


class TestTake:
    def test_take_indices(self) -> None:
        prop = Property(values=[10, 20, 30], unit="m", no_data_value=-1)
        taken = prop.take(np.array([2, 0]))
        assert taken.values.tolist() == [30, 10]
        assert taken.unit == "m"
        assert taken.no_data_value == -1
        assert not taken.values.flags.writeable
        assert prop.values.tolist() == [10, 20, 30]

    def test_take_mask(self) -> None:
        prop = Property(values=np.arange(8.0).reshape(4, 2))
        taken = prop.take(np.array([True, False, False, True]))
        assert taken.values.tolist() == [[0.0, 1.0], [6.0, 7.0]]

    def test_map_take(self) -> None:
        entity = points(point_data={"a": [1, 2, 3, 4], "b": np.arange(8).reshape(4, 2)})
        taken = entity.point_data.take(np.array([3, 1]))
        assert isinstance(taken, PropertyMap)
        assert taken["a"].values.tolist() == [4, 2]
        assert taken["b"].values.tolist() == [[6, 7], [2, 3]]


class TestPropertyMap:
    def test_is_a_read_only_dict(self) -> None:
        props = points(point_data={"a": [1, 2, 3, 4]}).point_data
        assert isinstance(props, dict)
        assert list(props) == ["a"]
        for mutate in (
            lambda: props.__setitem__("b", Property(values=[1, 2, 3, 4])),
            lambda: props.__delitem__("a"),
            lambda: props.update({"b": [1, 2, 3, 4]}),
            lambda: props.pop("a"),
            lambda: props.popitem(),
            lambda: props.setdefault("b", Property(values=[1])),
            props.clear,
        ):
            with pytest.raises(TypeError, match="immutable"):
                mutate()
        with pytest.raises(TypeError, match="immutable"):
            props |= {"b": Property(values=[1])}
        assert list(props) == ["a"]

    def test_default_is_empty(self) -> None:
        entity = points()
        assert entity.point_data == {}
        assert entity.cell_data == {}
        assert isinstance(entity.point_data, PropertyMap)

    def test_check_length(self) -> None:
        props = PropertyMap({"a": [1, 2]})
        props.check_length(2, "points")
        with pytest.raises(ValueError, match="property 'a' has 2 values for 3 points"):
            props.check_length(3, "points")

    def test_cell_data_on_surface(self) -> None:
        surface = Surface(
            vertices=TRIANGLE,
            faces=[[0, 1, 2]],
            cell_data={"dip": Property(values=[12.5], unit="deg")},
        )
        assert surface.cell_data["dip"].unit == "deg"
        assert surface.cell_data["dip"].values.tolist() == [12.5]
