"""geoh5 (Mira Geoscience ANALYST, format version 2) on h5py: ``.geoh5`` workspaces.

Written from the published geoh5 schema, not through geoh5py (which pins ``numpy<1.27``):
Points, Curve, Surface, BlockModel and Drillhole objects with their vertex and cell data, both
ways, float64 coordinates exactly. A drillhole is a ``Well``: its collar, surveys (float32 dip and
azimuth at depth) and stations, logs as depth data, markers as referenced depth data and zones
as referenced interval data (``_drillhole``). A block model reads as a ``RegularGrid`` (or, when
its cell sizes vary, as a point set of its cell centres standing for the grid,
``metadata["grid"]``) and writes back as the same block model.
``make geoh5-check`` cross-checks the files with geoh5py in an environment of its own. Needs
h5py (the ``geoh5`` extra).

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> back = geobrep.read(geobrep.write(scene, pathlib.Path(tempfile.mkdtemp()) / "cake.geoh5"))
>>> [s.name for s in back.surfaces][:2]
['H1', 'H2']
>>> back.surfaces[0].vertices.tobytes() == scene.surfaces[0].vertices.tobytes()
True
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geobrep.adapters._file_format import file_format
from geobrep.errors import FormatError, import_optional
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, NoOptions
from geobrep.model.entities import RegularGrid, Well
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "geobrep_register_formats"]

#: What a geoh5 workspace written by geobrep holds.
CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"PointSet", "PolyLine", "Surface", "RegularGrid", "Well"}),
    point_data=True,
    cell_data=True,
    names=True,
    multiple_entities=True,
)


def _read(path: Path) -> Scene:
    import_optional("h5py", "geoh5", f"reading geoh5 ({path.name})")
    from geobrep.adapters.geoh5._workspace import read_geoh5

    return read_geoh5(path)


def _write(scene: Scene, path: Path, options: NoOptions) -> None:
    import_optional("h5py", "geoh5", f"writing geoh5 ({path.name})")
    from geobrep.adapters.geoh5._workspace import write_geoh5

    if not scene.entities:
        raise FormatError("the scene has nothing geoh5 holds", path)
    write_geoh5(scene, path)


def _losses(scene: Scene, path: Path) -> list[str]:
    """Kinds, metadata, patch labels, vector properties, property details and what a
    drillhole does not hold of a well."""
    from geobrep.adapters.geoh5._well_losses import well_losses

    lost = []
    kinds = [e.label for e in scene.entities if e.kind]
    if kinds:
        lost.append(f"kinds of {len(kinds)} entities dropped")
    extra = [e.label for e in scene.entities if set(e.metadata) - {"grid"}]
    if extra:
        lost.append(f"metadata of {len(extra)} entities dropped")
    patched = [s.label for s in scene.surfaces if s.patch_labels is not None]
    if patched:
        lost.append(f"patch labels of {len(patched)} surfaces dropped")
    for grid in scene.of_type(RegularGrid):
        if grid.point_data:
            names = ", ".join(grid.point_data)
            lost.append(
                f"{grid.label}: point properties dropped: {names} (block models hold cell data)"
            )
    for well in scene.of_type(Well):
        lost.extend(well_losses(well))
    for entity in scene.entities:
        if isinstance(entity, Well):
            continue
        for field in ("point_data", "cell_data"):
            if entity.type == "RegularGrid" and field == "point_data":
                continue
            for name, prop in getattr(entity, field).items():
                where = f"{entity.label} {name!r}"
                values = prop.values
                if values.ndim != 1:
                    lost.append(f"{where}: vector property dropped (geoh5 data are scalars)")
                    continue
                if prop.unit or prop.no_data_value is not None or prop.metadata:
                    lost.append(f"{where}: unit, no-data value and metadata dropped")
                if values.dtype.kind in "biu" and values.dtype != np.int32:
                    lost.append(f"{where}: {values.dtype} stored as int32")
                elif values.dtype.kind == "f" and values.dtype != np.float64:
                    lost.append(f"{where}: {values.dtype} read back as float64")
    return lost


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``geoh5`` (``.geoh5``; by extension: HDF5 files look alike)."""
    registry.add(
        file_format(
            "geoh5",
            "geoh5 workspace (Geoscience ANALYST, on h5py): points, curves, surfaces, block "
            "models, drillholes",
            (".geoh5",),
            capabilities=CAPABILITIES,
            options=NoOptions,
            read=_read,
            write=_write,
            losses=_losses,
        )
    )
