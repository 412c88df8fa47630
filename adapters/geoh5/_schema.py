"""The pieces of the geoh5 schema the workspace and drillhole modules share: object type uuids,
entity flags, x/y/z records, object types and data groups (with their data types)."""

from __future__ import annotations

import uuid
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ENTITY_FLAGS",
    "FLOAT_NDV",
    "INTEGER_NDV",
    "OBJECT_TYPES",
    "XYZ",
    "add_data",
    "data_values",
    "object_type",
    "text",
    "uid",
    "value_map",
    "vertex_rows",
    "whole",
    "xyz",
]

#: geoh5 object type uuids (fixed by the schema) and names.
OBJECT_TYPES = {
    "Points": "{202C5DB1-A56D-4004-9CAD-BAAFD8899406}",
    "Curve": "{6A057FDC-B355-11E3-95BE-FD84A7FFCB88}",
    "Surface": "{F26FEBA3-ADED-494B-B9E9-B2BBCBE298E1}",
    "Block model": "{B020A277-90E2-4CD7-84D6-612EE3F25051}",
    "Drillhole": "{7CAEBF0E-D16E-11E3-BC69-E4632694AA37}",
}
ENTITY_FLAGS = {"Allow delete": 1, "Allow move": 1, "Allow rename": 1, "Public": 1, "Visible": 1}
XYZ = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
#: geoh5's no-data values of float and integer data (values not sampled at a vertex or cell).
FLOAT_NDV = 1.17549435e-38
INTEGER_NDV = -2147483648
_MAP = np.dtype([("Key", "<u4"), ("Value", h5py.string_dtype())])


def uid() -> str:
    return "{" + str(uuid.uuid4()) + "}"


def text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def vertex_rows(points: NDArray[np.float64]) -> NDArray[Any]:
    """``(N, 3)`` float64 points as geoh5's x, y, z records (a view when they are C-ordered)."""
    return np.ascontiguousarray(points, dtype="<f8").view(XYZ).reshape(-1)


def xyz(rows: NDArray[Any]) -> NDArray[np.float64]:
    """x, y, z records (or an ``(N, 3)`` array) as ``(N, 3)`` float64 points."""
    if rows.dtype == XYZ:  # geobrep's and geoh5py's records: the floats as they lie
        return rows.view("<f8").reshape(-1, 3).astype(np.float64, copy=False)
    if rows.dtype.names:
        return np.column_stack([rows[k] for k in ("x", "y", "z")]).astype(np.float64)
    return np.asarray(rows, dtype=np.float64).reshape(-1, 3)


def whole(dataset: Any) -> NDArray[Any]:
    """All of a dataset as a new array, read straight into it (``read_direct``: h5py's
    ``dataset[()]`` fills a zeroed array through more steps); strings and scalars as h5py
    gives them."""
    if not isinstance(dataset, h5py.Dataset):
        raise TypeError(f"{dataset!r} is not a dataset")
    shape, dtype = dataset.shape, dataset.dtype
    if not shape or dtype.hasobject or dtype.kind not in "biufV":
        return np.asarray(dataset[()])
    array = np.empty(shape, dtype=dtype)
    if array.size:
        dataset.read_direct(array)
    return array


def object_type(root: h5py.Group, name: str) -> h5py.Group:
    """The group of object type ``name`` (created on first use)."""
    ident = OBJECT_TYPES[name]
    types = root["Types/Object types"]
    if ident not in types:
        types.create_group(ident).attrs.update({"ID": ident, "Name": name, "Description": name})
    return types[ident]


def add_data(
    root: h5py.Group,
    obj: h5py.Group,
    name: str,
    association: str,
    values: NDArray[Any],
    *,
    description: str = "",
    names: list[str] | None = None,
) -> None:
    """Data ``name`` of ``obj`` (``Float`` for float64 values, ``Integer`` for int32, and
    ``Referenced`` int32 keys when ``names`` is given: key ``k`` names ``names[k - 1]``, key 0
    is ``Unknown``), with a data type of its own."""
    primitive = (
        "Referenced" if names is not None else "Float" if values.dtype.kind == "f" else "Integer"
    )
    ident, type_ident = uid(), uid()
    data = root["Data"].create_group(ident)
    data.attrs.update({"ID": ident, "Name": name, "Association": association, **ENTITY_FLAGS})
    data.create_dataset("Data", data=values)
    kind = root["Types/Data types"].create_group(type_ident)
    kind.attrs.update(
        {
            "ID": type_ident,
            "Name": name,
            "Description": description or name,
            "Primitive type": primitive,
        }
    )
    if names is not None:
        pairs = [(0, "Unknown"), *((k + 1, v) for k, v in enumerate(names))]
        kind.create_dataset("Value map", data=np.array(pairs, dtype=_MAP))
    data["Type"] = kind
    obj["Data"][ident] = data


def data_values(data: h5py.Group) -> tuple[str, str, NDArray[Any]] | None:
    """Name, primitive type and values of a data group (None without a ``Data`` dataset)."""
    if "Data" not in data:
        return None
    kind = data.get("Type")
    primitive = "" if kind is None else text(kind.attrs.get("Primitive type", ""))
    return text(data.attrs.get("Name", "")), primitive, whole(data["Data"])


def value_map(data: h5py.Group) -> dict[int, str]:
    """The names of a ``Referenced`` data's keys (key 0 ``Unknown`` left out)."""
    kind = data.get("Type")
    if kind is None or "Value map" not in kind:
        return {}
    rows = kind["Value map"][()]
    return {int(k): text(v) for k, v in zip(rows["Key"], rows["Value"], strict=True) if int(k)}
