"""OMF v1 (the Open Mining Format) through the ``omf`` 1.0 package: ``.omf`` projects.

Surfaces, line sets, point sets and volumes with their data arrays (scalars, 2- and 3-vectors
on vertices, faces, segments or cells) and colours, both ways; float64 coordinates exactly.
A volume reads as a ``RegularGrid`` (or, when its cell sizes vary, as a point set of its cell
centres standing for the grid, ``metadata["grid"]``) and writes back as the same volume.
Needs the ``omf`` extra (``pip install geobrep[omf]``).

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> back = geobrep.read(geobrep.write(scene, pathlib.Path(tempfile.mkdtemp()) / "cake.omf"))
>>> [s.name for s in back.surfaces][:2]
['H1', 'H2']
>>> back.surfaces[0].vertices.tobytes() == scene.surfaces[0].vertices.tobytes()
True
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from geobrep.adapters._file_format import file_format
from geobrep.errors import FormatError, import_optional
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, NoOptions
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "geobrep_register_formats"]

#: What an OMF v1 project holds.
CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"PointSet", "PolyLine", "Surface", "RegularGrid"}),
    point_data=True,
    cell_data=True,
    names=True,
    multiple_entities=True,
)

#: Entity metadata OMF keeps (as the element's colour and description).
_KEPT_METADATA = frozenset({"color", "description", "grid"})


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Without the NumPy 2 deprecation notes of omf 1.0's vectormath (one per array)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "__array_wrap__", DeprecationWarning)
        yield


def _read(path: Path) -> Scene:
    import_optional("omf", "omf", f"reading OMF ({path.name})")
    from geobrep.adapters.omf._project import read_omf

    with _quiet():
        return read_omf(path)


def _write(scene: Scene, path: Path, options: NoOptions) -> None:
    import_optional("omf", "omf", f"writing OMF ({path.name})")
    from geobrep.adapters.omf._project import write_omf

    if not scene.entities:
        raise FormatError("the scene has nothing OMF holds", path)
    with _quiet():
        write_omf(scene, path)


def _property_losses(scene: Scene) -> list[str]:
    lost = []
    for entity in scene.entities:
        for field in ("point_data", "cell_data"):
            for name, prop in getattr(entity, field).items():
                width = prop.values.shape[1] if prop.values.ndim == 2 else 1
                where = f"{entity.label} {name!r}"
                if prop.values.ndim > 2 or width > 3:
                    lost.append(f"{where}: {width}-component property dropped (OMF: 1 to 3)")
                elif prop.unit or prop.no_data_value is not None or prop.metadata:
                    lost.append(f"{where}: unit, no-data value and metadata dropped")
                if prop.values.dtype.kind in "iub" and prop.values.dtype != np.int64:
                    lost.append(f"{where}: {prop.values.dtype} read back as int64")
    return lost


def _losses(scene: Scene, path: Path) -> list[str]:
    """Kinds, other metadata, patch labels, colours beyond 8 bits and property details."""
    lost = []
    kinds = [e.label for e in scene.entities if e.kind]
    if kinds:
        lost.append(f"kinds of {len(kinds)} entities dropped")
    extra = [e.label for e in scene.entities if set(e.metadata) - _KEPT_METADATA]
    if extra:
        lost.append(f"metadata of {len(extra)} entities dropped (OMF keeps colour, description)")
    patched = [s.label for s in scene.surfaces if s.patch_labels is not None]
    if patched:
        lost.append(f"patch labels of {len(patched)} surfaces dropped")
    coloured = [e.label for e in scene.entities if "color" in e.metadata]
    if coloured:
        lost.append(f"colours of {len(coloured)} entities rounded to 8 bits per channel")
    return lost + _property_losses(scene)


def _sniff(head: bytes) -> bool:
    return head.startswith(b"\x84\x83\x82\x81OMF-v0.9")


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``omf`` (``.omf``)."""
    registry.add(
        file_format(
            "omf",
            "Open Mining Format v1 (omf 1.0): surfaces, line sets, point sets, volumes",
            (".omf",),
            capabilities=CAPABILITIES,
            options=NoOptions,
            read=_read,
            write=_write,
            sniff=_sniff,
            losses=_losses,
        )
    )
