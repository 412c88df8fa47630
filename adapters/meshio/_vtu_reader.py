"""geobrep's own VTU reader: what meshio 5.3.5 reads from a one-piece file, without meshio.

Importing meshio costs a command about 50 ms (its 40 format modules, rich for its command
line, numpy.ma), more than reading a small file. :func:`read_vtu_mesh` reads the files geobrep
and meshio write (ASCII, or binary base64 inline or appended, uncompressed or zlib/lzma
compressed, UInt32/UInt64 headers, either byte order) into the arrays meshio's reader returns
(the same values, dtypes, byte orders and cell blocks, steps done as meshio does them), for
:func:`~geobrep.adapters.meshio._bridge.layout_from_mesh` to take as it takes a
``meshio.Mesh``. It returns None for anything else (several pieces, raw appended data,
polyhedra, cell types geobrep has no entity for, a file meshio would refuse or warn about):
such a file is meshio's to read, and to say what is wrong with.
"""

from __future__ import annotations

import base64
import lzma
import warnings
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, Final, Literal
from xml.etree import ElementTree

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters._vtk_xml import split_base64_blocks

__all__ = ["VtuMesh", "read_vtu_mesh"]

_TYPES: Final[dict[str, np.dtype[Any]]] = {
    "Float32": np.dtype(np.float32),
    "Float64": np.dtype(np.float64),
    "Int8": np.dtype(np.int8),
    "Int16": np.dtype(np.int16),
    "Int32": np.dtype(np.int32),
    "Int64": np.dtype(np.int64),
    "UInt8": np.dtype(np.uint8),
    "UInt16": np.dtype(np.uint16),
    "UInt32": np.dtype(np.uint32),
    "UInt64": np.dtype(np.uint64),
}
_DECOMPRESS: Final[dict[str, Callable[[bytes], bytes]]] = {
    "vtkZLibDataCompressor": zlib.decompress,
    "vtkLZMADataCompressor": lzma.decompress,
}
#: VTK cell type -> meshio's name and nodes per cell, for the cells geobrep has entities for
#: (their VTK and meshio node orders agree).
_CELLS: Final = {
    1: ("vertex", 1),
    3: ("line", 2),
    5: ("triangle", 3),
    9: ("quad", 4),
    10: ("tetra", 4),
}
_HEADERS: Final[dict[str, np.dtype[Any]]] = {
    name: _TYPES[name] for name in ("Int32", "Int64", "UInt32", "UInt64")
}
_PIECE_PARTS: Final = ("Points", "Cells", "PointData", "CellData")


class _NotMineError(Exception):
    """The file is not one this reader reads as meshio does: meshio reads it."""


# Plain classes: a dataclass costs ~0.5 ms to create at import (Python 3.11 compiles each of
# its methods), a tenth of what reading a small file takes.
class CellBlock:
    """One run of cells of a type, as ``meshio.CellBlock`` holds it."""

    __slots__ = ("data", "type")

    def __init__(self, type: str, data: NDArray[Any]) -> None:
        self.type, self.data = type, data


class VtuMesh:
    """What ``meshio.read`` returns for a VTU, as far as geobrep reads it."""

    __slots__ = ("cell_data", "cells", "field_data", "point_data", "points")

    def __init__(
        self,
        points: NDArray[Any],
        cells: list[CellBlock],
        point_data: dict[str, NDArray[Any]],
        cell_data: dict[str, list[NDArray[Any]]],
        field_data: dict[str, NDArray[Any]],
    ) -> None:
        self.points, self.cells = points, cells
        self.point_data, self.cell_data, self.field_data = point_data, cell_data, field_data


def read_vtu_mesh(path: Path) -> VtuMesh | None:
    """The mesh meshio reads from the VTU at ``path``, or None when meshio must read it."""
    try:
        root = ElementTree.parse(path).getroot()
        return _Reader(root).mesh()
    except Exception:  # raw appended bytes, or anything meshio reads (or refuses) its own way
        return None


class _Reader:
    """meshio's ``VtuReader`` for a one-piece file."""

    def __init__(self, root: ElementTree.Element) -> None:
        attrib = root.attrib
        if root.tag != "VTKFile" or attrib.get("type") != "UnstructuredGrid":
            raise _NotMineError
        if attrib.get("version", "0.1") not in ("0.1", "1.0"):
            raise _NotMineError
        compressor = attrib.get("compressor")
        if compressor is not None and compressor not in _DECOMPRESS:
            raise _NotMineError
        self.decompress = _DECOMPRESS[compressor] if compressor is not None else None
        order = attrib.get("byte_order")
        if order not in (None, "LittleEndian", "BigEndian"):
            raise _NotMineError
        self.order: Literal["<", ">"] | None = None
        if order is not None:
            self.order = "<" if order == "LittleEndian" else ">"
        # meshio reads the header of binary arrays in this type (an integer one, here)
        header = _HEADERS.get(attrib.get("header_type", "UInt32"))
        self.header = (
            header if header is None or self.order is None else header.newbyteorder(self.order)
        )
        self.root = root
        self.appended: str | None = None

    def mesh(self) -> VtuMesh:
        grid = None
        for child in self.root:
            if child.tag == "UnstructuredGrid" and grid is None:
                grid = child
            elif child.tag == "AppendedData" and self.appended is None:
                if child.attrib["encoding"] != "base64":
                    raise _NotMineError
                text = (child.text or "").strip()
                if not text.startswith("_"):
                    raise _NotMineError
                self.appended = text[1:]
            else:
                raise _NotMineError
        if grid is None:
            raise _NotMineError
        pieces = [child for child in grid if child.tag == "Piece"]
        fields: dict[str, NDArray[Any]] = {}
        for child in grid:
            if child.tag == "FieldData":
                for array in child:
                    fields[array.attrib["Name"]] = self.array(array)
            elif child.tag != "Piece":
                raise _NotMineError
        if len(pieces) != 1:
            raise _NotMineError  # meshio keeps the cells of the last piece only
        return self.piece(pieces[0], fields)

    def piece(self, piece: ElementTree.Element, fields: dict[str, NDArray[Any]]) -> VtuMesh:
        parts: dict[str, ElementTree.Element] = {}
        for child in piece:
            if child.tag not in _PIECE_PARTS or child.tag in parts:
                raise _NotMineError
            if any(array.tag != "DataArray" for array in child):
                raise _NotMineError
            parts[child.tag] = child
        if "Points" not in parts or "Cells" not in parts or len(parts["Points"]) != 1:
            raise _NotMineError
        n_points, n_cells = int(piece.attrib["NumberOfPoints"]), int(piece.attrib["NumberOfCells"])
        array = parts["Points"][0]
        points = self.array(array).reshape(n_points, int(array.attrib["NumberOfComponents"]))
        cells = {array.attrib["Name"]: self.array(array) for array in parts["Cells"]}
        if len(cells["offsets"]) != n_cells or len(cells["types"]) != n_cells:
            raise _NotMineError
        point_data = {a.attrib["Name"]: self.array(a) for a in parts.get("PointData", ())}
        raw = {a.attrib["Name"]: self.array(a) for a in parts.get("CellData", ())}
        blocks, cell_data = _blocks(cells, raw)
        for values in point_data.values():
            if len(values) != len(points):
                raise _NotMineError
        for per_block in cell_data.values():
            if len(per_block) != len(blocks):
                raise _NotMineError
            if any(len(v) != len(b.data) for v, b in zip(per_block, blocks, strict=True)):
                raise _NotMineError
        # meshio merges the pieces' points and point data (a copy, in native byte order)
        merged = {name: np.concatenate([values]) for name, values in point_data.items()}
        return VtuMesh(np.concatenate([points]), blocks, merged, cell_data, fields)

    def array(self, element: ElementTree.Element) -> NDArray[Any]:
        """meshio's ``read_data``: one ``<DataArray>``, shaped by its components."""
        attrib = element.attrib
        dtype = _TYPES[attrib["type"]]
        kind = attrib.get("format", "ascii")
        text = element.text
        if kind == "ascii" and text is not None:
            data = np.empty((0,), dtype=dtype) if not text.strip() else _ascii(text, dtype)
        elif kind == "binary" and text is not None:
            data = self.binary(text.strip(), dtype)
        elif kind == "appended" and self.appended is not None:
            data = self.binary(self.appended[int(attrib["offset"]) :], dtype)
        else:
            raise _NotMineError
        components = attrib.get("NumberOfComponents", "")
        if components != "":  # meshio drops an empty one (Firedrake writes them)
            count = int(components)
            if count <= 0 or data.size % count:
                raise _NotMineError  # meshio warns and skips (or refuses) such an array
            data = data.reshape(-1, count)
        return data

    def binary(self, text: str, dtype: np.dtype[Any]) -> NDArray[Any]:
        if self.header is None:
            raise _NotMineError
        if self.order is not None:
            dtype = dtype.newbyteorder(self.order)
        if self.decompress is None:
            return self.uncompressed(text, dtype)
        return self.compressed(text, dtype)

    def uncompressed(self, text: str, dtype: np.dtype[Any]) -> NDArray[Any]:
        assert self.header is not None
        data = base64.b64decode(text)
        item = self.header.itemsize
        total = np.frombuffer(data[:item], self.header)[0]
        if len(data) == item:  # the length was encoded on its own (padded)
            data = base64.b64decode(text[len(base64.b64encode(data)) :])
        else:
            data = data[item:]
        return np.frombuffer(data[:total], dtype=dtype)

    def compressed(self, text: str, dtype: np.dtype[Any]) -> NDArray[Any]:
        assert self.decompress is not None
        assert self.header is not None
        table, data = split_base64_blocks(text, self.header)
        values = np.frombuffer(table, self.header)
        count = int(values[0])
        sizes = values[3:]
        if len(sizes) != count:
            raise _NotMineError("a block table shorter than it says")
        offsets = np.empty(sizes.shape[0] + 1, dtype=sizes.dtype)
        offsets[0] = 0
        np.cumsum(sizes, out=offsets[1:])
        blocks = [
            np.frombuffer(self.decompress(data[offsets[k] : offsets[k + 1]]), dtype=dtype)
            for k in range(count)
        ]
        return np.concatenate(blocks)


def _ascii(text: str, dtype: np.dtype[Any]) -> NDArray[Any]:
    """``numpy.fromstring(text, dtype, sep=" ")`` as meshio calls it, refusing what it would
    cut short (numpy stops at the first word that is not a number, with a warning)."""
    words = text.split()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpy's warning of a text it could not read to its end
        data = np.fromstring(text, dtype=dtype, sep=" ")
    if len(data) != len(words):
        raise _NotMineError
    return np.asarray(data)


def _blocks(
    cells: dict[str, NDArray[Any]], raw: dict[str, NDArray[Any]]
) -> tuple[list[CellBlock], dict[str, list[NDArray[Any]]]]:
    """meshio's ``vtk_cells_from_data``: a block per run of cells of one type."""
    connectivity, offsets = cells["connectivity"].ravel(), cells["offsets"].ravel()
    types = cells["types"].ravel()
    if len(offsets) != len(types):
        raise _NotMineError
    breaks = np.where(types[:-1] != types[1:])[0] + 1
    starts = np.concatenate([[0], breaks])
    ends = np.concatenate([breaks, [len(types)]])
    blocks: list[CellBlock] = []
    cell_data: dict[str, list[NDArray[Any]]] = {}
    for start, end in zip(starts, ends, strict=True):
        known = _CELLS.get(int(types[start]))
        if known is None:
            raise _NotMineError  # meshio drops cells it does not know, or has a type geobrep lacks
        name, nodes = known
        order = np.arange(nodes, dtype=offsets.dtype) - nodes
        indices = np.add.outer(offsets[start:end], order)
        blocks.append(CellBlock(name, np.asarray(connectivity[indices] + np.int64(0))))
        for key, values in raw.items():
            cell_data.setdefault(key, []).append(np.asarray(values[start:end]))
    return blocks, cell_data
