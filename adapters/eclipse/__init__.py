"""Eclipse GRDECL (.grdecl): corner-point grids (SPECGRID, COORD, ZCORN, ACTNUM, cell properties).

Registered through ``geobrep_register_formats`` like any third-party format; see
docs/grids-wells-rasters.md.
"""

from __future__ import annotations

from pathlib import Path

from geobrep.adapters._file_format import file_format
from geobrep.adapters.eclipse._grdecl import looks_like_grdecl, read_grdecl, write_grdecl
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, NoOptions
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "geobrep_register_formats"]

CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"StructuredGrid"}), cell_data=True, names=False
)


def _losses(scene: Scene, path: Path) -> list[str]:
    from geobrep.model.entities import StructuredGrid

    grids = [e for e in scene.entities if isinstance(e, StructuredGrid)]
    lost = [
        f"{g.label}: a curvilinear grid (GRDECL holds corner-point grids)"
        for g in grids
        if not g.is_corner_point
    ]
    corner = [g for g in grids if g.is_corner_point]
    lost += [f"{g.label}: only the first grid is written" for g in corner[1:]]
    return lost


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``grdecl`` format (.grdecl)."""
    registry.add(
        file_format(
            "grdecl",
            "Eclipse GRDECL corner-point grid (SPECGRID, COORD, ZCORN, ACTNUM, properties)",
            (".grdecl",),
            options=NoOptions,
            read=read_grdecl,
            write=write_grdecl,
            sniff=looks_like_grdecl,
            capabilities=CAPABILITIES,
            losses=_losses,
        )
    )
