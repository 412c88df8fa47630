"""GOCAD Well (.wl): a well head (``WREF``), stations, markers, zones and log curves.

Stations are ``PATH md z dx dy`` (``TVSS_PATH`` likewise, z being true vertical depth sub-sea)
offsets from ``WREF``, or ``VRTX x y z`` absolute points (their MD is then the length along the
stations). ``MRKR name flag md`` places a marker (its ``DIP``/``NORM`` lines are kept in its
metadata), ``ZONE name top_md base_md index`` a zone, and ``WELL_CURVE`` ... ``END_CURVE`` a log
whose ``REC md value`` rows (or ``SEEK`` ... ``PROPERTY``/``REC``) follow. ``ZPOSITIVE Depth``
files store depth: z is negated on reading and writing.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from geobrep.adapters.gocad._headers import quote, quote_rest
from geobrep.adapters.gocad._keyed import KeyedLine, parse_keyed, read_text
from geobrep.adapters.gocad._numbers import format_float
from geobrep.adapters.gocad._objects import crs_block, z_sign_of
from geobrep.errors import EntityValidationError, FormatError
from geobrep.model.crs import CRS
from geobrep.model.entities import Well, WellLog, WellMarker, WellZone

__all__ = ["read_well", "well_text"]


class _Curve:
    def __init__(self, line: KeyedLine) -> None:
        self.line = line
        self.name = ""
        self.unit: str | None = None
        self.no_data: float | None = None
        self.md: list[float] = []
        self.values: list[float] = []


def _curve_line(curve: _Curve, line: KeyedLine) -> None:
    if line.keyword == "PROPERTY":
        curve.name = line.rest()
    elif line.keyword == "UNIT":
        curve.unit = line.rest()
    elif line.keyword == "NO_DATA_VALUE" or line.keyword == "PROP_NO_DATA_VALUE":
        curve.no_data = line.floats(1)[0]
    elif line.keyword == "REC":
        md, value = line.floats(2)
        curve.md.append(md)
        curve.values.append(value)


class _WellBuilder:
    def __init__(self, z_sign: float) -> None:
        self.z_sign = z_sign
        self.head: list[float] | None = None
        self.path_rows: list[list[float]] = []
        self.vertices: list[list[float]] = []
        self.markers: list[WellMarker] = []
        self.zones: list[WellZone] = []
        self.curves: list[_Curve] = []
        self.datum = ""
        self.datum_elevation: float | None = None
        self.curve: _Curve | None = None

    def line(self, line: KeyedLine) -> None:
        keyword = line.keyword
        if self.curve is not None:
            if keyword == "END_CURVE":
                self.curves.append(self.curve)
                self.curve = None
            else:
                _curve_line(self.curve, line)
            return
        if keyword == "WREF":
            self.head = line.floats(3)
        elif keyword in ("PATH", "TVSS_PATH"):
            self.path_rows.append(line.floats(4))
        elif keyword in ("VRTX", "PVRTX"):
            self.vertices.append(line.floats(3, 1))
        elif keyword == "DATUM":
            self.datum = line.rest()
        elif keyword in ("KB", "GL", "DATUM_ELEVATION"):
            self.datum_elevation = line.floats(1)[0]
        elif keyword == "MRKR":
            self._marker(line)
        elif keyword in ("DIP", "NORM", "MREF") and self.markers:
            last = self.markers[-1]
            meta = {**last.metadata, keyword.lower(): line.rest()}
            self.markers[-1] = last.model_copy(update={"metadata": meta})
        elif keyword == "ZONE":
            self._zone(line)
        elif keyword == "WELL_CURVE":
            self.curve = _Curve(line)

    def _marker(self, line: KeyedLine) -> None:
        if len(line.tokens) < 3:
            raise line.error("needs a name, a flag and a measured depth")
        md = line.floats(1, len(line.tokens) - 1)[0]
        self.markers.append(WellMarker(name=line.tokens[0], md=md))

    def _zone(self, line: KeyedLine) -> None:
        if len(line.tokens) < 3:
            raise line.error("needs a name, a top MD and a base MD")
        top, base = line.floats(2, 1)
        if not base >= top:
            raise line.error(f"zone {line.tokens[0]!r}: base MD {base} is above top MD {top}")
        self.zones.append(WellZone(name=line.tokens[0], top_md=top, base_md=base))


def _stations(builder: _WellBuilder, path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    head = np.array(builder.head if builder.head is not None else [0.0, 0.0, 0.0])
    head[2] *= builder.z_sign
    if builder.path_rows:
        rows = np.array(builder.path_rows)
        xyz = np.stack(
            [head[0] + rows[:, 2], head[1] + rows[:, 3], rows[:, 1] * builder.z_sign], axis=1
        )
        return head, xyz, rows[:, 0]
    if builder.vertices:
        xyz = np.array(builder.vertices)
        xyz[:, 2] *= builder.z_sign
        steps = np.linalg.norm(np.diff(np.vstack([head, xyz]), axis=0), axis=1)
        return head, xyz, np.cumsum(steps)
    if builder.head is None:
        raise FormatError("the well has no WREF, PATH or VRTX line", path)
    return head, head[None, :], np.zeros(1)


def read_well(
    path: Path, text: str | None = None, inherited: dict[str, Any] | None = None
) -> tuple[Well, dict[str, Any] | None]:
    """The well of a .wl file, and its CRS block (``text`` and ``inherited``: a group
    member's text and the group's CRS block, as for a Voxet)."""
    if text is None:
        text = read_text(path, "Well file")
    keyed, _ = parse_keyed(path, text)
    z_sign = -1.0 if (keyed.crs or inherited or {}).get("ZPOSITIVE") == "Depth" else 1.0
    builder = _WellBuilder(z_sign)
    for line in keyed.lines:
        builder.line(line)
    head, xyz, md = _stations(builder, path)
    logs: dict[str, WellLog] = {}
    for curve in builder.curves:
        name = curve.name or f"curve_{len(logs) + 1}"
        logs[name] = WellLog(
            md=curve.md,
            values=np.array(curve.values),
            unit=curve.unit,
            no_data_value=curve.no_data,
        )
    metadata: dict[str, Any] = {"gocad": {"type": "Well"}}
    try:
        well = Well(
            name=keyed.name,
            head=head,
            vertices=xyz,
            md=md,
            datum=builder.datum,
            datum_elevation=builder.datum_elevation,
            markers=tuple(builder.markers),
            zones=tuple(builder.zones),
            logs=logs,
            metadata=metadata,
        )
    except EntityValidationError as exc:
        raise FormatError(f"the well is invalid: {exc}", path) from None
    return well, keyed.crs


def _f(value: float) -> str:
    return format_float(value) if math.isfinite(value) else "0"


def well_text(well: Well, crs: CRS | None) -> str:
    """The .wl text of ``well`` (stations as ``PATH md z dx dy`` rows)."""
    sign = z_sign_of(crs)
    lines = ["GOCAD Well 1", "HEADER {", f"name:{quote_rest(well.name or 'well')}", "}"]
    lines += crs_block(crs)
    head = well.head
    lines.append(f"WREF {_f(head[0])} {_f(head[1])} {_f(head[2] * sign)}")
    if well.datum:
        lines.append(f"DATUM {well.datum}")
    if well.datum_elevation is not None:
        lines.append(f"KB {_f(well.datum_elevation)}")
    for md, (x, y, z) in zip(well.md, well.vertices, strict=True):
        lines.append(f"PATH {_f(md)} {_f(z * sign)} {_f(x - head[0])} {_f(y - head[1])}")
    for marker in well.markers:
        lines.append(f"MRKR {quote(marker.name)} 0 {_f(marker.md)}")
    for zone in well.zones:
        lines.append(f"ZONE {quote(zone.name)} {_f(zone.top_md)} {_f(zone.base_md)} 0")
    for name, log in well.logs.items():
        lines += ["WELL_CURVE", f"PROPERTY {name}"]
        if log.unit:
            lines.append(f"UNIT {log.unit}")
        if log.no_data_value is not None:
            lines.append(f"NO_DATA_VALUE {format_float(log.no_data_value)}")
        lines += [f"REC {_f(m)} {format_float(v)}" for m, v in zip(log.md, log.values, strict=True)]
        lines.append("END_CURVE")
    lines.append("END")
    return "\n".join(lines) + "\n"
