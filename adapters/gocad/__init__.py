"""GOCAD formats: TSurf (.ts), PLine (.pl), VSet (.vs), TSolid (.so), Model3d (.ml), groups,
Voxet (.vo) and SGrid (.sg), with their side files, and Well (.wl); and SKUA horizon stacks
(.xml).

One format, ``gocad``, covers the GOCAD ASCII family: the reader recognises each object by its
``GOCAD <Type>`` line (so a .ts holding a PLine still reads), the writer picks the object type
from the extension (see :mod:`geobrep.adapters.gocad._writer`). The ``skua`` format reads and
writes the stratigraphic columns of SKUA's ``<UserObjects>`` XML as the scene's groups (.xml is
shared: its sniffer looks at the root element). Registered through
``geobrep_register_formats`` like any third-party format.
"""

from __future__ import annotations

from pathlib import Path

from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec, NoOptions
from geobrep.model.scene import Scene

__all__ = ["EXTENSIONS", "geobrep_register_formats", "looks_like_gocad"]

#: File extensions of the GOCAD ASCII family.
EXTENSIONS = (".ts", ".pl", ".vs", ".so", ".ml", ".gp", ".vo", ".sg", ".wl")


def looks_like_gocad(head: bytes) -> bool:
    """True when the first non-blank line is ``GOCAD <Type> ...``."""
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return text[:6].upper() == b"GOCAD " and len(text.split(None, 2)) >= 2


def _read(path: Path, options: object) -> Scene:
    from geobrep.adapters.gocad._grids import object_type_of, read_grid_object
    from geobrep.adapters.gocad._reader import read_gocad
    from geobrep.adapters.gocad.options import GocadOptions

    assert isinstance(options, GocadOptions)
    grid_type = object_type_of(path)
    if grid_type is not None:
        return read_grid_object(path, grid_type)
    return read_gocad(path, options)


def _write(scene: Scene, path: Path, options: object) -> None:
    from geobrep.adapters.gocad._grids import grid_object_for, write_grid_object
    from geobrep.adapters.gocad._writer import write_gocad
    from geobrep.adapters.gocad.options import GocadOptions

    assert isinstance(options, GocadOptions)
    grid_type = grid_object_for(path, options.object_type)
    if grid_type is not None:
        write_grid_object(scene, path, grid_type, options.voxet_ascii)
        return
    write_gocad(scene, path, options)


#: The entity types each GOCAD object type holds (the writer picks it from the extension).
_HELD = {
    ".ts": ("TSurf", frozenset({"Surface"})),
    ".pl": ("PLine", frozenset({"PolyLine"})),
    ".vs": ("VSet", frozenset({"PointSet"})),
    ".so": ("TSolid", frozenset({"TetMesh"})),
    ".ml": ("Model3d", frozenset({"Surface", "Block"})),
    ".gp": (
        "group",
        frozenset(
            {"Surface", "PolyLine", "PointSet", "TetMesh", "RegularGrid", "StructuredGrid", "Well"}
        ),
    ),
    ".vo": ("Voxet", frozenset({"RegularGrid"})),
    ".sg": ("SGrid", frozenset({"StructuredGrid"})),
    ".wl": ("Well", frozenset({"Well"})),
}


_FAMILY = frozenset(
    {"Surface", "PolyLine", "PointSet", "TetMesh", "Block", "RegularGrid", "StructuredGrid", "Well"}
)


def _read_stack(path: Path, options: object) -> Scene:
    from geobrep.adapters.gocad._horizons_stack import read_horizons_stack

    return read_horizons_stack(path)


def _write_stack(scene: Scene, path: Path, options: object) -> None:
    from geobrep.adapters.gocad._horizons_stack import write_horizons_stack
    from geobrep.host.capabilities import restrict_scene

    write_horizons_stack(restrict_scene(scene, _STACK_CAPABILITIES), path, options)


def _stack_losses(scene: Scene, path: Path) -> list[str]:
    from geobrep.adapters.gocad._horizons_stack import stack_losses

    return stack_losses(scene, path)


def _looks_like_stack(head: bytes) -> bool:
    from geobrep.adapters.gocad._horizons_stack import looks_like_horizons_stack

    return looks_like_horizons_stack(head)


#: A horizon stack holds groups only (names of horizons and units), no entities.
_STACK_CAPABILITIES = FormatCapabilities(entity_types=frozenset(), names=True)


def _entity_grid_losses(entity: object) -> list[str]:
    """What a Voxet, SGrid or Well object cannot hold of ``entity`` (its own type's object)."""
    from geobrep.model.entities import RegularGrid, StructuredGrid, Well

    lost: list[str] = []
    if isinstance(entity, RegularGrid):
        if entity.point_data and entity.cell_data:
            lost.append(f"{entity.label}: cell data (a Voxet holds node values)")
        elif entity.cell_data:
            lost.append(f"{entity.label}: cells (cell data are written at the cell centres)")
    elif isinstance(entity, StructuredGrid):
        if entity.points is None:
            lost.append(f"{entity.label}: a corner-point grid (an SGrid holds node points)")
        elif entity.actnum is not None and not entity.actnum.all():
            lost.append(f"{entity.label}: inactive cells (actnum)")
    elif isinstance(entity, Well):
        if any(m.surface for m in entity.markers):
            lost.append(f"{entity.label}: the surfaces its markers hit")
        if entity.point_data or entity.cell_data:
            names = ", ".join([*entity.point_data, *entity.cell_data])
            lost.append(f"{entity.label}: station and segment properties ({names})")
    return lost


def _grid_losses(scene: Scene, path: Path) -> list[str]:
    """What a Voxet, SGrid or Well file cannot hold of the one entity it keeps, and a group
    file of each grid and well it holds."""
    from geobrep.model.entities import RegularGrid, StructuredGrid, Well

    suffix = path.suffix.lower()
    wanted = {".vo": RegularGrid, ".sg": StructuredGrid, ".wl": Well}.get(suffix)
    if suffix == ".gp":
        return [s for e in scene.entities for s in _entity_grid_losses(e)]
    first = next((e for e in scene.entities if wanted and isinstance(e, wanted)), None)
    return _entity_grid_losses(first) if first is not None else []


def _losses(scene: Scene, path: Path) -> list[str]:
    """What the object type of ``path``'s extension cannot hold (the format holds the rest)."""
    from geobrep.adapters.gocad._objects import gocad_section

    object_type, held = _HELD.get(path.suffix.lower(), ("", frozenset()))
    if not held:
        return []
    grid_lost = (
        _grid_losses(scene, path) if object_type in ("Voxet", "SGrid", "Well", "group") else []
    )
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
    if object_type == "Model3d":
        from geobrep.adapters.gocad._writer import model3d_copies

        grid_lost = grid_lost + model3d_copies(scene)
    return grid_lost + [
        f"{count} {type_name} entities dropped (a GOCAD {object_type} file holds {kinds})"
        for type_name, count in sorted(dropped.items())
    ]


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``gocad`` format (.ts .pl .vs .so .ml .gp .vo .sg .wl) and ``skua`` (.xml)."""
    from geobrep.adapters.gocad.options import GocadOptions

    registry.add(
        FormatSpec(
            name="gocad",
            description="GOCAD: TSurf, PLine, VSet, TSolid, Model3d, groups, Voxet, SGrid and Well",
            extensions=EXTENSIONS,
            reader=_read,
            writer=_write,
            sniff=looks_like_gocad,
            options=GocadOptions,
            capabilities=FormatCapabilities(
                entity_types=_FAMILY,
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
    registry.add(
        FormatSpec(
            name="skua",
            description="SKUA horizon stack: the order of horizons and units as groups",
            extensions=(".xml",),
            reader=_read_stack,
            writer=_write_stack,
            sniff=_looks_like_stack,
            options=NoOptions,
            capabilities=_STACK_CAPABILITIES,
            losses=_stack_losses,
        )
    )
