"""Write one GOCAD object: header, CRS block, property headers and the element body.

Writers use 1-based contiguous vertex ids, LF line ends and the shortest exact text of every
float, so read → write → read is bit-identical. Vertices are written in index order (spread
over the TFACE/ILINE/TVOLUME parts so that every vertex is declared before a cell uses it); a
vertex with exactly the same coordinates as an earlier one is written as ``ATOM`` (or
``PATOM``) of it.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._headers import color_from_text, quote, quote_rest
from geobrep.adapters.gocad._numbers import format_float, row_pieces
from geobrep.adapters.gocad._parser import GocadWarning
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity
from geobrep.model.properties import Property

__all__ = ["ObjectText", "VertexWriter", "crs_block", "part_vertex_ranges"]

FLAG_PROPERTY = "gocad_vertex_flag"
CTETRA_PROPERTY = "gocad_ctetra_faces"
_FLAG_TEXT = {1: b" CNXYZ", 2: b" XYZ"}
_COLOR_KEY = {"TSurf": "*solid*color", "PLine": "*line*color", "VSet": "*atoms*color"}


def report(message: str) -> None:
    """Tell the user what GOCAD cannot hold (a :class:`GocadWarning`)."""
    warnings.warn(message, GocadWarning, stacklevel=3)


def gocad_section(metadata: Mapping[str, Any]) -> dict[str, Any]:
    """The ``"gocad"`` entry of a metadata dict (empty when absent or malformed)."""
    value = metadata.get("gocad")
    return value if isinstance(value, dict) else {}


def gocad_metadata(entity: Entity | None) -> dict[str, Any]:
    """What the reader kept about an entity's GOCAD object."""
    return {} if entity is None else gocad_section(entity.metadata)


def crs_block(crs: CRS | dict[str, Any] | None) -> list[str]:
    """The ``GOCAD_ORIGINAL_COORDINATE_SYSTEM`` lines of a CRS (none for ``None``)."""
    if crs is None:
        return []
    if isinstance(crs, dict):  # a raw block kept from the source
        lines = ["GOCAD_ORIGINAL_COORDINATE_SYSTEM"]
        for key, value in crs.items():
            if isinstance(value, list):
                lines.append(f"{key} " + " ".join(f'"{v}"' for v in value))
            elif key == "NAME":
                lines.append(f"{key} {quote_rest(str(value))}")
            else:
                lines.append(f"{key} {value}".rstrip())
        lines.append("END_ORIGINAL_COORDINATE_SYSTEM")
        return lines
    lines = ["GOCAD_ORIGINAL_COORDINATE_SYSTEM"]
    name = crs.name
    if crs.epsg is not None:
        if name is None:
            name = f"EPSG:{crs.epsg}"
            report(f"GOCAD has no EPSG field: EPSG:{crs.epsg} is written as the CRS name")
        else:
            report(f"GOCAD has no EPSG field: EPSG:{crs.epsg} is not written (NAME {name!r} is)")
    if crs.wkt or crs.proj:
        report("GOCAD has no WKT/PROJ field: the CRS definition is not written")
    if name is not None:
        lines.append(f"NAME {quote_rest(name)}")
    extra = crs.metadata.get("gocad")
    if isinstance(extra, dict):
        for key, value in extra.items():
            lines.append(f"{key.upper()} {value}".rstrip())
    lines.append("AXIS_NAME " + " ".join(f'"{a}"' for a in crs.axis_names))
    lines.append("AXIS_UNIT " + " ".join(f'"{u}"' for u in crs.axis_units))
    lines.append("ZPOSITIVE " + ("Depth" if crs.z_positive == "down" else "Elevation"))
    lines.append("END_ORIGINAL_COORDINATE_SYSTEM")
    return lines


def z_sign_of(crs: CRS | dict[str, Any] | None) -> float:
    if isinstance(crs, dict):
        return -1.0 if crs.get("ZPOSITIVE") == "Depth" else 1.0
    return -1.0 if crs is not None and crs.z_positive == "down" else 1.0


def object_crs(entity: Entity | None, scene_crs: CRS | None) -> CRS | dict[str, Any] | None:
    """The CRS an object is written with: its own (kept from the source) or the scene's."""
    gocad = gocad_metadata(entity)
    if "crs" in gocad:
        own = gocad["crs"]
        return own if isinstance(own, dict) else None
    return scene_crs


def header_lines(
    object_type: str,
    name: str,
    metadata: dict[str, Any],
    color: Any,
    extra: Sequence[tuple[str, str]] = (),
) -> list[str]:
    """``HEADER { ... }`` with every kept key, ``name`` first-class and the colour understood."""
    pairs = [(str(k), str(v)) for k, v in metadata.get("header", [])]
    names = [i for i, (k, _) in enumerate(pairs) if k.lower() == "name"]
    if names:
        if name:
            key = pairs[names[0]][0]
            pairs[names[0]] = (key, name)
    elif name:
        pairs.insert(0, ("name", name))
    for key, value in extra:  # values the writer must impose (name_in_model_list)
        same = [i for i, (k, _) in enumerate(pairs) if k == key]
        if same:
            pairs[same[0]] = (key, value)
        else:
            pairs.append((key, value))
    if isinstance(color, list) and len(color) in (3, 4):
        color_key = _COLOR_KEY.get(object_type, "*solid*color")
        keys = [i for i, (k, _) in enumerate(pairs) if k.endswith("color")]
        text = " ".join(format_float(c) for c in color)
        if keys:
            index = keys[0]
            if color_from_text(pairs[index][1]) != [float(c) for c in (*color, 1.0)][:4]:
                pairs[index] = (pairs[index][0], text)
        else:
            pairs.append((color_key, text))
    return ["HEADER {", *(f"{k}:{v}" for k, v in pairs), "}"]


def geology_lines(
    metadata: dict[str, Any], kind: str | None, object_type: str, derive_type: bool = True
) -> list[str]:
    geology = metadata.get("geology") or {}
    lines = []
    if "GEOLOGICAL_FEATURE" in geology:
        lines.append(f"GEOLOGICAL_FEATURE {quote_rest(str(geology['GEOLOGICAL_FEATURE']))}")
    geo_type = geology.get("GEOLOGICAL_TYPE")
    if (
        derive_type
        and geo_type is None
        and kind in _TYPE_OF_KIND
        and object_type in ("TSurf", "PLine")
    ):
        geo_type = _TYPE_OF_KIND[kind]
    if geo_type is not None:
        lines.append(f"GEOLOGICAL_TYPE {geo_type}")
    if "STRATIGRAPHIC_POSITION" in geology:
        lines.append("STRATIGRAPHIC_POSITION " + " ".join(geology["STRATIGRAPHIC_POSITION"]))
    return lines


_TYPE_OF_KIND = {
    "fault": "fault",
    "horizon": "top",
    "boundary": "boundary",
    "unconformity": "unconformity",
    "intrusion": "intrusive",
}


def property_header(
    props: dict[str, Property], prefix: str, skip: Sequence[str], where: str
) -> tuple[list[str], list[tuple[str, Property]]]:
    """Property-header lines and the properties written, in order."""
    chosen = [(n, p) for n, p in props.items() if n not in skip]
    if not chosen:
        return [], []
    metas = [gocad_section(p.metadata) for _, p in chosen]
    lines = [f"{prefix}PROPERTIES " + " ".join(quote(n) for n, _ in chosen)]

    def line(keyword: str, values: list[str]) -> None:
        lines.append(f"{prefix}{keyword} " + " ".join(values))

    # Every keyword is written (OpenGeode reads them in this fixed order) except
    # NO_DATA_VALUES when no property has one; absent entries get the defaults the reader maps
    # back to "absent".
    line(
        "PROP_LEGAL_RANGES",
        [" ".join(m.get("legal_range", ["**none**", "**none**"])) for m in metas],
    )
    missing = [n for n, p in chosen if p.no_data_value is None]
    if len(missing) < len(chosen):  # written when any property has one (OpenGeode needs it)
        if missing:
            report(f"{where}: properties {missing} have no no-data value; -99999 is written")
        line(
            "NO_DATA_VALUES",
            [
                format_float(p.no_data_value if p.no_data_value is not None else -99999.0)
                for _, p in chosen
            ],
        )
    line(
        "PROPERTY_CLASSES",
        [quote(m.get("class", n)) for (n, _), m in zip(chosen, metas, strict=True)],
    )
    line("PROPERTY_KINDS", [quote(m.get("kind", "unknown")) for m in metas])
    line(
        "PROPERTY_SUBCLASSES",
        [" ".join(m.get("subclass", ["QUANTITY", "Float"])) for m in metas],
    )
    line("ESIZES", [str(p.element_size) for _, p in chosen])
    line("UNITS", [quote(p.unit or "none") for _, p in chosen])
    if any("read_only" in m for m in metas):
        line("READ_ONLY", [m.get("read_only", "0") for m in metas])
    for name, prop in chosen:
        if prop.dtype.kind not in "fiub":
            report(f"{where}: property {name!r} ({prop.dtype}) is written as numbers")
        elif prop.dtype.kind != "f":
            report(f"{where}: integer property {name!r} is read back as float64")
    return lines, chosen


def class_header_lines(metadata: dict[str, Any]) -> list[str]:
    lines: list[str] = []
    for name, entries in (metadata.get("class_headers") or {}).items():
        lines.append(f"PROPERTY_CLASS_HEADER {name} {{")
        lines.extend(f"{k}:{v}" for k, v in entries.items())
        lines.append("}")
    return lines


def value_columns(props: list[tuple[str, Property]], n: int) -> NDArray[np.float64]:
    """The properties side by side as float64 (what GOCAD stores), one row per element."""
    if not props:
        return np.zeros((n, 0))
    return np.concatenate(
        [np.asarray(p.values).reshape(n, p.element_size).astype(np.float64) for _, p in props],
        axis=1,
    )


def part_vertex_ranges(
    n_vertices: int, cells: NDArray[np.int64], parts: NDArray[np.int64], n_parts: int
) -> NDArray[np.int64]:
    """Start index of each part's vertex block (``n_parts + 1`` entries, last = n_vertices).

    Every vertex a part's cells use is declared in that part or an earlier one; vertex order
    is kept.
    """
    need = np.zeros(n_parts, dtype=np.int64)
    if cells.size:
        used = cells.max(axis=1) + 1
        np.maximum.at(need, parts, used)
    need = np.maximum.accumulate(need) if n_parts else need
    starts = np.zeros(n_parts + 1, dtype=np.int64)
    if n_parts:
        starts[1:n_parts] = need[: n_parts - 1]
    starts[n_parts] = n_vertices
    return starts


_MIX = (0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9)


def duplicate_of(vertices: NDArray[np.float64]) -> NDArray[np.int64]:
    """For each vertex, the first earlier vertex with the same coordinate bits, else -1."""
    n = vertices.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    bits = np.ascontiguousarray(vertices).view(np.int64).reshape(n, 3)
    with np.errstate(over="ignore"):  # a hash of the bits: equal rows have equal hashes
        mixed = bits.view(np.uint64) * np.array(_MIX, dtype=np.uint64)
        key = mixed[:, 0] ^ (mixed[:, 1] >> np.uint64(1)) ^ (mixed[:, 2] << np.uint64(1))
    hashed = np.sort(key)
    if not (hashed[1:] == hashed[:-1]).any():
        return np.full(n, -1, dtype=np.int64)  # no two rows alike (the common case)
    order = np.lexsort((np.arange(n), bits[:, 2], bits[:, 1], bits[:, 0]))
    ranked = bits[order]
    same = (ranked[1:] == ranked[:-1]).all(axis=1)
    result = np.full(n, -1, dtype=np.int64)
    if not same.any():
        return result
    starts = np.flatnonzero(np.r_[True, ~same])
    group = np.cumsum(np.r_[True, ~same]) - 1
    owner = order[starts][group]  # lowest index of each group (index breaks ties in lexsort)
    duplicate = owner != order
    result[order[duplicate]] = owner[duplicate]
    return result


class VertexWriter:
    """Formats the vertex lines of an object, ranges at a time."""

    def __init__(
        self,
        vertices: NDArray[np.float64],
        values: NDArray[Any],
        flags: NDArray[np.integer[Any]] | None,
        z_sign: float,
        atom_keyword: str = "ATOM",
    ) -> None:
        xyz = np.array(vertices, dtype=np.float64)
        if z_sign < 0:
            xyz[:, 2] = -xyz[:, 2]
        self.xyz = xyz
        self.values = values
        self.flags = flags
        self.atoms = duplicate_of(np.asarray(vertices, dtype=np.float64))
        self.has_values = values.shape[1] > 0
        self.atom_keyword = ("P" + atom_keyword if self.has_values else atom_keyword).encode()

    def lines(self, lo: int, hi: int) -> list[bytes]:
        """The lines of vertices ``lo .. hi - 1`` (ids ``lo + 1 ..``) as pieces to concatenate
        (see :func:`~geobrep.adapters.gocad._numbers.row_pieces`), no final newline."""
        if hi <= lo:
            return []
        atoms = self.atoms[lo:hi]
        is_atom = atoms >= 0
        pieces: list[bytes] = []
        keyword = b"PVRTX" if self.has_values else b"VRTX"
        cuts = np.flatnonzero(np.diff(is_atom.astype(np.int8))) + 1
        for a, b in zip(np.r_[0, cuts].tolist(), np.r_[cuts, hi - lo].tolist(), strict=True):
            ids = np.arange(lo + a + 1, lo + b + 1, dtype=np.int64)
            values = self.values[lo + a : lo + b] if self.has_values else None
            if pieces:
                pieces.append(b"\n")
            if is_atom[a]:
                refs = atoms[a:b] + 1
                pieces += row_pieces(self.atom_keyword, np.column_stack([ids, refs]), values)
            else:
                data = self.xyz[lo + a : lo + b]
                if values is not None:
                    data = np.concatenate([data, values], axis=1)
                pieces += row_pieces(keyword, ids, data)
        if self.flags is not None:
            flags = np.asarray(self.flags[lo:hi])
            if flags.any():
                rows = b"".join(pieces).split(b"\n")
                for i in np.flatnonzero(flags).tolist():
                    rows[i] += _FLAG_TEXT.get(int(flags[i]), b"")
                pieces = [b"\n".join(rows)]
        return pieces


class ObjectText:
    """Accumulates the lines of one object as bytes, joined once at the end."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []

    def add(self, *lines: str) -> None:
        for line in lines:
            self.parts += (line.encode("utf-8"), b"\n")

    def add_bytes(self, block: bytes) -> None:
        """Lines of text (no final newline)."""
        if block:
            self.parts += (block, b"\n")

    def add_pieces(self, pieces: list[bytes]) -> None:
        """Lines of text given as pieces to concatenate (no final newline)."""
        if pieces:
            self.parts += (*pieces, b"\n")

    def text(self) -> bytes:
        return b"".join(self.parts)
