"""The native ``.geobrep`` format: a lossless container for a whole scene.

Registered through ``geobrep_register_formats`` like any third-party format.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format
from geobrep.adapters.native._container import NativeDocument, load, looks_native, save
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry
from geobrep.model.scene import Scene

__all__ = ["NativeDocument", "NativeOptions", "geobrep_register_formats", "load", "save"]


class NativeOptions(BaseModel):
    """Options of the native format."""

    model_config = ConfigDict(extra="forbid")

    compress: bool = False
    """Deflate the arrays (smaller files, slower; the data stay bit-identical)."""


def _write(scene: Scene, path: Path, options: NativeOptions) -> None:
    save(scene, path, compress=options.compress)


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``native`` format (``.geobrep``)."""
    registry.add(
        file_format(
            "native",
            "geobrep's lossless scene container (zip of JSON + .npy arrays)",
            (".geobrep",),
            options=NativeOptions,
            read=load,
            write=_write,
            sniff=looks_native,
            capabilities=FormatCapabilities(
                entity_types=frozenset(
                    {
                        "PointSet",
                        "PolyLine",
                        "Polygon",
                        "Surface",
                        "TetMesh",
                        "NurbsSurface",
                        "Annotation",
                        "Block",
                        "LinearOctree",
                        "RegularGrid",
                        "StructuredGrid",
                        "Well",
                    }
                ),
                point_data=True,
                cell_data=True,
                names=True,
                ids=True,
                topology=True,
                crs=True,
                multiple_entities=True,
                empty_entities=True,
            ),
        )
    )
