"""SKUA horizon stacks (.xml): a stratigraphic column as the order of horizons and units.

A SKUA ``<UserObjects>`` file holds ``<LocalStratigraphicColumn>`` elements, each a ``<name>``,
a ``<classification_type>``, ``<rank_names>`` and ``<units>``: units from the top of the column
down, each with a ``<name>``, a ``<color>`` and the horizons at its ``<top>`` and ``<base>``
(each a ``<name>``, a ``<relation>``, ``stratigraphic`` or ``structural`` (an erosion), and a
``<color>``). A column becomes one group of kind ``stratigraphic_column`` whose two children
list, top down, its horizons (kind ``horizon``, in the order the units name them) and its units
(kind ``stratigraphic_unit``, each unit's ``top`` and ``base`` in its metadata). Written back,
a column is the same XML: read → write gives the bytes SKUA wrote.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Final
from xml.etree.ElementTree import Element
from xml.sax.saxutils import escape, quoteattr

from pydantic import JsonValue

from geobrep.adapters.gocad._safe_xml import parse_xml
from geobrep.errors import EntityValidationError, FormatError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.scene import Group, Scene

__all__ = [
    "COLUMN",
    "HORIZON",
    "HORIZONS",
    "UNIT",
    "UNITS",
    "horizons_stack_text",
    "looks_like_horizons_stack",
    "read_horizons_stack",
    "stack_losses",
    "stratigraphic_columns",
    "write_horizons_stack",
]

COLUMN: Final = "stratigraphic_column"
HORIZONS: Final = "horizons"
HORIZON: Final = "horizon"
UNITS: Final = "stratigraphic_units"
UNIT: Final = "stratigraphic_unit"

_ROOT: Final = "UserObjects"
_COLUMN_TAG: Final = "LocalStratigraphicColumn"
_COLUMN_PARTS: Final = frozenset({"name", "classification_type", "rank_names", "units"})
_UNIT_PARTS: Final = frozenset({"name", "color", "top", "base"})
_BOUNDARY_PARTS: Final = frozenset({"name", "relation", "color"})
_SNIFF = re.compile(
    rb"\s*(<\?xml[^>]*\?>\s*)?(<!--.*?-->\s*)*<(UserObjects|LocalStratigraphicColumn)[\s/>]", re.S
)
# what XML 1.0 can hold: tab, newline, carriage return and the characters from space on
_XML_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.-]*")
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def looks_like_horizons_stack(head: bytes) -> bool:
    """True when the first element is ``<UserObjects>`` or ``<LocalStratigraphicColumn>``."""
    return _SNIFF.match(head.removeprefix(b"\xef\xbb\xbf")) is not None


class _Reading:
    """One file being read: its path, the lines of its elements and what was skipped."""

    def __init__(self, path: Path, lines: dict[Element, int]) -> None:
        self.path = path
        self.lines = lines
        self.skipped: list[str] = []

    def error(self, message: str, element: Element) -> FormatError:
        return FormatError(message, self.path, self.lines.get(element))

    def text(self, element: Element, tag: str, *, required: bool = True) -> str | None:
        """The stripped text of ``element``'s one ``<tag>`` child."""
        found = element.findall(tag)
        if len(found) > 1:
            raise self.error(f"<{element.tag}> has {len(found)} <{tag}> elements", found[1])
        if not found:
            if required:
                raise self.error(f"<{element.tag}> has no <{tag}>", element)
            return None
        if len(found[0]):
            raise self.error(f"<{tag}> holds elements, not text", found[0])
        return (found[0].text or "").strip()

    def color(self, element: Element) -> list[float] | None:
        text = self.text(element, "color", required=False)
        if text is None:
            return None
        try:
            values = [float(t) for t in text.split()]
        except ValueError:
            raise self.error(f"<color> {text[:40]!r} is not numbers", element) from None
        if len(values) not in (3, 4) or not all(math.isfinite(v) for v in values):
            raise self.error(f"<color> {text[:40]!r} is not 3 or 4 finite numbers", element)
        return values

    def skip_unknown(self, element: Element, known: frozenset[str]) -> None:
        for child in element:
            if child.tag not in known:
                line = self.lines.get(child)
                self.skipped.append(f"<{child.tag}> of <{element.tag}> (line {line})")


def _boundary(reading: _Reading, unit: Element, side: str) -> dict[str, JsonValue] | None:
    found = unit.findall(side)
    if len(found) > 1:
        raise reading.error(f"a unit has {len(found)} <{side}> horizons", found[1])
    if not found:
        return None
    element = found[0]
    reading.skip_unknown(element, _BOUNDARY_PARTS)
    name = reading.text(element, "name")
    if not name:
        raise reading.error(f"the <{side}> horizon has an empty <name>", element)
    boundary: dict[str, JsonValue] = {"horizon": name}
    relation = reading.text(element, "relation", required=False)
    if relation is not None:
        boundary["relation"] = relation
    color = reading.color(element)
    if color is not None:
        boundary["color"] = list(color)
    return boundary


def _unit(reading: _Reading, element: Element) -> Group:
    reading.skip_unknown(element, _UNIT_PARTS)
    name = reading.text(element, "name")
    if not name:
        raise reading.error("a unit has an empty <name>", element)
    metadata: dict[str, JsonValue] = {}
    color = reading.color(element)
    if color is not None:
        metadata["color"] = list(color)
    for side in ("top", "base"):
        boundary = _boundary(reading, element, side)
        if boundary is not None:
            metadata[side] = boundary
    return Group(name=name, kind=UNIT, metadata=metadata)


def _horizons(units: list[Group]) -> list[Group]:
    """The horizons the units name, top down, each with the colour it first has."""
    horizons: dict[str, dict[str, JsonValue]] = {}
    for unit in units:
        for side in ("top", "base"):
            boundary = unit.metadata.get(side)
            if isinstance(boundary, dict) and isinstance(boundary["horizon"], str):
                name = boundary["horizon"]
                if name not in horizons:
                    color = boundary.get("color")
                    horizons[name] = {} if color is None else {"color": color}
    return [Group(name=n, kind=HORIZON, metadata=m) for n, m in horizons.items()]


def _column(reading: _Reading, element: Element) -> Group:
    reading.skip_unknown(element, _COLUMN_PARTS)
    skua: dict[str, JsonValue] = {"attributes": dict(element.attrib)}
    kind = reading.text(element, "classification_type", required=False)
    if kind is not None:
        skua["classification_type"] = kind
    ranks = element.findall("rank_names")
    if len(ranks) > 1:
        raise reading.error(f"a column has {len(ranks)} <rank_names> elements", ranks[1])
    if ranks:
        reading.skip_unknown(ranks[0], frozenset({"rank_name"}))
        skua["rank_names"] = [(r.text or "").strip() for r in ranks[0].findall("rank_name")]
    units_parts = element.findall("units")
    if len(units_parts) != 1:
        raise reading.error(f"a column has {len(units_parts)} <units> elements, not 1", element)
    skua["units_attributes"] = dict(units_parts[0].attrib)
    reading.skip_unknown(units_parts[0], frozenset({"unit"}))
    units = [_unit(reading, u) for u in units_parts[0].findall("unit")]
    return Group(
        name=reading.text(element, "name") or "",
        kind=COLUMN,
        metadata={"skua": skua},
        children=(
            Group(name="horizons", kind=HORIZONS, children=tuple(_horizons(units))),
            Group(name="units", kind=UNITS, children=tuple(units)),
        ),
    )


def read_horizons_stack(path: Path) -> Scene:
    """The stratigraphic columns of a SKUA ``<UserObjects>`` file, as groups of an empty scene."""
    root, lines = parse_xml(path)
    reading = _Reading(path, lines)
    if root.tag == _COLUMN_TAG:
        columns = [root]
    elif root.tag == _ROOT:
        reading.skip_unknown(root, frozenset({_COLUMN_TAG}))
        columns = root.findall(_COLUMN_TAG)
    else:
        raise reading.error(f"the root element is <{root.tag}>, not <{_ROOT}>", root)
    if not columns:
        raise reading.error(f"<{_ROOT}> holds no <{_COLUMN_TAG}>", root)
    groups = [_column(reading, c) for c in columns]
    metadata: dict[str, JsonValue] = {}
    if reading.skipped:
        metadata[SKIPPED_ON_READ] = list(reading.skipped)
    return Scene(name=path.stem, groups=groups, metadata=metadata)


# -- writing ---------------------------------------------------------------------------------
def stratigraphic_columns(scene: Scene) -> list[Group]:
    """The groups of kind ``stratigraphic_column`` anywhere in ``scene``'s group tree."""
    return [g for root in scene.groups for g in root.walk() if g.kind == COLUMN]


def _number(value: float) -> str:
    """The shortest exact text of ``value`` (``1`` for 1.0, as SKUA writes it)."""
    text = repr(float(value))
    return text.removesuffix(".0")


class _Writing:
    """The XML lines of one file being written, and the group being written (for errors)."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.where = "groups"

    def bad(self, field: str, reason: str) -> EntityValidationError:
        return EntityValidationError("Group", f"{self.where}.{field}", reason)

    def checked(self, value: object, field: str) -> str:
        if not isinstance(value, str):
            raise self.bad(field, f"is {type(value).__name__}, not text")
        if _NOT_XML.search(value):
            raise self.bad(field, f"{value[:40]!r} holds a character XML cannot hold")
        return value

    def text(self, value: object, field: str) -> str:
        return escape(self.checked(value, field), {"\r": "&#13;"})

    def element(self, depth: int, tag: str, value: object, field: str) -> None:
        self.lines.append(f"{' ' * depth}<{tag}>{self.text(value, field)}</{tag}>")

    def open(self, depth: int, tag: str, attributes: object = None, field: str = "") -> None:
        if attributes is None:
            attributes = {}
        if not isinstance(attributes, dict):
            raise self.bad(field, "is not a mapping of XML attributes")
        for key in attributes:
            if not isinstance(key, str) or not _XML_NAME.fullmatch(key):
                raise self.bad(field, f"{key!r} is not an XML attribute name")
        pairs = "".join(f" {k}={quoteattr(self.checked(v, field))}" for k, v in attributes.items())
        self.lines.append(f"{' ' * depth}<{tag}{pairs}>")

    def close(self, depth: int, tag: str) -> None:
        self.lines.append(f"{' ' * depth}</{tag}>")

    def color(self, depth: int, value: object, field: str) -> None:
        if value is None:
            return
        if (
            not isinstance(value, list | tuple)
            or len(value) not in (3, 4)
            or not all(isinstance(v, int | float) and math.isfinite(v) for v in value)
        ):
            raise self.bad(field, "is not 3 or 4 finite numbers")
        self.lines.append(f"{' ' * depth}<color>{' '.join(_number(v) for v in value)}</color>")


def _part(column: Group, kind: str) -> Group | None:
    found = [c for c in column.children if c.kind == kind]
    return found[0] if found else None


def _write_boundary(
    writing: _Writing, side: str, boundary: object, colors: dict[str, JsonValue]
) -> None:
    if boundary is None:
        return
    if not isinstance(boundary, dict) or "horizon" not in boundary:
        raise writing.bad(f"metadata[{side!r}]", "is not a mapping with a 'horizon' name")
    writing.open(4, side)
    writing.element(5, "name", boundary["horizon"], f"metadata[{side!r}]['horizon']")
    if "relation" in boundary:
        writing.element(5, "relation", boundary["relation"], f"metadata[{side!r}]['relation']")
    color = boundary.get("color", colors.get(str(boundary["horizon"])))
    writing.color(5, color, f"metadata[{side!r}]['color']")
    writing.close(4, side)


def _write_unit(writing: _Writing, unit: Group, colors: dict[str, JsonValue]) -> None:
    writing.where = f"groups[{unit.name!r}]"
    writing.open(3, "unit")
    writing.element(4, "name", unit.name, "name")
    writing.color(4, unit.metadata.get("color"), "metadata['color']")
    for side in ("top", "base"):
        _write_boundary(writing, side, unit.metadata.get(side), colors)
    writing.close(3, "unit")


def _write_column(writing: _Writing, column: Group) -> None:
    writing.where = f"groups[{column.name!r}]"
    skua = column.metadata.get("skua", {})
    if not isinstance(skua, dict):
        raise writing.bad("metadata['skua']", "is not a mapping")
    writing.open(1, _COLUMN_TAG, skua.get("attributes"), "metadata['skua']['attributes']")
    writing.element(2, "name", column.name, "name")
    if "classification_type" in skua:
        field = "metadata['skua']['classification_type']"
        writing.element(2, "classification_type", skua["classification_type"], field)
    ranks = skua.get("rank_names")
    if ranks is not None:
        if not isinstance(ranks, list):
            raise writing.bad("metadata['skua']['rank_names']", "is not a list of names")
        writing.open(2, "rank_names")
        for rank in ranks:
            writing.element(3, "rank_name", rank, "metadata['skua']['rank_names']")
        writing.close(2, "rank_names")
    horizons = _part(column, HORIZONS)
    colors = {h.name: h.metadata.get("color") for h in (horizons.children if horizons else ())}
    colors = {k: v for k, v in colors.items() if v is not None}
    units = _part(column, UNITS)
    field = "metadata['skua']['units_attributes']"
    writing.open(2, "units", skua.get("units_attributes"), field)
    for unit in units.children if units else ():
        _write_unit(writing, unit, colors)
    writing.close(2, "units")
    writing.close(1, _COLUMN_TAG)


def horizons_stack_text(scene: Scene) -> str:
    """The SKUA ``<UserObjects>`` XML of ``scene``'s stratigraphic columns."""
    writing = _Writing()
    writing.open(0, _ROOT)
    for column in stratigraphic_columns(scene):
        _write_column(writing, column)
    writing.close(0, _ROOT)
    return "\n".join(writing.lines) + "\n\n"


def write_horizons_stack(scene: Scene, path: Path, options: object) -> None:
    """Write ``scene``'s stratigraphic columns as a SKUA horizon stack."""
    if not stratigraphic_columns(scene):
        raise FormatError(
            f"the scene has no stratigraphic column (a group of kind {COLUMN!r}) to write", path
        )
    path.write_text(horizons_stack_text(scene), encoding="utf-8")


def stack_losses(scene: Scene, path: Path) -> list[str]:
    """The groups a horizon stack cannot hold (all but the stratigraphic columns)."""
    columns = {id(g) for c in stratigraphic_columns(scene) for g in c.walk()}
    inside = [g for root in scene.groups for g in root.walk() if id(g) not in columns]
    other = [g for g in inside if not any(id(c) in columns for c in g.walk())]
    if not other:
        return []
    return [f"{len(other)} groups other than stratigraphic columns dropped"]
