"""The parts every GOCAD object shares: HEADER, CRS block, geology lines, property headers."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from geobrep.adapters.gocad._lexer import split_tokens
from geobrep.adapters.gocad._numbers import parse_float
from geobrep.adapters.gocad._records import Warn

__all__ = [
    "PROPERTY_KEYWORDS",
    "PropertySpec",
    "color_from_text",
    "parse_property_line",
]

#: Property-header keywords (each also exists with a TRGL_, SEG_ or TETRA_ prefix).
PROPERTY_KEYWORDS = (
    "PROPERTIES",
    "PROP_LEGAL_RANGES",
    "NO_DATA_VALUES",
    "PROPERTY_CLASSES",
    "PROPERTY_KINDS",
    "PROPERTY_SUBCLASSES",
    "ESIZES",
    "UNITS",
    "READ_ONLY",
)

_NAMED_COLORS = {
    "white": [1.0, 1.0, 1.0, 1.0],
    "black": [0.0, 0.0, 0.0, 1.0],
    "red": [1.0, 0.0, 0.0, 1.0],
    "green": [0.0, 1.0, 0.0, 1.0],
    "blue": [0.0, 0.0, 1.0, 1.0],
    "yellow": [1.0, 1.0, 0.0, 1.0],
    "cyan": [0.0, 1.0, 1.0, 1.0],
    "magenta": [1.0, 0.0, 1.0, 1.0],
    "grey": [0.5, 0.5, 0.5, 1.0],
    "gray": [0.5, 0.5, 0.5, 1.0],
    "orange": [1.0, 0.647059, 0.0, 1.0],
}


def color_from_text(text: str) -> list[float] | None:
    """RGBA in [0, 1] from ``r g b [a]``, ``#rrggbb`` or a colour name; None if unreadable.

    >>> color_from_text("#ff8000"), color_from_text("0 0 0.5")
    ([1.0, 0.5019607843137255, 0.0, 1.0], [0.0, 0.0, 0.5, 1.0])
    """
    value = text.strip()
    if value.startswith("#") and len(value) == 7:
        try:
            return [int(value[i : i + 2], 16) / 255.0 for i in (1, 3, 5)] + [1.0]
        except ValueError:
            return None
    if value.lower() in _NAMED_COLORS:
        return list(_NAMED_COLORS[value.lower()])
    parts = value.split()
    if len(parts) in (3, 4):
        try:
            rgba = [float(p) for p in parts]
        except ValueError:
            return None
        if not all(math.isfinite(c) for c in rgba):
            return None
        return rgba if len(rgba) == 4 else [*rgba, 1.0]
    return None


@dataclass
class PropertySpec:
    """What a property header says about one property (vertex or cell).

    Default entries (``**none**`` ranges, class = name, kind ``unknown``, ``QUANTITY Float``,
    unit ``none``) count as absent, so that a writer that always writes every keyword (as
    OpenGeode needs) round-trips exactly.
    """

    name: str
    esize: int = 1
    no_data: float | None = None
    legal_range: tuple[str, str] | None = None
    klass: str | None = None
    kind: str | None = None
    subclass: list[str] | None = None
    unit: str | None = None
    read_only: str | None = None

    def metadata(self) -> dict[str, Any]:
        """What geobrep keeps in ``Property.metadata["gocad"]``."""
        out: dict[str, Any] = {}
        if self.klass is not None and self.klass != self.name:
            out["class"] = self.klass
        if self.kind is not None and self.kind.lower() != "unknown":
            out["kind"] = self.kind
        if self.subclass is not None and self.subclass != ["QUANTITY", "Float"]:
            out["subclass"] = list(self.subclass)
        if self.legal_range is not None and self.legal_range != ("**none**", "**none**"):
            out["legal_range"] = list(self.legal_range)
        if self.read_only is not None:
            out["read_only"] = self.read_only
        return out


@dataclass
class PropertyHeader:
    """The property header of one element kind (vertices or cells).

    Lines are collected as they come and applied together by :meth:`resolve` (when the first
    data line sizes the tables), so that their order in the file does not matter.
    """

    specs: list[PropertySpec] = field(default_factory=list)
    seen: dict[str, int] = field(default_factory=dict)  # keyword -> line
    pending: list[tuple[str, str, int]] = field(default_factory=list)  # (keyword, text, line)
    resolved: bool = False

    @property
    def n_values(self) -> int:
        return sum(spec.esize for spec in self.specs)

    def resolve(self, warn: Warn) -> None:
        """Apply the collected lines: the names first (``PROPERTIES``, or ``PROPERTY_CLASSES``
        when there is no ``PROPERTIES`` line), then every other line in file order."""
        if self.resolved:
            return
        self.resolved = True
        pending, self.pending = self.pending, []
        names = [p for p in pending if p[0] == "PROPERTIES"]
        if not names:
            names = [p for p in pending if p[0] == "PROPERTY_CLASSES"][:1]
            if names:
                warn("PROPERTY_CLASSES without PROPERTIES names the properties", names[0][2])
        for _, text, line in names:
            _name_properties(self, text, line, warn)
        for keyword, text, line in pending:
            if keyword != "PROPERTIES":
                _apply(self, keyword, text, line, warn)


def _subclasses(tokens: list[str]) -> list[list[str]]:
    groups: list[list[str]] = []
    i = 0
    while i < len(tokens):
        width = 4 if tokens[i].upper() == "LINEARFUNCTION" else 2
        groups.append(tokens[i : i + width])
        i += width
    return groups


#: Keywords that change the layout of the value columns (ignored once the tables are sized).
_LAYOUT_KEYWORDS = ("PROPERTIES", "ESIZES")


def parse_property_line(
    header: PropertyHeader, keyword: str, text: str, line: int, warn: Warn
) -> None:
    """One property-header line (``keyword`` without its TRGL_/SEG_/TETRA_ prefix): collected
    until :meth:`PropertyHeader.resolve`, applied at once after it."""
    header.seen[keyword] = line
    if text.count('"') % 2:
        warn(f"{keyword} has an unbalanced quote; the rest of the line is one entry", line)
    if not header.resolved:
        header.pending.append((keyword, text, line))
    elif keyword in _LAYOUT_KEYWORDS:
        warn(f"{keyword} after the data lines is ignored (the value columns are fixed)", line)
    else:
        _apply(header, keyword, text, line, warn)


def _name_properties(header: PropertyHeader, text: str, line: int, warn: Warn) -> None:
    tokens = split_tokens(text)[1:]
    if header.specs:
        warn(f"a second PROPERTIES line replaces the first (line {line})", line)
    header.specs = [PropertySpec(name=name or f"property_{i}") for i, name in enumerate(tokens)]


def _apply(header: PropertyHeader, keyword: str, text: str, line: int, warn: Warn) -> None:
    tokens = split_tokens(text)[1:]
    specs = header.specs
    if not specs:
        warn(f"{keyword} without PROPERTIES is ignored", line)
        return
    groups: list[list[str]] = []
    if keyword == "PROP_LEGAL_RANGES":
        groups = [tokens[i : i + 2] for i in range(0, len(tokens), 2)]
    elif keyword == "PROPERTY_SUBCLASSES":
        groups = _subclasses(tokens)
    count = len(groups) if groups else len(tokens)
    if count != len(specs):
        warn(
            f"{keyword} gives {count} entries for {len(specs)} properties; "
            "extra entries are ignored, missing ones keep their defaults",
            line,
        )
    if keyword == "PROP_LEGAL_RANGES":
        for spec, pair in zip(specs, groups, strict=False):
            if len(pair) == 2:
                spec.legal_range = (pair[0], pair[1])
    elif keyword == "PROPERTY_SUBCLASSES":
        for spec, group in zip(specs, groups, strict=False):
            spec.subclass = list(group)
    else:
        for spec, value in zip(specs, tokens, strict=False):
            _apply_entry(spec, keyword, value, line, warn)


def _apply_entry(spec: PropertySpec, keyword: str, value: str, line: int, warn: Warn) -> None:
    """One entry of a one-token-per-property keyword (ESIZES, NO_DATA_VALUES, UNITS, ...)."""
    if keyword == "ESIZES":
        try:
            size = int(value)
        except ValueError:
            warn(f"ESIZES entry {value!r} is not an integer; using 1", line)
            size = 1
        if size < 1:
            warn(f"ESIZES entry {size} is not positive; using 1", line)
            size = 1
        spec.esize = size
    elif keyword == "NO_DATA_VALUES":
        try:
            spec.no_data = parse_float(value)
        except ValueError:
            warn(f"no-data value {value!r} is not a number; ignored", line)
    elif keyword == "PROPERTY_CLASSES":
        spec.klass = value
    elif keyword == "PROPERTY_KINDS":
        spec.kind = value
    elif keyword == "UNITS":
        spec.unit = None if value.lower() == "none" else value
    elif keyword == "READ_ONLY":
        spec.read_only = value


def quote_rest(text: str) -> str:
    """A rest-of-line value (NAME, REGION and TSURF names): quoted only when it must be.

    >>> quote_rest("gocad Local"), quote_rest(" gocad Local")
    ('gocad Local', '" gocad Local"')
    """
    text = " ".join(text.splitlines())  # one line, whatever the source held
    if text and text == text.strip() and not text.startswith('"'):
        return text
    return '"' + text + '"'


def quote(text: str) -> str:
    """Quote a token (a property name) when it is empty or holds spaces or quotes."""
    if text and not any(c.isspace() for c in text) and '"' not in text:
        return text
    return '"' + text.replace('"', "'") + '"'
