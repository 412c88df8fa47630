"""Lossless PLY through ``plyfile``: binary or ASCII, float64 coordinates, every property.

Point sets, surfaces and polylines of a scene go into one file with their names, ids, patch
labels and properties (see :mod:`geobrep.adapters.ply._codec`); PLY files from other programs
read as one surface keeping every vertex and face property.

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> path = geobrep.write(scene, pathlib.Path(tempfile.mkdtemp()) / "cake.ply")
>>> geobrep.read(path).surfaces == scene.surfaces
True
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format, full_capabilities
from geobrep.adapters.ply._codec import read_ply, write_ply
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatRegistry
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "PlyOptions", "geobrep_register_formats", "read_ply", "write_ply"]

CAPABILITIES = full_capabilities({"PointSet", "PolyLine", "Surface"})


class PlyOptions(BaseModel):
    """Options of the ``ply`` writer."""

    model_config = ConfigDict(extra="forbid")

    binary: bool = True
    """Little-endian binary (compact, fast); False writes ASCII. Both are exact."""


def _write(scene: Scene, path: Path, options: PlyOptions) -> None:
    write_ply(scene, path, binary=options.binary)


def _sniff(head: bytes) -> bool:
    return head.startswith(b"ply\n") or head.startswith(b"ply\r\n")


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``ply``."""
    registry.add(
        file_format(
            "ply",
            "Stanford PLY (plyfile): exact, all vertex and face properties",
            (".ply",),
            capabilities=CAPABILITIES,
            options=PlyOptions,
            read=read_ply,
            write=_write,
            sniff=_sniff,
        )
    )
