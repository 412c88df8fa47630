"""The XYZ point format: one ``x y z [value]`` line per point, ``#`` starts a comment.

Example file::

    # x y z value
    500000.0 7000000.0 -120.5 3.2
    500010.0 7000000.0 -121.0 3.4
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from geobrep.plugins import FileAccessError, FormatError

if TYPE_CHECKING:
    from geobrep import Scene

__all__ = ["XyzOptions", "looks_like_xyz", "read_xyz", "write_xyz"]

_SNIFF_BYTES = 4096  # what geobrep hands to ``sniff``
_SNIFF_SPLIT = re.compile(r"[\s,;]+")


class XyzOptions(BaseModel):
    """Options of the ``xyz`` format.

    ``delimiter``: column separator (``None``: any whitespace on read, one space on write).
    ``value_name``: the point-data property held by the optional fourth column.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    delimiter: str | None = Field(default=None, min_length=1)
    value_name: str = Field(default="value", min_length=1)


def looks_like_xyz(head: bytes) -> bool:
    """True if the first non-comment line of ``head`` holds 3 or 4 numbers.

    Example:
        >>> looks_like_xyz(b"# survey\\n1.0 2.0 3.0 0.5\\n"), looks_like_xyz(b"GOCAD TSurf 1\\n")
        (True, False)
    """
    if b"\x00" in head:
        return False
    lines = head.decode("utf-8", errors="replace").splitlines()
    if len(head) >= _SNIFF_BYTES and not head.endswith((b"\n", b"\r")):
        lines = lines[:-1]  # the last line may be cut short
    for line in lines:
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        tokens = _SNIFF_SPLIT.split(text)
        return 3 <= len(tokens) <= 4 and all(_is_number(token) for token in tokens)
    return False


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _split(line: str, delimiter: str | None) -> list[str]:
    if delimiter is None:
        return line.split()
    return [field.strip() for field in line.split(delimiter)]


def _parse(path: Path, options: XyzOptions) -> list[list[float]]:
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise FormatError(f"not UTF-8 text ({exc.reason})", path=path) from exc
    except OSError as exc:
        raise FileAccessError(exc.strerror or str(exc), path) from exc
    rows: list[list[float]] = []
    first_line = 0
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = _split(stripped, options.delimiter)
        if len(fields) not in (3, 4):
            raise FormatError(
                f"expected 3 or 4 columns (x y z [value]), found {len(fields)}", path, lineno
            )
        if rows and len(fields) != len(rows[0]):
            raise FormatError(
                f"expected {len(rows[0])} columns like line {first_line}, found {len(fields)}",
                path,
                lineno,
            )
        try:
            rows.append([float(field) for field in fields])
        except ValueError:
            bad = next(field for field in fields if not _is_number(field))
            raise FormatError(f"not a number: {bad!r}", path, lineno) from None
        first_line = first_line or lineno
    if not rows:
        raise FormatError("no points found (expected lines 'x y z [value]')", path)
    return rows


def read_xyz(path: Path, options: XyzOptions) -> Scene:
    """Read ``path`` into a scene holding one ``PointSet`` named after the file.

    A fourth column becomes the point-data property ``options.value_name``.
    """
    table = np.asarray(_parse(path, options), dtype=np.float64)

    from geobrep import PointSet, Scene  # on use, so plugin discovery stays cheap

    vertices = np.ascontiguousarray(table[:, :3])
    if table.shape[1] == 4:
        values = np.ascontiguousarray(table[:, 3])
        points = PointSet(
            vertices=vertices, name=path.stem, point_data={options.value_name: values}
        )
    else:
        points = PointSet(vertices=vertices, name=path.stem)
    return Scene(entities=[points])


def write_xyz(scene: Scene, path: Path, options: XyzOptions) -> None:
    """Write the scene's single ``PointSet`` to ``path`` atomically.

    Only the property ``options.value_name`` is written (as the fourth column); other
    point-data properties are not stored by this format.
    """
    from geobrep import PointSet
    from geobrep.plugins import atomic_write

    entities = tuple(scene.entities)
    point_sets = [entity for entity in entities if isinstance(entity, PointSet)]
    for entity in entities:
        if not isinstance(entity, PointSet):
            raise FormatError(
                f"xyz stores point sets only, not {type(entity).__name__} {entity.name!r}",
                path=path,
            )
    if len(point_sets) != 1:
        raise FormatError(f"xyz stores one point set; the scene has {len(entities)}", path=path)
    points = point_sets[0]
    columns = [np.asarray(points.vertices, dtype=np.float64)]
    header = "# x y z"
    prop = points.point_data.get(options.value_name)
    if prop is not None:
        values = np.asarray(prop, dtype=np.float64)
        if values.shape != (len(columns[0]),):
            raise FormatError(
                f"point-data {options.value_name!r} of {points.name!r} has shape "
                f"{values.shape}; xyz stores one value per point",
                path=path,
            )
        columns.append(values[:, np.newaxis])
        header += f" {options.value_name}"
    table = np.hstack(columns)
    delimiter = options.delimiter or " "
    with atomic_write(path) as tmp_path, open(tmp_path, "w", encoding="utf-8", newline="\n") as out:
        out.write(header + "\n")
        for row in table.tolist():  # Python floats: repr() round-trips exactly
            out.write(delimiter.join(repr(value) for value in row) + "\n")
