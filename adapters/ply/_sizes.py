"""What a PLY header declares, checked against the file before any row is allocated.

plyfile allocates ``element.count`` rows as soon as it reads an ``element`` line, so a 200-byte
file declaring ``element vertex 400000000`` costs gigabytes before the data is seen.
:func:`check_element_sizes` reads the header alone and refuses a file whose elements need
more bytes than the file holds after its header (each row at least its smallest encoding:
the scalar sizes in binary, one digit and a separator per value in ASCII), or more memory than
the read budget allows (:mod:`geobrep.adapters.limits`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Final

from geobrep.adapters.limits import check_declared
from geobrep.errors import FormatError

__all__ = ["ElementDeclaration", "check_element_sizes", "declared_elements"]

SCALAR_SIZES: Final = {
    **dict.fromkeys(("char", "uchar", "int8", "uint8"), 1),
    **dict.fromkeys(("short", "ushort", "int16", "uint16"), 2),
    **dict.fromkeys(("int", "uint", "int32", "uint32", "float", "float32"), 4),
    **dict.fromkeys(("double", "float64"), 8),
}
#: Memory plyfile spends on each list value beyond its row slot (a small numpy array object).
LIST_OBJECT_BYTES: Final = 120


@dataclass
class ElementDeclaration:
    """One ``element`` of a PLY header: its name, count, line and properties' sizes."""

    name: str
    count: int
    line: int
    scalar_bytes: int = 0
    """Bytes of the scalar properties of one binary row."""
    scalars: int = 0
    lists: int = 0
    list_count_bytes: int = 0
    """Bytes of the list lengths of one binary row (every list may be empty)."""

    def smallest_row(self, binary: bool) -> int:
        """The fewest bytes one row can take in the file."""
        if binary:
            return self.scalar_bytes + self.list_count_bytes
        return 2 * (self.scalars + self.lists)

    def row_memory(self) -> int:
        """Bytes plyfile allocates per row: the row slot plus an object per list."""
        return self.scalar_bytes + self.lists * (8 + LIST_OBJECT_BYTES)


def _property(element: ElementDeclaration, words: list[str]) -> bool:
    """Add the property of ``words`` (``property ...`` split) to ``element``; False if unknown."""
    if len(words) == 5 and words[1] == "list":
        count_size = SCALAR_SIZES.get(words[2])
        if count_size is None or words[3] not in SCALAR_SIZES:
            return False
        element.lists += 1
        element.list_count_bytes += count_size
        return True
    if len(words) == 3 and words[1] in SCALAR_SIZES:
        element.scalars += 1
        element.scalar_bytes += SCALAR_SIZES[words[1]]
        return True
    return False


def declared_elements(path: Path) -> tuple[list[ElementDeclaration], bool, int] | None:
    """The elements, binary or not, and the offset of the data of the PLY file at ``path``;
    None when the header is not one this check understands (plyfile then says what is wrong)."""
    elements: list[ElementDeclaration] = []
    binary = False
    with path.open("rb") as stream:
        if stream.readline().rstrip(b"\r\n") != b"ply":
            return None
        for number, raw in enumerate(iter(stream.readline, b""), 2):
            words = raw.decode("latin-1").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "end_header":
                return elements, binary, stream.tell()
            if words[0] == "format" and len(words) == 3:
                binary = words[1] != "ascii"
            elif words[0] == "element" and len(words) == 3:
                try:
                    count = int(words[2])
                except ValueError:
                    return None
                if count < 0:
                    raise FormatError(f"element {words[1]!r} declares {count} rows", path, number)
                elements.append(ElementDeclaration(words[1], count, number))
            elif words[0] == "property" and elements:
                if not _property(elements[-1], words):
                    return None
            else:
                return None
    return None


def check_element_sizes(path: Path) -> None:
    """Raise :class:`FormatError` when the header declares more rows than the file can hold."""
    declared = declared_elements(path)
    if declared is None:
        return
    elements, binary, offset = declared
    size = path.stat().st_size
    available = size - offset
    needed = 0
    memory = 0
    for element in elements:
        row = element.smallest_row(binary)
        needed += element.count * row
        memory += element.count * element.row_memory()
        if needed > available:
            raise FormatError(
                f"element {element.name!r} declares {element.count} rows of at least {row} "
                f"bytes, but the file holds {available} bytes after its header"
                + (" (with the elements before it)" if needed > element.count * row else ""),
                path,
                element.line,
            )
        check_declared(memory, size, f"element {element.name!r}", path, element.line)
