"""GOCAD Voxet (.vo): a regular lattice of nodes with properties in binary or ASCII side files.

The nodes are ``AXIS_O + a·AXIS_U + b·AXIS_V + c·AXIS_W`` with ``a`` running from ``AXIS_MIN``
to ``AXIS_MAX`` in ``AXIS_N`` steps (likewise ``b``, ``c``): a Voxet samples its properties at
the lattice *points*, so it reads as a :class:`~geobrep.RegularGrid` of ``AXIS_N - 1`` cells per
axis whose ``point_data`` are the properties (test.vo: 10 × 10 × 10 nodes, 9 × 9 × 9 cells).

Binary property files (``PROP_FILE``) are raw big-endian arrays (``PROP_ESIZE`` bytes per
value; ``PROP_ETYPE IEEE`` floats or ``Octet`` integers, ``PROP_SIGNED``; ``PROP_OFFSET``
bytes skipped), found beside the header and read through a numpy memory map; an
``ASCII_DATA_FILE`` is a table of ``I J K value...`` rows.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._ascii_rows import NodeRows, iter_rows
from geobrep.adapters.gocad._keyed import MAX_TEXT, KeyedFile, KeyedLine, parse_keyed, read_text
from geobrep.adapters.limits import check_declared, human_bytes, parse_numbers
from geobrep.errors import EntityValidationError, FormatError
from geobrep.model.entities import RegularGrid
from geobrep.model.properties import Property

__all__ = [
    "PropertyFile",
    "VoxetAxes",
    "ascii_numbers",
    "mapped_array",
    "property_dtype",
    "property_lines",
    "property_meta",
    "read_voxet",
    "side_file",
    "voxet_grid",
]

_AXIS_KEYS = ("AXIS_O", "AXIS_U", "AXIS_V", "AXIS_W", "AXIS_MIN", "AXIS_MAX")


@dataclass
class PropertyFile:
    """What the header says of one property: name, side file and its binary layout."""

    number: int
    name: str
    file: str | None = None
    esize: int = 4
    etype: str = "IEEE"
    signed: bool = True
    offset: int = 0
    no_data: float | None = None
    unit: str | None = None
    kind: str | None = None
    line: int = 0
    extra: dict[str, str] = field(default_factory=dict)


@dataclass
class VoxetAxes:
    """The lattice keywords of a Voxet or SGrid header."""

    values: dict[str, list[float]] = field(default_factory=dict)
    counts: tuple[int, int, int] | None = None


def property_dtype(prop: PropertyFile, where: KeyedLine | None, path: Path) -> np.dtype[Any]:
    """The big-endian numpy dtype of a property file's values."""
    etype = prop.etype.upper()
    if etype == "IEEE" and prop.esize in (4, 8):
        return np.dtype(f">f{prop.esize}")
    if etype in ("OCTET", "IEEE") and prop.esize in (1, 2, 4, 8):
        return np.dtype(f">{'i' if prop.signed else 'u'}{prop.esize}")
    message = f"property {prop.name!r}: PROP_ETYPE {prop.etype} with PROP_ESIZE {prop.esize}"
    raise FormatError(f"{message} is not a supported value type", path, prop.line or None)


def property_lines(keyed: KeyedFile) -> dict[int, PropertyFile]:
    props: dict[int, PropertyFile] = {}
    for line in keyed.lines:
        keyword = line.keyword
        if keyword == "PROPERTY":
            number = line.int_at(0, 1, 10_000)
            props[number] = PropertyFile(number, line.rest(1), line=line.number)
            continue
        if not keyword.startswith("PROP") or keyword in ("PROPERTY_CLASS_HEADER",):
            continue
        if not line.tokens or not line.tokens[0].isdigit():
            continue
        prop = props.get(int(line.tokens[0]))
        if prop is None:
            raise line.error(f"refers to property {line.tokens[0]}, not declared by PROPERTY")
        _apply(prop, line)
    return props


def _apply(prop: PropertyFile, line: KeyedLine) -> None:
    value = line.rest(1)
    keyword = line.keyword
    if keyword == "PROP_FILE":
        prop.file = value
    elif keyword == "PROP_ESIZE":
        prop.esize = line.int_at(1, 1, 8)
    elif keyword == "PROP_ETYPE":
        prop.etype = value
    elif keyword == "PROP_SIGNED":
        prop.signed = line.int_at(1, 0, 1) == 1
    elif keyword == "PROP_OFFSET":
        prop.offset = line.int_at(1, 0, 2**50)
    elif keyword == "PROP_NO_DATA_VALUE":
        prop.no_data = line.floats(1, 1)[0]
    elif keyword == "PROP_UNIT":
        prop.unit = value
    elif keyword == "PROPERTY_KIND":
        prop.kind = value
    elif keyword == "PROP_FORMAT" and value.upper() not in ("RAW", ""):
        raise line.error(f"property file format {value!r} is not supported (only RAW)")
    else:
        prop.extra[keyword] = value


def _axes(keyed: KeyedFile) -> VoxetAxes:
    axes = VoxetAxes()
    for line in keyed.lines:
        if line.keyword in _AXIS_KEYS:
            axes.values[line.keyword] = line.floats(3)
        elif line.keyword == "AXIS_N":
            n = [line.int_at(a, 1, 2**31) for a in range(3)]
            axes.counts = (n[0], n[1], n[2])
    return axes


def voxet_grid(axes: VoxetAxes, z_sign: float, path: Path, name: str) -> RegularGrid:
    """The grid whose points are the lattice nodes (no properties yet)."""
    for key in ("AXIS_O", "AXIS_U", "AXIS_V", "AXIS_W", "AXIS_N"):
        if key not in axes.values and not (key == "AXIS_N" and axes.counts):
            raise FormatError(f"the header has no {key} line", path)
    assert axes.counts is not None
    o = np.array(axes.values["AXIS_O"])
    vectors = np.array([axes.values[k] for k in ("AXIS_U", "AXIS_V", "AXIS_W")])
    lo = np.array(axes.values.get("AXIS_MIN", [0.0, 0.0, 0.0]))
    hi = np.array(axes.values.get("AXIS_MAX", [1.0, 1.0, 1.0]))
    n = np.array(axes.counts, dtype=np.float64)
    step = np.where(n > 1, (hi - lo) / np.maximum(n - 1, 1), 1.0)
    first = o + lo @ vectors
    cells = vectors * step[:, None]
    flip = np.array([1.0, 1.0, z_sign])
    try:
        return RegularGrid(
            name=name,
            origin=first * flip,
            u=cells[0] * flip,
            v=cells[1] * flip,
            w=cells[2] * flip,
            counts=tuple(max(c - 1, 1) for c in axes.counts),
        )
    except EntityValidationError as exc:
        raise FormatError(f"the voxet lattice is invalid: {exc}", path) from None


def side_file(path: Path, name: str, what: str) -> Path:
    """The file ``name`` beside the header ``path``; a FormatError when it points elsewhere
    (an absolute path or ``..``: a header may not make the reader open other files)."""
    folder = path.parent.resolve()
    side = (folder / name).resolve()
    if not name or not side.is_relative_to(folder):
        raise FormatError(
            f"{what} {name!r} is not a file beside the header (side files outside the "
            f"folder of {path.name}, absolute or through '..', are not read)",
            path,
        )
    return path.parent / name


def mapped_array(
    path: Path, name: str, what: str, dtype: np.dtype[Any], offset: int, count: int
) -> NDArray[Any]:
    """``count`` values of ``dtype`` from byte ``offset`` of the side file ``name`` beside the
    header ``path``, memory-mapped and copied in native byte order; a FormatError naming the
    file when it is missing or too short."""
    side = side_file(path, name, what)
    try:
        size = side.stat().st_size
    except OSError:
        raise FormatError(f"{what}: its file {str(side)!r} is missing", path) from None
    need = offset + count * dtype.itemsize
    if size < need:
        raise FormatError(
            f"{what}: its file {str(side)!r} has {size} bytes, "
            f"{count} values of {dtype.itemsize} bytes from byte {offset} need {need}",
            path,
        )
    if count == 0:
        return np.zeros(0, dtype=dtype.newbyteorder("="))
    mapped = np.memmap(side, dtype=dtype, mode="r", offset=offset, shape=(count,))
    return np.ascontiguousarray(mapped, dtype=dtype.newbyteorder("="))


def _binary(prop: PropertyFile, count: int, path: Path) -> NDArray[Any]:
    """The values of a raw property file beside the header (errors name both files)."""
    if prop.file is None:
        raise FormatError(f"property {prop.name!r} has no PROP_FILE", path, prop.line or None)
    dtype = property_dtype(prop, None, path)
    what = f"property {prop.name!r}: PROP_FILE"
    return mapped_array(path, prop.file, what, dtype, prop.offset, count)


def _ascii_table(
    file_name: str, path: Path, props: list[PropertyFile], counts: tuple[int, int, int]
) -> list[NDArray[np.float64]]:
    side = side_file(path, file_name, "ASCII_DATA_FILE")
    if not side.is_file():
        raise FormatError(f"the ASCII_DATA_FILE {str(side)!r} is missing", path)
    total = int(np.prod(counts))
    check_declared(8 * total * max(len(props), 1), side.stat().st_size, "AXIS_N", side)
    out = [np.full(total, np.nan if p.no_data is None else p.no_data) for p in props]
    nodes = NodeRows(counts, side)  # a node listed twice is a FormatError naming the line
    for chunk in iter_rows(side, 3 + len(props), (0, 1, 2), MAX_TEXT):
        where = nodes.place(chunk)
        for column, values in enumerate(out):
            values[where] = chunk.floats[:, column]
    return out


def _after_leading_comments(data: bytes) -> bytes:
    """``data`` from its first line that is not blank nor a ``*`` or ``#`` comment."""
    start = 0
    while start < len(data):
        end = data.find(b"\n", start)
        end = len(data) if end < 0 else end + 1
        line = data[start:end].strip()
        if line and line[:1] not in (b"*", b"#"):
            break
        start = end
    return data[start:]


def ascii_numbers(side: Path) -> NDArray[np.float64]:
    """Every number of an ASCII data file (``*`` and ``#`` comment lines skipped), parsed from
    its bytes in one C-level pass: the comment lines at its head are cut off, and only a file
    with comments further down pays for a search of every line."""
    try:
        size = side.stat().st_size
    except OSError as exc:
        raise FormatError(f"cannot open the ASCII data file: {exc.strerror}", side) from None
    if size > MAX_TEXT:
        raise FormatError(f"the ASCII data file is {human_bytes(size)}, more than allowed", side)
    body = _after_leading_comments(side.read_bytes())
    if b"*" in body or b"#" in body:
        body = re.sub(rb"(?m)^[ \t\r]*[*#].*$", b"", body)
    try:
        return parse_numbers(body)
    except ValueError as exc:
        raise FormatError(f"ASCII data file: {exc}", side) from None


def read_voxet(
    path: Path, text: str | None = None, inherited: dict[str, Any] | None = None
) -> tuple[RegularGrid, KeyedFile]:
    """The grid of a .vo file with its properties as point data; and the parsed header.

    ``text`` is the object's text when it is a member of a group file ``path`` (side files are
    found beside ``path`` all the same); ``inherited`` the group's CRS block, which a member
    without its own takes (``ZPOSITIVE``)."""
    if text is None:
        text = read_text(path, "Voxet header")
    keyed, _ = parse_keyed(path, text)
    axes = _axes(keyed)
    z_sign = -1.0 if (keyed.crs or inherited or {}).get("ZPOSITIVE") == "Depth" else 1.0
    grid = voxet_grid(axes, z_sign, path, keyed.name)
    props = property_lines(keyed)
    counts = axes.counts or (1, 1, 1)
    total = int(np.prod(counts))
    ascii_line = next((ln for ln in keyed.lines if ln.keyword == "ASCII_DATA_FILE"), None)
    values: dict[str, NDArray[Any]] = {}
    ordered = [props[k] for k in sorted(props)]
    if ascii_line is not None:
        table = _ascii_table(ascii_line.rest(), path, ordered, counts)
        values = {p.name: v for p, v in zip(ordered, table, strict=True)}
    else:
        values = {p.name: _binary(p, total, path) for p in ordered}
    data = {
        p.name: Property(
            values=values[p.name], unit=p.unit, no_data_value=p.no_data, metadata=property_meta(p)
        )
        for p in ordered
    }
    metadata: dict[str, Any] = {"gocad": {"type": "Voxet"}}
    return grid.replace(point_data=data, metadata=metadata), keyed


def property_meta(prop: PropertyFile) -> dict[str, Any]:
    gocad: dict[str, Any] = {}
    if prop.kind:
        gocad["kind"] = prop.kind
    return {"gocad": gocad} if gocad else {}
