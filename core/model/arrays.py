"""NumPy array fields for pydantic models: vectorised checks, read-only views, binary-friendly JSON.

An array field is declared with :func:`array_field`, which returns an ``Annotated`` type::

    Points = array_field("float64", (None, 3), finite=True)

Validation checks dtype, shape and (optionally) finiteness with whole-array numpy operations,
never element by element, and returns a read-only *view* (no copy when the input already has the
right dtype). In JSON an array is an object ``{"dtype", "shape", "file"}`` when a serialisation
context supplies an ``array_writer`` (the native format stores the data in ``.npy`` sidecars), or
``{"dtype", "shape", "data"}`` with nested lists otherwise.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeAlias

import numpy as np
from numpy.typing import NDArray
from pydantic import PlainSerializer, PlainValidator, SerializationInfo, ValidationInfo
from pydantic.json_schema import WithJsonSchema

__all__ = [
    "ARRAY_READER",
    "ARRAY_WRITER",
    "BoolArray",
    "ControlNet",
    "FaceArray",
    "FloatArray",
    "IndexArray",
    "NumericArray",
    "Points",
    "TetArray",
    "Vector3",
    "WeightGrid",
    "array_field",
    "array_reader",
    "as_readonly",
]

#: Key of the validation context entry that loads a sidecar array: ``reader(file) -> ndarray``.
ARRAY_READER = "array_reader"
#: Key of the serialisation context entry that stores an array: ``writer(array) -> file``.
ARRAY_WRITER = "array_writer"

DTypeRule = Literal["float64", "integer", "bool", "numeric"]

# Models with a custom ``__init__`` are validated through it when nested, which drops pydantic's
# validation context; the array reader therefore also travels in a context variable.
_ACTIVE_READER: ContextVar[Callable[[str], NDArray[Any]] | None] = ContextVar(
    "geobrep_array_reader", default=None
)


@contextmanager
def array_reader(reader: Callable[[str], NDArray[Any]]) -> Iterator[None]:
    """Make ``reader(file) -> ndarray`` resolve ``{"file": ...}`` array records while active."""
    token = _ACTIVE_READER.set(reader)
    try:
        yield
    finally:
        _ACTIVE_READER.reset(token)


_ARRAY_JSON_SCHEMA: dict[str, Any] = {
    "type": "object",
    "description": "A numpy array: its dtype (numpy string, e.g. '<f8'), its shape, and either "
    "the name of a .npy member of the container ('file') or nested lists ('data').",
    "properties": {
        "dtype": {"type": "string"},
        "shape": {"type": "array", "items": {"type": "integer", "minimum": 0}},
        "file": {"type": "string"},
        "data": {"type": "array"},
    },
    "required": ["dtype", "shape"],
    "additionalProperties": False,
}


def as_readonly(array: NDArray[Any]) -> NDArray[Any]:
    """Return a read-only view of ``array`` (the caller's array keeps its own flags)."""
    view = array.view()
    view.flags.writeable = False
    return view


def _shape_text(shape: tuple[int | None, ...]) -> str:
    names = iter("NMKLPQ")
    return "(" + ", ".join(next(names) if s is None else str(s) for s in shape) + ")"


def _from_json(value: dict[str, Any], info: ValidationInfo) -> NDArray[Any]:
    try:
        dtype = np.dtype(value["dtype"])
        shape = tuple(int(s) for s in value["shape"])
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"malformed array record: {exc}") from None
    if dtype.kind not in "biuf" or dtype.subdtype is not None:
        raise ValueError(f"array record dtype {value['dtype']!r} is not a number type")
    if "file" in value:
        reader = (info.context or {}).get(ARRAY_READER) or _ACTIVE_READER.get()
        if reader is None:
            raise ValueError(f"array stored in file {value['file']!r} but no array reader given")
        array = np.asarray(reader(value["file"]))
    elif "data" in value:
        array = np.asarray(value["data"], dtype=dtype)
    else:
        raise ValueError("array record has neither 'file' nor 'data'")
    if array.dtype != dtype or array.shape != shape:
        if array.size == 0 and int(np.prod(shape)) == 0:
            array = array.astype(dtype).reshape(shape)
        else:
            raise ValueError(
                f"array data has dtype {array.dtype} and shape {array.shape}, "
                f"record says {dtype} and {shape}"
            )
    return array


def _coerce_dtype(array: NDArray[Any], rule: DTypeRule) -> NDArray[Any]:
    kind = array.dtype.kind
    if rule == "float64":
        if array.dtype == np.float64:
            return array
        if kind in "fiu":  # booleans are not coordinates: reject them like strings
            return array.astype(np.float64)
        raise ValueError(f"expected real numbers, got dtype {array.dtype}")
    if rule == "integer":
        if kind in "iu":
            if array.dtype in (np.int32, np.int64):
                return array
            if array.dtype == np.uint64 and array.size and array.max() > np.iinfo(np.int64).max:
                raise ValueError(f"value {int(array.max())} does not fit a signed 64-bit index")
            return array.astype(np.int64)
        if kind == "f" and array.size == 0:
            return array.astype(np.int64)
        raise ValueError(f"expected integers, got dtype {array.dtype}")
    if rule == "bool":
        if kind == "b":
            return array
        raise ValueError(f"expected booleans, got dtype {array.dtype}")
    if kind in "fiub":
        return array
    raise ValueError(f"expected numbers, got dtype {array.dtype}")


def _check_shape(array: NDArray[Any], shape: tuple[int | None, ...] | None) -> NDArray[Any]:
    if shape is None:
        return array
    if array.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(array.shape, shape, strict=False)
    ):
        # An empty list of points arrives as shape (0,): give it the expected trailing shape.
        if array.size == 0 and all(s is not None for s in shape[1:]):
            return array.reshape((0, *(s for s in shape[1:] if s is not None)))
        raise ValueError(f"expected shape {_shape_text(shape)}, got {array.shape}")
    return array


def _all_finite(array: NDArray[Any]) -> bool:
    """Every value finite, in one pass and no temporary array: a sum is finite when every term
    is (NaN and infinities carry through a sum); only a sum that is not (those, or finite
    terms overflowing) is looked at value by value."""
    with np.errstate(over="ignore", invalid="ignore"):
        total = np.add.reduce(array, axis=None)
    return bool(np.isfinite(total)) or bool(np.isfinite(array).all())


def _first_nonfinite(array: NDArray[Any]) -> str:
    bad = ~np.isfinite(array)
    count = int(bad.sum())
    where = np.argwhere(bad)[0]
    index = int(where[0]) if where.size else 0
    return f"contains {count} non-finite value(s) (NaN or inf), first at index {index}"


def _make_validator(
    rule: DTypeRule,
    shape: tuple[int | None, ...] | None,
    finite: bool,
    columns: tuple[int, ...] | None,
) -> Callable[[Any, ValidationInfo], NDArray[Any]]:
    def validate(value: Any, info: ValidationInfo) -> NDArray[Any]:
        if isinstance(value, dict):
            array = _from_json(value, info)
        elif isinstance(value, np.ndarray):
            array = value
        else:
            try:
                array = np.asarray(value)
            except (ValueError, TypeError) as exc:
                raise ValueError(f"cannot be read as an array: {exc}") from None
        if array.dtype == object:
            raise ValueError("ragged or non-numeric values cannot form an array")
        array = _coerce_dtype(array, rule)
        if columns is not None and array.size == 0 and array.ndim == 1:
            array = array.reshape((0, columns[0]))
        array = _check_shape(array, shape)
        if columns is not None and array.ndim == 2 and array.shape[1] not in columns:
            allowed = " or ".join(str(t) for t in columns)
            raise ValueError(f"expected {allowed} columns, got shape {array.shape}")
        if finite and array.dtype.kind == "f" and not _all_finite(array):
            raise ValueError(_first_nonfinite(array))
        return as_readonly(array)

    return validate


def _serialize(array: NDArray[Any], info: SerializationInfo) -> dict[str, Any]:
    record: dict[str, Any] = {"dtype": array.dtype.str, "shape": list(array.shape)}
    writer = (info.context or {}).get(ARRAY_WRITER)
    if writer is not None:
        record["file"] = writer(array)
    else:
        record["data"] = array.tolist()
    return record


def array_field(
    rule: DTypeRule,
    shape: tuple[int | None, ...] | None = None,
    *,
    finite: bool = False,
    columns: tuple[int, ...] | None = None,
) -> Any:
    """Build an ``Annotated[np.ndarray, ...]`` pydantic field type.

    ``rule`` picks the dtype policy (``"float64"`` converts real input to float64; ``"integer"``
    keeps int32/int64 and widens other integers), ``shape`` uses ``None`` for free dimensions,
    ``columns`` allows several column counts for 2-D arrays (faces: ``(3, 4)``).

    >>> import numpy as np
    >>> from pydantic import BaseModel
    >>> class M(BaseModel):
    ...     points: array_field("float64", (None, 3), finite=True)
    >>> M(points=[[0, 0, 1]]).points.dtype
    dtype('float64')
    """
    return Annotated[
        np.ndarray,
        PlainValidator(_make_validator(rule, shape, finite, columns)),
        PlainSerializer(_serialize, when_used="json"),
        WithJsonSchema(_ARRAY_JSON_SCHEMA),
    ]


if TYPE_CHECKING:  # what type checkers see: plain numpy arrays
    Points: TypeAlias = NDArray[np.float64]
    Vector3: TypeAlias = NDArray[np.float64]
    FloatArray: TypeAlias = NDArray[np.float64]
    IndexArray: TypeAlias = NDArray[np.integer[Any]]
    BoolArray: TypeAlias = NDArray[np.bool_]
    NumericArray: TypeAlias = NDArray[Any]
    FaceArray: TypeAlias = NDArray[np.integer[Any]]
    TetArray: TypeAlias = NDArray[np.integer[Any]]
    ControlNet: TypeAlias = NDArray[np.float64]
    WeightGrid: TypeAlias = NDArray[np.float64]
else:
    Points = array_field("float64", (None, 3), finite=True)
    Vector3 = array_field("float64", (3,), finite=True)
    FloatArray = array_field("float64", (None,), finite=True)
    IndexArray = array_field("integer", (None,))
    BoolArray = array_field("bool", (None,))
    NumericArray = array_field("numeric")
    FaceArray = array_field("integer", (None, None), columns=(3, 4))
    TetArray = array_field("integer", (None, 4))
    ControlNet = array_field("float64", (None, None, 3), finite=True)
    WeightGrid = array_field("float64", (None, None), finite=True)
