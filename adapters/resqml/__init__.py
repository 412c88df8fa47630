"""RESQML 2.0.1 (Energistics) through resqpy: ``.epc`` packages with their ``.h5`` arrays.

Surfaces, point sets and polylines are written as triangulated, point-set and polyline-set
representations of horizon, fault and boundary interpretations in one local depth CRS (units,
EPSG code, z increasing downward when the source's z pointed down, an optional ``offset``);
properties as continuous (with their unit of measure) or discrete properties; blocks as geobody
features and interpretations naming their bounding patches. Coordinates and properties are
float64 and come back bit for bit. Needs the ``resqml`` extra (``pip install geobrep[resqml]``).

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> path = geobrep.write(scene, pathlib.Path(tempfile.mkdtemp()) / "cake.epc")
>>> sorted(p.name for p in path.parent.iterdir())
['cake.epc', 'cake.h5']
>>> geobrep.read(path).surfaces == scene.surfaces
True
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format
from geobrep.errors import FormatError, import_optional
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "ResqmlOptions", "geobrep_register_formats"]

#: What a RESQML model written by geobrep holds.
CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"PointSet", "PolyLine", "Surface", "Block"}),
    point_data=True,
    cell_data=True,
    names=True,
    ids=True,
    topology=True,
    crs=True,
    multiple_entities=True,
)


class ResqmlOptions(BaseModel):
    """Options of the ``resqml`` writer."""

    model_config = ConfigDict(extra="forbid")

    offset: tuple[float, float, float] | None = None
    """Origin of the local CRS: coordinates are stored relative to it (an origin that would
    change a coordinate in the last bit is refused, so the round trip stays exact)."""


def _read(path: Path) -> Scene:
    import_optional("resqpy", "resqml", f"reading RESQML ({path.name})")
    from geobrep.adapters.resqml._reader import read_resqml

    return read_resqml(path)


def _write(scene: Scene, path: Path, options: ResqmlOptions) -> None:
    import_optional("resqpy", "resqml", f"writing RESQML ({path.name})")
    from geobrep.adapters.resqml._writer import write_resqml

    if not scene.entities:
        raise FormatError("the scene has nothing RESQML holds", path)
    write_resqml(scene, path, options.offset)


def _losses(scene: Scene, path: Path) -> list[str]:
    """Vertices shared between polyline parts are written once per part (RESQML polylines
    own their nodes); quads are refused (a FormatError, not a loss)."""
    lost = []
    for line in scene.polylines:
        if len(line.indices) != line.n_points or (line.indices != np.arange(line.n_points)).any():
            lost.append(f"{line.label}: vertices shared between parts are written once per part")
    return lost


def _sniff(head: bytes) -> bool:
    from geobrep.adapters.resqml._package import sniff_epc

    return sniff_epc(head)


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``resqml`` (``.epc``)."""
    registry.add(
        file_format(
            "resqml",
            "RESQML 2.0.1 model through resqpy (.epc + .h5): surfaces, points, lines, blocks",
            (".epc",),
            capabilities=CAPABILITIES,
            options=ResqmlOptions,
            read=_read,
            write=_write,
            sniff=_sniff,
            losses=_losses,
        )
    )
