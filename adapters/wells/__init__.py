"""Well deviation tables (.dev; .dat and .txt path tables with ``format="deviation"``) and LAS
2.0 / 3.0 well logs (.las, through lasio: the ``wells`` extra); :func:`attach_las` puts a LAS
file's logs on a well.

Registered through ``geobrep_register_formats`` like any third-party format; see
docs/grids-wells-rasters.md.
"""

from __future__ import annotations

from pathlib import Path

from geobrep.adapters._file_format import file_format
from geobrep.adapters.wells._deviation import read_deviation, write_deviation
from geobrep.adapters.wells._las import attach_las, las_losses, looks_like_las, read_las, write_las
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, NoOptions
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "attach_las", "geobrep_register_formats"]

CAPABILITIES = FormatCapabilities(entity_types=frozenset({"Well"}), point_data=True, names=True)


def _losses(scene: Scene, path: Path) -> list[str]:
    from geobrep.model.entities import Well

    lost: list[str] = []
    wells = [e for e in scene.entities if isinstance(e, Well)]
    for well in wells[:1]:
        for what, present in (
            ("markers", well.markers),
            ("zones", well.zones),
            ("logs", well.logs),
            ("datum", well.datum or well.datum_elevation is not None),
        ):
            if present:
                lost.append(f"{well.label}: its {what} (a deviation table holds stations)")
    lost += [f"{w.label}: only the first well is written" for w in wells[1:]]
    return lost


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``deviation`` (.dev) and ``las`` (.las) formats."""
    registry.add(
        file_format(
            "deviation",
            "well deviation table (Petrel .dev: MD X Y Z and survey columns; X Y Z path tables)",
            (".dev",),
            options=NoOptions,
            read=read_deviation,
            write=write_deviation,
            capabilities=CAPABILITIES,
            losses=_losses,
        )
    )
    registry.add(
        file_format(
            "las",
            "LAS 2.0 / 3.0 well logs (lasio): curves on measured depth",
            (".las",),
            options=NoOptions,
            read=read_las,
            write=write_las,
            sniff=looks_like_las,
            capabilities=FormatCapabilities(entity_types=frozenset({"Well"}), names=True),
            losses=las_losses,
        )
    )
