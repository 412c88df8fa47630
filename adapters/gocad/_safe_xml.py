"""XML of untrusted files parsed safely: no DTD, so no entity expansion or external entities.

The standard library's parsers expand the entities a ``<!DOCTYPE>`` declares (a "billion
laughs" of a few hundred bytes expands to gigabytes) and may resolve external ones. This parser
drives expat directly and refuses any ``<!DOCTYPE>``, any entity declaration and any reference to
an external entity, bounds the file's size and the nesting depth, and keeps the line of each
element for error messages.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> (folder / "a.xml").write_text("<a><b>x</b></a>")
15
>>> root, lines = parse_xml(folder / "a.xml")
>>> root.find("b").text, lines[root.find("b")]
('x', 1)
>>> _ = (folder / "bomb.xml").write_text('<!DOCTYPE a [<!ENTITY x "xx">]><a>&x;</a>')
>>> parse_xml(folder / "bomb.xml")
Traceback (most recent call last):
...
geobrep.errors.FormatError: ...bomb.xml:1: a <!DOCTYPE> is refused (no DTD or entities are read)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Final
from xml.etree.ElementTree import Element, TreeBuilder
from xml.parsers import expat

from geobrep.adapters.limits import human_bytes
from geobrep.errors import FormatError

__all__ = ["MAX_DEPTH", "MAX_XML_BYTES", "parse_xml"]

MAX_XML_BYTES: Final = 16 * 2**20
"""The largest XML file read (16 MiB)."""
MAX_DEPTH: Final = 64
"""The deepest nesting of elements read."""


class _RefusedError(Exception):
    """Raised from an expat handler; becomes a FormatError at the handler's line."""


class _Builder:
    """Expat handlers feeding a :class:`TreeBuilder`, with each element's line."""

    def __init__(self, parser: Any) -> None:
        self.parser = parser
        self.tree = TreeBuilder()
        self.lines: dict[Element, int] = {}
        self.depth = 0

    def start(self, tag: str, attributes: dict[str, str]) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise _RefusedError(f"elements are nested more than {MAX_DEPTH} deep")
        self.lines[self.tree.start(tag, attributes)] = self.parser.CurrentLineNumber

    def end(self, tag: str) -> None:
        self.depth -= 1
        self.tree.end(tag)


def _refuse(what: str) -> Any:
    def handler(*_: object) -> None:
        raise _RefusedError(what)

    return handler


def parse_xml(path: Path) -> tuple[Element, dict[Element, int]]:
    """The root element of the XML file ``path`` and the line where each element starts.

    Raises:
        FormatError: the file is larger than :data:`MAX_XML_BYTES`, is not well-formed XML,
            has a ``<!DOCTYPE>``, or nests elements deeper than :data:`MAX_DEPTH`.
    """
    size = path.stat().st_size
    if size > MAX_XML_BYTES:
        raise FormatError(
            f"the file is {human_bytes(size)}, more than the "
            f"{human_bytes(MAX_XML_BYTES).replace('.0 ', ' ')} an XML file may be",
            path,
        )
    parser = expat.ParserCreate()
    builder = _Builder(parser)
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.tree.data
    parser.StartDoctypeDeclHandler = _refuse(
        "a <!DOCTYPE> is refused (no DTD or entities are read)"
    )
    parser.EntityDeclHandler = _refuse("an entity declaration is refused")
    parser.ExternalEntityRefHandler = _refuse("an external entity is refused")
    try:
        parser.Parse(path.read_bytes(), True)
    except expat.ExpatError as exc:
        message = expat.ErrorString(exc.code) if exc.code is not None else str(exc)
        raise FormatError(f"not well-formed XML: {message}", path, exc.lineno) from None
    except _RefusedError as exc:
        raise FormatError(str(exc), path, parser.CurrentLineNumber) from None
    return builder.tree.close(), builder.lines
