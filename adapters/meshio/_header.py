"""Put geobrep's JSON header into VTK files meshio writes without field data.

meshio's VTU and legacy VTK writers drop ``field_data``; VTK itself (and ParaView) read it.
:func:`embed_vtu_header` adds a ``<FieldData>`` element at the end of a ``.vtu`` (in place, only
the tail is rewritten); :func:`embed_legacy_header` adds a ``FIELD FieldData`` section after the
``DATASET`` line of a legacy ``.vtk`` (as VTK's own writer does), and
:func:`read_legacy_header` finds it again.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from geobrep.adapters.cell_layout import HEADER_ARRAY, decode_header, encode_header
from geobrep.errors import FormatError

__all__ = [
    "embed_legacy_header",
    "embed_vtu_header",
    "read_legacy_header",
    "vtk_field_problem",
]

_TAIL = 4096
_LEGACY_HEAD = 1 << 24
#: The types geobrep stored its legacy header as: ``float`` now, ``vtktypeuint8`` before.
_HEADER_TYPES: dict[str, np.dtype[Any]] = {"float": np.dtype(">f4"), "vtktypeuint8": np.dtype("u1")}


def embed_vtu_header(path: Path, header: dict[str, Any]) -> None:
    """Append the header as UInt8 ``FieldData`` of the ``UnstructuredGrid`` element."""
    data = encode_header(header)
    values = " ".join(map(str, data.tolist()))
    element = (
        f'<FieldData>\n<DataArray type="UInt8" Name="{HEADER_ARRAY}" '
        f'NumberOfTuples="{data.size}" format="ascii">\n{values}\n</DataArray>\n</FieldData>\n'
    ).encode()
    with path.open("r+b") as stream:
        size = stream.seek(0, 2)
        start = max(0, size - _TAIL)
        stream.seek(start)
        tail = stream.read()
        where = tail.rfind(b"</UnstructuredGrid>")
        if where < 0:
            raise FormatError("meshio wrote no </UnstructuredGrid> element", path)
        stream.seek(start + where)
        stream.write(element + tail[where:])


def embed_legacy_header(path: Path, header: dict[str, Any], binary: bool) -> None:
    """Insert a ``FIELD FieldData`` section holding the header after the ``DATASET`` line.

    Its bytes are stored as ``float`` (32-bit, big-endian when binary; each byte exactly): the
    one array type VTK's legacy reader and meshio's both read the same way. (geobrep before
    issue 15 wrote ``vtktypeuint8``, which VTK does not know; ``unsigned_char`` meshio 5.3.5
    does not; ``int`` is 4 bytes to VTK and 8 to meshio.)
    """
    data = encode_header(header)
    body = data.astype(">f4").tobytes() if binary else " ".join(map(str, data.tolist())).encode()
    section = f"FIELD FieldData 1\n{HEADER_ARRAY} 1 {data.size} float\n".encode() + body + b"\n"
    staged = path.with_name(path.name + ".body")
    path.rename(staged)
    try:
        with staged.open("rb") as source, path.open("wb") as target:
            head = source.read(1024)
            line_end = head.find(b"\n", head.find(b"DATASET"))
            if head.find(b"DATASET") < 0 or line_end < 0:
                raise FormatError("meshio wrote no DATASET line", path)
            target.write(head[: line_end + 1] + section + head[line_end + 1 :])
            shutil.copyfileobj(source, target, 1 << 22)
    finally:
        staged.unlink(missing_ok=True)


def read_legacy_header(path: Path) -> dict[str, Any] | None:
    """The header of a legacy ``.vtk`` written by geobrep, or None."""
    with path.open("rb") as stream:
        head = stream.read(_LEGACY_HEAD)
    marker = f"\n{HEADER_ARRAY} 1 ".encode()
    where = head.find(marker)
    points = head.find(b"\nPOINTS")
    if where < 0 or (0 <= points < where):
        return None
    line_end = head.find(b"\n", where + 1)
    fields = head[where + 1 : line_end].split()
    try:
        count = int(fields[2])
    except (IndexError, ValueError):
        return None
    binary = b"\nBINARY" in head[:256]
    start = line_end + 1
    stored = _HEADER_TYPES.get(fields[3].decode("latin-1").lower() if len(fields) > 3 else "")
    if stored is None:
        return None
    if binary:
        raw = np.frombuffer(head[start : start + count * stored.itemsize], dtype=stored)
    else:
        stop = head.find(b"\n", start)
        try:
            raw = np.array(head[start:stop].split(), dtype=np.float64)
        except (ValueError, OverflowError):  # not numbers: not a header geobrep wrote
            return None
    if raw.size != count:
        return None
    return decode_header(raw)


#: The array types VTK's legacy reader knows (lower case, as it compares them).
VTK_LEGACY_TYPES = frozenset(
    {
        "bit", "char", "signed_char", "unsigned_char", "short", "unsigned_short", "int",
        "unsigned_int", "long", "unsigned_long", "float", "double", "vtkidtype", "vtktypeint64",
        "vtktypeuint64", "string", "utf8_string", "variant",
    }
)  # fmt: skip
_FIELD_ARRAY = re.compile(rb"(?m)^[ \t]*\S+[ \t]+\d+[ \t]+\d+[ \t]+([A-Za-z_]\w*)[ \t]*\r?$")
_FIELD_LINE = re.compile(rb"(?m)^[ \t]*FIELD\b[^\n]*\n?")
_FIELD_HEAD = re.compile(rb"[ \t]*FIELD[ \t]+\S+[ \t]+\d+[ \t]*\r?\n")
_DECLARATION = re.compile(rb"[ \t]*\S+[ \t]+\d+[ \t]+\d+[ \t]+([A-Za-z_]\w*)[ \t]*\r?\n")
_NOT_TYPES = frozenset({"nan", "inf", "infinity"})


def vtk_field_problem(path: Path) -> str | None:
    """What, in the legacy VTK file at ``path``, VTK's reader would crash on; None if nothing.

    VTK's legacy reader crashes the process (a segmentation fault) on FIELD data it cannot
    parse: an unknown array type (such as the ``vtktypeuint8`` meshio's 5.1 writer uses), a
    FIELD line without its array count, or a first array declaration that is not
    ``name components tuples type``. Such a file must not reach it. Lines elsewhere that look
    like an array declaration are checked too (a binary block that happens to look like one is
    refused: rare, and safe).
    """
    with path.open("rb") as stream:
        data = stream.read()
    for match in _FIELD_LINE.finditer(data):
        head = _FIELD_HEAD.match(data, match.start())
        if head is None:
            return f"a FIELD line is not 'FIELD name count': {match.group(0)[:60]!r}"
        declaration = _DECLARATION.match(data, head.end())
        if declaration is None:
            shown = data[head.end() : head.end() + 60]
            return f"a FIELD array declaration is not 'name components tuples type': {shown!r}"
    for match in _FIELD_ARRAY.finditer(data):
        kind = match.group(1).decode("latin-1")
        if kind.lower() not in VTK_LEGACY_TYPES and kind.lower() not in _NOT_TYPES:
            return f"a FIELD array has type {kind!r}, which VTK's legacy reader does not know"
    return None
