"""What a VTK XML file (VTU, VTP) declares, checked before meshio or VTK allocates or inflates it.

:func:`check_xml_counts`: the counts of every ``<Piece>`` and ``<DataArray>``
(``NumberOfPoints``, ``NumberOfTuples`` x ``NumberOfComponents``, ...) are non-negative integers
within the read budget (:mod:`geobrep.adapters.limits`); VTK allocates what they say (a VTP
declaring 400 000 000 points kills the process).

:func:`check_vtu_sizes`: a file compressed with zlib or lzma stores each binary ``DataArray``
as a header ``[#blocks, block size, last block size, compressed size of each block]`` and the
compressed blocks; meshio and VTK inflate every block whole, so 5 MB of zlib can become
gigabytes. It reads each header, refuses a file whose arrays declare more than the
read budget (:mod:`geobrep.adapters.limits`) in all, and inflates each block in bounded steps
(keeping nothing) to make sure it holds no more than its header declares: what meshio then
inflates is bounded by the budget. Inline (``format="binary"``) and appended (base64 or raw)
data are checked the way meshio reads them.
"""

from __future__ import annotations

import base64
import binascii
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final, Literal
from xml.etree import ElementTree

import numpy as np

from geobrep.adapters.limits import check_declared, inflate_bounded
from geobrep.errors import FormatError

__all__ = ["check_vtu_sizes", "check_xml_counts", "split_base64_blocks"]

_COMPRESSORS: Final[dict[str, Literal["zlib", "lzma"]]] = {
    "vtkZLibDataCompressor": "zlib",
    "vtkLZMADataCompressor": "lzma",
}
_HEADER_TYPES: Final[dict[str, np.dtype[np.unsignedinteger]]] = {
    "UInt32": np.dtype(np.uint32),
    "UInt64": np.dtype(np.uint64),
}


def _base64_chars(count: int) -> int:
    return -(-count // 3) * 4


def split_base64_blocks(text: str, header: np.dtype[Any]) -> tuple[bytes, bytes]:
    """A compressed array's base64 text decoded as meshio decodes it: the block table
    (``[#blocks, block size, last block size, compressed size of each block]``, encoded on its
    own) and the compressed blocks. The table is shorter than one ``header`` item when the
    text holds none; bad base64 raises :class:`binascii.Error` (a ValueError)."""
    item = header.itemsize
    first = base64.b64decode(text[: _base64_chars(item)])[:item]
    if len(first) < item:
        return first, b""
    chars = _base64_chars((3 + int(np.frombuffer(first, header)[0])) * item)
    return base64.b64decode(text[:chars]), base64.b64decode(text[chars:])


@dataclass
class _Budget:
    """The file being checked and the bytes its arrays have declared so far."""

    path: Path
    size: int
    method: Literal["zlib", "lzma"]
    header: np.dtype[np.unsignedinteger]
    declared: int = 0

    def blocks(self, header: bytes, data: bytes | memoryview, name: str) -> int:
        """Check one array's blocks (``header`` holds at least its block table); the bytes of
        ``data`` they use."""
        item = self.header.itemsize
        what = f"DataArray {name!r}"
        if len(header) < 3 * item:
            raise FormatError(f"{what}: its compressed-data header is cut short", self.path)
        count = int(np.frombuffer(header[:item], self.header)[0])
        if len(header) < (3 + count) * item:
            raise FormatError(
                f"{what} declares {count} compressed blocks, more than its header holds",
                self.path,
            )
        table = np.frombuffer(header[: (3 + count) * item], self.header).astype(object)
        block, last = int(table[1]), int(table[2])
        total = count * block if last == 0 or count == 0 else (count - 1) * block + last
        self.declared += total
        check_declared(self.declared, self.size, what, self.path)
        start = 0
        for index, compressed in enumerate(table[3:]):
            piece = bytes(data[start : start + int(compressed)])
            start += int(compressed)
            limit = block if index < count - 1 or last == 0 else last
            inflate_bounded(piece, limit, f"{what} block {index}", self.path, self.method)
        return start

    def base64_array(self, text: str, name: str) -> None:
        """An array as meshio reads it from base64 text: header first, then the blocks."""
        try:
            header, data = split_base64_blocks(text, self.header)
        except (binascii.Error, ValueError) as exc:
            raise FormatError(
                f"DataArray {name!r} is not valid base64 ({exc})", self.path
            ) from None
        if len(header) < self.header.itemsize:
            raise FormatError(f"DataArray {name!r} holds no compressed data", self.path)
        self.blocks(header, data, name)


def _attributes(path: Path) -> dict[str, str] | None:
    """The attributes of the ``<VTKFile>`` element, from the start of the file."""
    with path.open("rb") as stream:
        head = stream.read(1 << 16).decode("latin-1")
    match = re.search(r"<VTKFile\b([^>]*)>", head)
    if match is None:
        return None
    return dict(re.findall(r'([\w:]+)\s*=\s*"([^"]*)"', match.group(1)))


def check_vtu_sizes(path: Path) -> None:
    """Raise :class:`FormatError` when the compressed arrays of the VTU at ``path`` declare
    more than the read budget, or inflate to more than they declare."""
    attributes = _attributes(path)
    if attributes is None or attributes.get("compressor") not in _COMPRESSORS:
        return  # uncompressed data is never larger than the file
    header = _HEADER_TYPES.get(attributes.get("header_type", "UInt32"))
    if header is None:
        return  # meshio refuses it
    order: Literal["<", ">"] = (
        "<" if attributes.get("byte_order", "LittleEndian") == "LittleEndian" else ">"
    )
    budget = _Budget(
        path,
        path.stat().st_size,
        _COMPRESSORS[attributes["compressor"]],
        header.newbyteorder(order),
    )
    try:
        _check_xml(budget)
    except ElementTree.ParseError:
        _check_raw_appended(budget)  # raw appended bytes are not XML: meshio splits them off


def _check_xml(budget: _Budget) -> None:
    appended: list[tuple[int, str]] = []
    for _, element in ElementTree.iterparse(budget.path, events=("end",)):
        if element.tag == "DataArray":
            name = element.get("Name", "?")
            if element.get("format") == "binary":
                budget.base64_array((element.text or "").strip(), name)
            elif element.get("format") == "appended":
                try:
                    appended.append((int(element.get("offset", "0")), name))
                except ValueError:
                    message = f"DataArray {name!r} has no valid offset"
                    raise FormatError(message, budget.path) from None
            element.clear()
        elif element.tag == "AppendedData" and element.get("encoding") == "base64":
            text = (element.text or "").strip().removeprefix("_")
            for offset, name in appended:
                budget.base64_array(text[offset:], name)
            element.clear()


def _check_raw_appended(budget: _Budget) -> None:
    """Raw appended data, walked array by array from offset 0 as meshio walks it."""
    raw = budget.path.read_bytes()
    found = re.search(rb'<AppendedData[^>]+(?:">)', raw)
    stop = raw.find(b"</AppendedData>")
    if found is None or stop < 0 or b"_" not in raw[found.end() : stop]:
        return  # meshio refuses it
    data = memoryview(raw[found.end() : stop].split(b"_", 1)[1].rsplit(b"\n", 1)[0])
    del raw
    item = budget.header.itemsize
    position = 0
    while position + item <= len(data):
        count = int(np.frombuffer(data[position : position + item], budget.header)[0])
        header_end = position + (3 + count) * item
        name = f"at appended offset {position}"
        used = budget.blocks(bytes(data[position:header_end]), data[header_end:], name)
        position = header_end + used


_TAG = re.compile(rb"<(Piece|DataArray)\b([^>]*)>")
_ATTRIBUTE = re.compile(rb'([\w:]+)\s*=\s*"([^"]*)"')
#: Bytes at least per declared item: a point (3 doubles), a cell (one offset), a value.
_ITEM_BYTES: Final = {"NumberOfPoints": 24}


def _counts(attributes: dict[bytes, bytes], path: Path) -> dict[str, int]:
    counts: dict[str, int] = {}
    for key, text in attributes.items():
        name = key.decode("latin-1")
        if not name.startswith("NumberOf"):
            continue
        try:
            value = int(text)
        except ValueError:
            shown = text.decode("latin-1")[:40]
            raise FormatError(f"{name}={shown!r} is not a count", path) from None
        if value < 0:
            raise FormatError(f"{name}={value} is negative", path)
        counts[name] = value
    return counts


def check_xml_counts(path: Path) -> None:
    """Raise :class:`FormatError` when a ``<Piece>`` or ``<DataArray>`` declares a count that
    is not a non-negative integer, or more data than the read budget allows."""
    with path.open("rb") as stream:
        data = stream.read()
    size = len(data)
    for tag in _TAG.finditer(data):
        attributes = dict(_ATTRIBUTE.findall(tag.group(2)))
        counts = _counts(attributes, path)
        if tag.group(1) == b"Piece":
            declared = sum(value * _ITEM_BYTES.get(name, 8) for name, value in counts.items())
            check_declared(declared, size, "a <Piece>", path)
        else:
            name = attributes.get(b"Name", b"?").decode("latin-1")
            tuples = counts.get("NumberOfTuples", 0)
            declared = tuples * max(counts.get("NumberOfComponents", 1), 1) * 8
            check_declared(declared, size, f"DataArray {name!r}", path)
