"""GOCAD ASCII formats: TSurf (.ts), PLine (.pl), VSet (.vs), TSolid (.so), Model3d (.ml), groups.

One format, ``gocad``, covers the family: the reader recognises each object by its
``GOCAD <Type>`` line (so a .ts holding a PLine still reads), the writer picks the object type
from the extension (see :mod:`geobrep.adapters.gocad._writer`). Registered through
``geobrep_register_formats`` like any third-party format.
"""

from __future__ import annotations

from pathlib import Path

from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec
from geobrep.model.scene import Scene

__all__ = ["EXTENSIONS", "geobrep_register_formats", "looks_like_gocad"]

#: File extensions of the GOCAD ASCII family.
EXTENSIONS = (".ts", ".pl", ".vs", ".so", ".ml", ".gp")


def looks_like_gocad(head: bytes) -> bool:
    """True when the first non-blank line is ``GOCAD <Type> ...``."""
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return text[:6].upper() == b"GOCAD " and len(text.split(None, 2)) >= 2


def _read(path: Path, options: object) -> Scene:
    from geobrep.adapters.gocad._reader import read_gocad
    from geobrep.adapters.gocad.options import GocadOptions

    assert isinstance(options, GocadOptions)
    return read_gocad(path, options)


def _write(scene: Scene, path: Path, options: object) -> None:
    from geobrep.adapters.gocad._writer import write_gocad
    from geobrep.adapters.gocad.options import GocadOptions

    assert isinstance(options, GocadOptions)
    write_gocad(scene, path, options)


#: The entity types each GOCAD object type holds (the writer picks it from the extension).
_HELD = {
    ".ts": ("TSurf", frozenset({"Surface"})),
    ".pl": ("PLine", frozenset({"PolyLine"})),
    ".vs": ("VSet", frozenset({"PointSet"})),
    ".so": ("TSolid", frozenset({"TetMesh"})),
    ".ml": ("Model3d", frozenset({"Surface", "Block"})),
    ".gp": ("group", frozenset({"Surface", "PolyLine", "PointSet", "TetMesh"})),
}


_FAMILY = frozenset({"Surface", "PolyLine", "PointSet", "TetMesh", "Block"})


def _losses(scene: Scene, path: Path) -> list[str]:
    """What the object type of ``path``'s extension cannot hold (the format holds the rest)."""
    from geobrep.adapters.gocad._objects import gocad_section

    object_type, held = _HELD.get(path.suffix.lower(), ("", frozenset()))
    if not held:
        return []
    dropped: dict[str, int] = {}
    for entity in scene.entities:
        if entity.type in held or entity.type not in _FAMILY:
            continue  # kept, or reported from the format's capabilities
        if object_type == "TSolid" and gocad_section(entity.metadata).get("type") == (
            "TSolid.SURFACE"
        ):
            continue
        dropped[entity.type] = dropped.get(entity.type, 0) + 1
    kinds = ", ".join(sorted(held))
    return [
        f"{count} {type_name} entities dropped (a GOCAD {object_type} file holds {kinds})"
        for type_name, count in sorted(dropped.items())
    ]


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``gocad`` format (.ts .pl .vs .so .ml .gp)."""
    from geobrep.adapters.gocad.options import GocadOptions

    registry.add(
        FormatSpec(
            name="gocad",
            description="GOCAD ASCII: TSurf, PLine, VSet, TSolid, Model3d and groups",
            extensions=EXTENSIONS,
            reader=_read,
            writer=_write,
            sniff=looks_like_gocad,
            options=GocadOptions,
            capabilities=FormatCapabilities(
                entity_types=frozenset({"Surface", "PolyLine", "PointSet", "TetMesh", "Block"}),
                point_data=True,
                cell_data=True,
                names=True,
                ids=False,
                topology=True,
                crs=True,
                multiple_entities=True,
                empty_entities=True,
            ),
            losses=_losses,
        )
    )
