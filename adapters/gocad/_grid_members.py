"""Voxet, SGrid and Well objects as members of a GOCAD group (.gp), read and written.

A group file holds its members' headers inline (``GOCAD Voxet 1 ... END`` between
``BEGIN_MEMBERS`` and ``END_MEMBERS``); their property, point and flag files are found beside
the group file, as a .vo file's are beside it, and a side file outside its folder is refused.
The writer names each member's side files ``<group stem>_<member>__...@@``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from geobrep.adapters.gocad._records import CrsBlock
from geobrep.adapters.gocad._sgrid import read_sgrid
from geobrep.adapters.gocad._sgrid_writer import sgrid_files
from geobrep.adapters.gocad._voxet import read_voxet
from geobrep.adapters.gocad._voxet_writer import SAFE_NAME, final_name, voxet_text
from geobrep.adapters.gocad._well import read_well, well_text
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity, RegularGrid, StructuredGrid, Well
from geobrep.ops.io import atomic_write

__all__ = ["MemberFiles", "read_member"]


def read_member(
    path: Path, text: str, kind: str, inherited: CrsBlock | None
) -> tuple[Entity, CrsBlock | None]:
    """The entity of a ``kind`` member of the group file ``path`` whose text is ``text``, and
    its own CRS block (None: it takes the group's, ``inherited``)."""
    if kind == "Voxet":
        grid, keyed = read_voxet(path, text, inherited)
        return grid, keyed.crs
    if kind == "SGrid":
        sgrid, keyed = read_sgrid(path, text, inherited)
        return sgrid, keyed.crs
    well, crs = read_well(path, text, inherited)
    return well, crs


class MemberFiles:
    """Writes the grid and well members of one group file: their text, and their side files
    beside the group file's final name, each under a stem no other member has."""

    def __init__(self, path: Path) -> None:
        self.final = final_name(path)
        self.stems: set[str] = set()

    def _stem(self, entity: Entity) -> str:
        base = f"{self.final.stem}_{SAFE_NAME.sub('_', entity.name or entity.type.lower())}"
        stem, number = base, 1
        while stem in self.stems:
            number += 1
            stem = f"{base}_{number}"
        self.stems.add(stem)
        return stem

    def text(self, entity: Entity, crs: CRS | None) -> bytes | None:
        """The member's object text (its side files written first), or None for another type."""
        if isinstance(entity, Well):
            return well_text(entity, crs).encode("utf-8")
        arrays: dict[str, Any]
        if isinstance(entity, RegularGrid):
            stem = self._stem(entity)
            props = entity.point_data or entity.cell_data
            files = {name: f"{stem}__{SAFE_NAME.sub('_', name)}@@" for name in props}
            if len(set(files.values())) != len(files):
                files = {name: f"{stem}__{i}@@" for i, name in enumerate(props, start=1)}
            header, by_name = voxet_text(entity, crs, files)
            arrays = {files[name]: values for name, values in by_name.items()}
        elif isinstance(entity, StructuredGrid):
            header, arrays = sgrid_files(entity, crs, self._stem(entity))
        else:
            return None
        for name, values in arrays.items():
            with atomic_write(self.final.with_name(name)) as temporary:
                values.tofile(temporary)
        return header.encode("utf-8")
