"""Per-vertex and per-element properties: named arrays with a unit and a no-data value.

Entities take properties through the ``point_data=`` and ``cell_data=`` keywords, as plain arrays
or as :class:`Property` objects, and give them back as :class:`Property` objects that behave like
arrays (``np.asarray(prop)``, ``prop[3]``, ``len(prop)``)::

    >>> import numpy as np
    >>> from geobrep import PointSet, Property
    >>> pts = PointSet(vertices=np.zeros((2, 3)),
    ...                point_data={"porosity": Property(values=[0.1, -999.0], unit="1",
    ...                                                 no_data_value=-999.0)})
    >>> float(pts.point_data["porosity"].masked().mean())
    0.1
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import Annotated, Any, NoReturn

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, GetCoreSchemaHandler, JsonValue, PlainSerializer, model_validator
from pydantic.json_schema import WithJsonSchema
from pydantic_core import core_schema

from geobrep.model.arrays import NumericArray
from geobrep.model.base import FrozenModel

__all__ = ["Property", "PropertyMap"]


def _json_float(value: float | None) -> float | str | None:
    """JSON has no NaN or infinity: write them as the strings pydantic reads back as floats."""
    if value is None or math.isfinite(value):
        return value
    return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")


#: A float (NaN and ±inf allowed: common no-data values) that survives a JSON round trip.
NoDataValue = Annotated[
    float | None,
    PlainSerializer(_json_float, return_type=float | str | None, when_used="json"),
    WithJsonSchema(
        {
            "anyOf": [
                {"type": "number"},
                {"enum": ["NaN", "Infinity", "-Infinity"]},
                {"type": "null"},
            ]
        }
    ),
]


class Property(FrozenModel):
    """A named array's values (``(N,)`` or ``(N, k)`` for vector properties) and their meaning."""

    values: NumericArray
    unit: str | None = None
    no_data_value: NoDataValue = None
    description: str = ""
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    @model_validator(mode="before")
    @classmethod
    def _wrap_plain_array(cls, data: Any) -> Any:
        if isinstance(data, Mapping) and "values" in data:
            return data
        return {"values": data}

    @model_validator(mode="after")
    def _check_rank(self) -> Property:
        if self.values.ndim not in (1, 2):
            raise ValueError(f"values must be (N,) or (N, k), got shape {self.values.shape}")
        if self.values.ndim == 2 and self.values.shape[1] < 1:
            raise ValueError("vector property needs an element size of at least 1")
        return self

    @property
    def element_size(self) -> int:
        """Number of components per element (1 for scalars)."""
        return 1 if self.values.ndim == 1 else int(self.values.shape[1])

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.values.shape)

    @property
    def dtype(self) -> np.dtype[Any]:
        return self.values.dtype

    def __len__(self) -> int:
        return int(self.values.shape[0])

    def __getitem__(self, index: Any) -> Any:
        return self.values[index]

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> NDArray[Any]:
        if dtype is None:
            return self.values
        return np.asarray(self.values, dtype=dtype)

    def masked(self) -> np.ma.MaskedArray[Any, Any]:
        """The values with no-data entries (and NaN) masked."""
        values = self.values
        mask = np.zeros(values.shape, dtype=bool)
        if self.no_data_value is not None:
            mask |= values == self.no_data_value
        if values.dtype.kind == "f":
            mask |= np.isnan(values)
        return np.ma.MaskedArray(values, mask=mask)

    def take(self, indices: NDArray[np.integer[Any]] | NDArray[np.bool_]) -> Property:
        """A property holding a subset (or reordering) of the elements."""
        return self.model_copy(update={"values": _readonly(self.values[indices])})

    def __repr__(self) -> str:
        unit = f", unit={self.unit!r}" if self.unit else ""
        nodata = f", no_data_value={self.no_data_value}" if self.no_data_value is not None else ""
        return f"Property(shape={self.shape}, dtype={self.dtype}{unit}{nodata})"


def _readonly(array: NDArray[Any]) -> NDArray[Any]:
    array.flags.writeable = False
    return array


class PropertyMap(dict[str, Property]):
    """An immutable ``name -> Property`` mapping (a dict subclass, so it serialises as one)."""

    def __init__(self, data: Mapping[str, Any] | None = None) -> None:
        items: dict[str, Property] = {}
        for name, value in (data or {}).items():
            if not isinstance(name, str) or not name:
                raise ValueError(f"property names must be non-empty strings, got {name!r}")
            items[name] = value if isinstance(value, Property) else Property.model_validate(value)
        super().__init__(items)

    def _immutable(self, *args: Any, **kwargs: Any) -> NoReturn:
        raise TypeError("properties are immutable: build a new entity with entity.replace(...)")

    __setitem__ = _immutable
    __delitem__ = _immutable
    clear = _immutable
    pop = _immutable
    popitem = _immutable
    setdefault = _immutable
    update = _immutable
    __ior__ = _immutable

    def __iter__(self) -> Iterator[str]:
        return super().__iter__()

    def __repr__(self) -> str:
        inner = ", ".join(f"{k!r}: {v!r}" for k, v in self.items())
        return f"PropertyMap({{{inner}}})"

    def check_length(self, expected: int, what: str) -> None:
        """Raise ValueError naming the first property whose element count is not ``expected``."""
        for name, prop in self.items():
            if len(prop) != expected:
                raise ValueError(f"property {name!r} has {len(prop)} values for {expected} {what}")

    def take(self, indices: NDArray[np.integer[Any]] | NDArray[np.bool_]) -> PropertyMap:
        """Every property restricted to (or reordered by) ``indices``."""
        return PropertyMap({name: prop.take(indices) for name, prop in self.items()})

    @classmethod
    def __get_pydantic_core_schema__(
        cls, source: Any, handler: GetCoreSchemaHandler
    ) -> core_schema.CoreSchema:
        dict_schema = handler.generate_schema(dict[str, Property])

        def build(value: dict[str, Property]) -> PropertyMap:
            return value if isinstance(value, PropertyMap) else cls(value)

        return core_schema.no_info_after_validator_function(build, dict_schema)
