"""The base of geobrep's immutable pydantic models: frozen, strict about extra fields, and
compared structurally (arrays by dtype, shape and bits, so two models holding NaN no-data values
in the same places are equal)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Self

import numpy as np
from pydantic import BaseModel, ConfigDict

__all__ = ["FrozenModel", "arrays_identical", "structurally_equal"]


def arrays_identical(a: Any, b: Any) -> bool:
    """Same dtype, same shape, same bits."""
    if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
        return False
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    bits_a = np.ascontiguousarray(a).reshape(-1).view(np.uint8)
    bits_b = np.ascontiguousarray(b).reshape(-1).view(np.uint8)
    return bool(np.array_equal(bits_a, bits_b))


#: Exact types whose values compare with ``==`` alone (no subclasses: they may override it).
_PLAIN: frozenset[type] = frozenset({str, int, bool, type(None)})
_SEQUENCES = (tuple, list)


def structurally_equal(a: Any, b: Any) -> bool:
    """Deep equality that understands numpy arrays inside models, dicts and sequences."""
    if type(a) in _PLAIN and type(b) in _PLAIN:  # the common leaves, before the costlier tests
        return bool(a == b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return arrays_identical(a, b)
    if isinstance(a, BaseModel) or isinstance(b, BaseModel):
        return type(a) is type(b) and all(
            structurally_equal(getattr(a, n), getattr(b, n)) for n in type(a).model_fields
        )
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(structurally_equal(a[k], b[k]) for k in a)
    if isinstance(a, _SEQUENCES) and isinstance(b, _SEQUENCES):
        return len(a) == len(b) and all(structurally_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True  # a NaN no-data value equals itself, as NaN array entries do
    return bool(a == b)


class FrozenModel(BaseModel):
    """Immutable model with structural equality (unhashable: it may hold arrays)."""

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return structurally_equal(self, other)

    __hash__ = None  # type: ignore[assignment]

    def model_copy(self, *, update: Mapping[str, Any] | None = None, deep: bool = False) -> Self:
        """A copy; with ``update`` the changed model is validated again (never a stale cache).

        Prefer ``replace(**changes)`` where a model offers it.
        """
        if not update:
            return super().model_copy(deep=deep)
        values = {name: getattr(self, name) for name in type(self).model_fields}
        values.update(update)
        return type(self)(**values)

    def __repr_args__(self) -> Any:
        for name, value in super().__repr_args__():
            if isinstance(value, np.ndarray) or (isinstance(value, tuple) and len(value) > 6):
                yield name, _ArraySummary(value)
            elif name in ("point_data", "cell_data", "metadata") and not value:
                continue
            else:
                yield name, value


class _ArraySummary:
    """Stands for a bulky value in a repr."""

    def __init__(self, value: Any) -> None:
        if isinstance(value, np.ndarray):
            self.text = f"<array {value.dtype} {value.shape}>"
        else:
            self.text = f"<{len(value)} {type(value[0]).__name__} items>"

    def __repr__(self) -> str:
        return self.text
