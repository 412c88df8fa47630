"""The GOCAD objects read line by line: Voxet (.vo), SGrid (.sg) and Well (.wl), to and from
scenes.

Only :func:`object_type_of` is needed to read any GOCAD file: each object's reader and writer
is imported when a file of its type is read or written (a .ts read loads none of them).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from geobrep.adapters.gocad._lexer import split_tokens
from geobrep.errors import FormatError
from geobrep.model.scene import Scene

if TYPE_CHECKING:
    from geobrep.model.entities import RegularGrid, StructuredGrid

__all__ = ["GRID_OBJECTS", "object_type_of", "read_grid_object", "write_grid_object"]

#: Object type → the extension it is written with and the name of the entity type it holds
#: (a class of :mod:`geobrep.model.entities`, imported when such an object is written).
GRID_OBJECTS: dict[str, tuple[str, str]] = {
    "Voxet": (".vo", "RegularGrid"),
    "SGrid": (".sg", "StructuredGrid"),
    "Well": (".wl", "Well"),
}
_BY_SUFFIX = {suffix: name for name, (suffix, _) in GRID_OBJECTS.items()}


def object_type_of(path: Path) -> str | None:
    """The object type of a file's ``GOCAD <Type>`` line when it is one of :data:`GRID_OBJECTS`."""
    with path.open("rb") as handle:
        head = handle.read(4096).decode("latin-1")
    for text in head.splitlines():
        tokens = split_tokens(text)
        if tokens:
            kind = tokens[1] if len(tokens) > 1 and tokens[0].upper() == "GOCAD" else ""
            if kind == "SGrid" and path.suffix.lower() != ".sg":
                return None  # an SGrid header before other objects (sgrid_tsurf.ts)
            return kind if kind in GRID_OBJECTS else None
    return None


def read_grid_object(path: Path, object_type: str) -> Scene:
    """A scene holding the object of a Voxet, SGrid or Well file."""
    from geobrep.adapters.gocad._reader import crs_from_block

    grid: RegularGrid | StructuredGrid
    if object_type == "Voxet":
        from geobrep.adapters.gocad._voxet import read_voxet

        grid, keyed = read_voxet(path)
    elif object_type == "SGrid":
        from geobrep.adapters.gocad._sgrid import read_sgrid

        grid, keyed = read_sgrid(path)
    else:
        from geobrep.adapters.gocad._well import read_well

        well, block = read_well(path)
        crs = crs_from_block(block) if block is not None else None
        return Scene(entities=[well.replace(id=0)], crs=crs, name=path.stem)
    crs = crs_from_block(keyed.crs) if keyed.crs is not None else None
    return Scene(entities=[grid.replace(id=0)], crs=crs, name=path.stem)


def grid_object_for(path: Path, object_type: str | None) -> str | None:
    """The grid object type a write to ``path`` asks for (option first, then extension)."""
    if object_type in GRID_OBJECTS:
        return object_type
    return None if object_type else _BY_SUFFIX.get(path.suffix.lower())


def write_grid_object(scene: Scene, path: Path, object_type: str, ascii_data: bool = False) -> None:
    """Write the scene's one entity of the object type's entity class."""
    from geobrep.adapters.gocad._objects import report
    from geobrep.model import entities
    from geobrep.model.entities import RegularGrid, StructuredGrid, Well

    _, name = GRID_OBJECTS[object_type]
    wanted = getattr(entities, name)
    chosen = [e for e in scene.entities if isinstance(e, wanted)]
    if not chosen:
        raise FormatError(f"the scene has no {wanted.__name__} to write as {object_type}", path)
    others = [e.label for e in scene.entities if e is not chosen[0]]
    if others:
        shown = ", ".join(others[:10])
        report(f"a {object_type} file holds one {wanted.__name__}; not written: {shown}")
    entity = chosen[0]
    if isinstance(entity, RegularGrid):
        from geobrep.adapters.gocad._voxet_writer import write_voxet

        write_voxet(entity, scene.crs, path, ascii_data)
    elif isinstance(entity, StructuredGrid):
        from geobrep.adapters.gocad._sgrid_writer import write_sgrid

        write_sgrid(entity, scene.crs, path)
    else:
        from geobrep.adapters.gocad._well import well_text

        assert isinstance(entity, Well)
        path.write_text(well_text(entity, scene.crs), encoding="utf-8")
