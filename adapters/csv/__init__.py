"""Points as delimited text: x, y, z and property columns (``.csv``; ``.xyz``, ``.txt``, ``.dat``
and other names are recognised by their content).

Survey points often arrive as a table: one point per line, values separated by commas,
semicolons, tabs or spaces, an optional header line. Columns named ``x``, ``y``, ``z`` (any
case) are the coordinates, otherwise the first three columns; every other numeric column is a
point property, and columns ``name[0]``, ``name[1]``, ... form one vector property. Lines
starting with ``#`` are comments.

geobrep writes a PointSet with full float64 precision (shortest round-trip text) and, unless
``metadata=False``, one leading comment line with what a plain table cannot hold (entity name,
CRS, property units, no-data values and integer types), so geobrep reads back exactly what it
wrote while other programs see an ordinary CSV after one comment line.

>>> import numpy as np, geobrep, tempfile, pathlib
>>> points = geobrep.PointSet(vertices=[[450000.125, 6700000.5, -12.0]], point_data={"age": [3.5]})
>>> path = geobrep.write(points, pathlib.Path(tempfile.mkdtemp()) / "tops.csv")
>>> print(path.read_text().splitlines()[-2:])
['x,y,z,age', '450000.125,6700000.5,-12.0,3.5']
>>> back = geobrep.read(path).point_sets[0]
>>> back.vertices.tobytes() == points.vertices.tobytes(), back.point_data == points.point_data
(True, True)
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format
from geobrep.adapters.csv._table import read_points_table, write_points_table
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "CsvOptions", "geobrep_register_formats"]

CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"PointSet"}), point_data=True, names=True, crs=True
)


class CsvOptions(BaseModel):
    """Options of the ``csv`` writer."""

    model_config = ConfigDict(extra="forbid")

    delimiter: str = ","
    """Column separator: ``,`` (default), ``;``, a tab or a space."""
    metadata: bool = True
    """Write the leading ``# geobrep:`` comment line (name, CRS, units, no-data values, types)."""


def _sniff(head: bytes) -> bool:
    from geobrep.adapters.csv._table import looks_like_points_table

    return looks_like_points_table(head)


def _write(scene: Scene, path: Path, options: CsvOptions) -> None:
    write_points_table(scene, path, delimiter=options.delimiter, metadata=options.metadata)


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``csv`` (.csv, and tables of points under any name, found by content)."""
    registry.add(
        file_format(
            "csv",
            "points as delimited text: x, y, z columns, more columns as properties",
            (".csv",),
            capabilities=CAPABILITIES,
            options=CsvOptions,
            read=read_points_table,
            write=_write,
            sniff=_sniff,
            generic_content=True,  # plain numbers: a more specific format wins
        )
    )
