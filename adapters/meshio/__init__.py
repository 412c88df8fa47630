"""Mesh formats through meshio: VTU, legacy VTK, OBJ, STL, OFF and Gmsh.

VTU and legacy VTK keep a whole scene (points, lines, surfaces, tetrahedral meshes with names,
ids, patch labels, properties, CRS and groups); the others keep what they can, and
:func:`geobrep.host.capabilities.capability_losses` says what they cannot. Legacy VTK POLYDATA files
(what ParaView writes for surfaces), which meshio cannot read, are read through pyvista when the
``viz`` extra is installed. geobrep reads one-piece VTU files itself
(:mod:`~geobrep.adapters.meshio._vtu_reader`: meshio's arrays, without importing meshio).

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> path = geobrep.write(scene, pathlib.Path(tempfile.mkdtemp()) / "cake.vtu")
>>> [s.name for s in geobrep.read(path).surfaces][:2]
['H1', 'H2']
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format, full_capabilities
from geobrep.adapters._vtk_xml import check_vtu_sizes, check_xml_counts
from geobrep.adapters.cell_layout import (
    ENTITY_ARRAY,
    HEADER_ARRAY,
    LAYOUT_TYPES,
    header_applies,
    layout_to_scene,
    scene_to_layout,
)
from geobrep.adapters.meshio._bridge import (
    layout_from_mesh,
    mesh_from_layout,
    read_mesh,
    write_mesh,
)
from geobrep.adapters.meshio._header import (
    embed_legacy_header,
    embed_vtu_header,
    read_legacy_header,
    vtk_field_problem,
)
from geobrep.adapters.meshio._vtu_reader import read_vtu_mesh
from geobrep.errors import FormatError, MissingDependencyError
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, NoOptions
from geobrep.model.scene import Scene

__all__ = [
    "CAPABILITIES",
    "LegacyVtkOptions",
    "StlOptions",
    "VtuOptions",
    "geobrep_register_formats",
]

_FULL = full_capabilities(LAYOUT_TYPES)
_SURFACE_ONLY = FormatCapabilities(entity_types=frozenset({"Surface"}))

#: What each meshio-backed format holds, by format name.
CAPABILITIES: dict[str, FormatCapabilities] = {
    "vtu": _FULL,
    "vtk": _FULL,
    "gmsh": FormatCapabilities(
        entity_types=LAYOUT_TYPES, point_data=True, ids=True, multiple_entities=True
    ),
    "obj": _SURFACE_ONLY,
    "stl": _SURFACE_ONLY,
    "off": _SURFACE_ONLY,
}


class VtuOptions(BaseModel):
    """Options of the ``vtu`` writer."""

    model_config = ConfigDict(extra="forbid", defer_build=True)

    compression: Literal["zlib", "lzma"] | None = None
    """Compress the binary arrays (smaller files, slower)."""


class LegacyVtkOptions(BaseModel):
    """Options of the legacy ``vtk`` writer."""

    model_config = ConfigDict(extra="forbid", defer_build=True)

    binary: bool = True
    """Big-endian binary arrays; False writes ASCII."""


class StlOptions(BaseModel):
    """Options of the ``stl`` writer."""

    model_config = ConfigDict(extra="forbid", defer_build=True)

    binary: bool = False
    """Binary STL stores coordinates as float32 (UTM coordinates lose centimetres); the
    default ASCII STL keeps them exactly."""


def _read_vtu(path: Path) -> Scene:
    check_xml_counts(path)
    check_vtu_sizes(path)
    mesh = read_vtu_mesh(path)  # what meshio reads, without importing it (~50 ms)
    if mesh is None:  # a file geobrep's reader leaves to meshio (which may refuse it)
        mesh = read_mesh(path, "vtu")
    return layout_to_scene(layout_from_mesh(mesh, path), path)


def _write_vtu(scene: Scene, path: Path, options: VtuOptions) -> None:
    from geobrep.adapters.meshio._vtu_writer import write_vtu

    layout = scene_to_layout(scene)
    if len(layout.points) == 0:
        write_mesh(mesh_from_layout(layout, field_data=False), path, "vtu")  # refuses it
    # meshio's file, its arrays streamed in chunks (meshio's writer holds ~5x each array)
    write_vtu(layout, path, options.compression)
    if layout.header is not None:
        embed_vtu_header(path, layout.header)


def _read_legacy(path: Path) -> Scene:
    with path.open("rb") as stream:
        head = stream.read(1024)
    if b"POLYDATA" in head or b"STRUCTURED_GRID" in head.replace(b"UNSTRUCTURED_GRID", b""):
        return _read_through_pyvista(path)
    try:
        mesh = read_mesh(path, "vtk")
    except FormatError:
        # VTK reads more of its own format than meshio does, but its legacy reader can crash
        # the process on a damaged file: a file meshio wrote (geobrep's) is meshio's to read.
        if _pyvista_available() and not _written_by_meshio(head):
            return _read_through_pyvista(path)
        raise
    layout = layout_from_mesh(mesh, path)
    header = read_legacy_header(path)
    if header_applies(header, layout.cell_data):
        layout.header = header
    return layout_to_scene(layout, path)


def _written_by_meshio(head: bytes) -> bool:
    """Whether a legacy file's head says meshio (so geobrep, too) wrote it."""
    return b"written by meshio" in head[:256] or f"\n{HEADER_ARRAY} ".encode() in head


def _pyvista_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("pyvista") is not None


def _read_through_pyvista(path: Path) -> Scene:
    """Legacy POLYDATA and structured grids: meshio cannot read them, VTK can (unless they
    hold what crashes VTK's reader: then a FormatError)."""
    problem = vtk_field_problem(path)
    if problem is not None:  # VTK would crash on it: geobrep says what is wrong instead
        raise FormatError(f"{problem} (VTK's legacy reader cannot read it safely)", path)
    try:
        from geobrep.adapters.pyvista import read_vtk_dataset
    except ImportError as exc:  # pragma: no cover - same distribution
        raise FormatError("legacy POLYDATA needs the pyvista adapter", path) from exc
    try:
        import pyvista  # noqa: F401
    except ImportError as exc:
        raise MissingDependencyError(
            "pyvista", "viz", f"reading legacy VTK POLYDATA ({path.name})"
        ) from exc
    return read_vtk_dataset(path, ".vtk")


def _write_legacy(scene: Scene, path: Path, options: LegacyVtkOptions) -> None:
    layout = scene_to_layout(scene)
    layout.point_data = _legacy_types(layout.point_data)
    layout.cell_data = _legacy_types(layout.cell_data)
    mesh = mesh_from_layout(layout, field_data=False)
    write_mesh(mesh, path, "vtk", binary=options.binary)
    if layout.header is not None:
        embed_legacy_header(path, layout.header, options.binary)


def _legacy_types(arrays: dict[str, NDArray[Any]]) -> dict[str, NDArray[Any]]:
    """Arrays in types that VTK's legacy reader and meshio's both know as meshio names them:
    integers narrower than 64 bits (``vtktypeint32``, ``vtktypeuint8``: unknown to VTK) as
    int64, half floats as float32. Lossless; the header's property records keep the dtype."""
    widened: dict[str, NDArray[Any]] = {}
    for name, values in arrays.items():
        array = np.asarray(values)
        if array.dtype.kind == "b" or (array.dtype.kind in "iu" and array.dtype.itemsize < 8):
            array = array.astype(np.int64)
        elif array.dtype.kind == "f" and array.dtype.itemsize < 4:
            array = array.astype(np.float32)
        widened[name] = array
    return widened


def check_off_counts(path: Path) -> None:
    """Refuse an OFF file with no counts line after ``OFF``: meshio would look for it forever."""
    with path.open("rb") as stream:
        stream.readline()
        for line in stream:
            text = line.strip()
            if text and not text.startswith(b"#"):
                return
    raise FormatError("an OFF file needs a line of vertex, face and edge counts after OFF", path)


def _reader(file_format: str) -> Callable[[Path], Scene]:
    def read(path: Path) -> Scene:
        if file_format == "off":
            check_off_counts(path)
        return layout_to_scene(layout_from_mesh(read_mesh(path, file_format), path), path)

    return read


def _surface_writer(file_format: str) -> Callable[[Scene, Path, BaseModel], None]:
    def write(kept: Scene, path: Path, options: BaseModel) -> None:
        if not kept.surfaces:
            raise FormatError(f"{file_format.upper()} holds surfaces and the scene has none", path)
        shapes = {s.faces.shape[1] for s in kept.surfaces}
        if file_format in ("stl",) and shapes != {3}:
            raise FormatError("STL holds triangles only; triangulate the quad surfaces", path)
        layout = scene_to_layout(kept)
        layout.point_data, layout.cell_data, layout.header = {}, {}, None
        extra = {"binary": options.binary} if isinstance(options, StlOptions) else {}
        write_mesh(mesh_from_layout(layout, field_data=False), path, file_format, **extra)

    return write


#: Components per value a Gmsh data field may have.
_GMSH_COMPONENTS = (1, 3, 9)


def _components(values: object) -> int:
    shape = getattr(values, "shape", ())
    return int(np.prod(shape[1:])) if len(shape) > 1 else 1


def _gmsh_losses(scene: Scene, path: Path) -> list[str]:
    """Gmsh keeps no header: property names lose their whitespace; odd sizes are dropped."""
    lost = []
    props = {n: p for e in scene.entities for n, p in e.point_data.items()}
    renamed = sorted(n for n in props if "_".join(n.split()) != n)
    if renamed:
        lost.append(
            "property names with whitespace read back with '_': "
            + ", ".join(f"{n!r} as {'_'.join(n.split())!r}" for n in renamed)
        )
    odd = sorted(n for n, p in props.items() if _components(p.values) not in _GMSH_COMPONENTS)
    if odd:
        lost.append(f"point properties dropped (Gmsh holds 1, 3 or 9 components): {', '.join(odd)}")
    return lost


def _gmsh_write(scene: Scene, path: Path, options: BaseModel) -> None:
    layout = scene_to_layout(scene)
    layout.point_data = {
        name: values
        for name, values in layout.point_data.items()
        if _components(values) in _GMSH_COMPONENTS
    }
    mesh = mesh_from_layout(layout, field_data=False)
    assert layout.header is not None
    ids = [int(record["id"]) for record in layout.header["entities"]]  # one block per entity
    entity = [
        np.full(len(conn), ident, np.int32)
        for ident, (_, conn) in zip(ids, layout.blocks, strict=True)
    ]
    # meshio reads Gmsh element data back misaligned with several cell blocks: keep tags only
    mesh.cell_data = {"gmsh:physical": entity, "gmsh:geometrical": entity}
    write_mesh(mesh, path, "gmsh22", binary=True)


#: The most string or real tags a Gmsh data section may declare (real files have one or two).
GMSH_MAX_TAGS = 1024
_GMSH_DATA = frozenset({b"$NodeData", b"$ElementData", b"$ElementNodeData"})


def _gmsh_int(lines: list[bytes], at: int) -> int | None:
    try:
        return int(lines[at])
    except (IndexError, ValueError):
        return None  # meshio says what is wrong


def _gmsh_data_counts(lines: list[bytes], number: int, size: int, path: Path) -> None:
    """The tags of the data section starting at line ``number``: at most :data:`GMSH_MAX_TAGS`
    string and real tags (meshio reads that many lines, past the end of the file), and no more
    values than the file's bytes can hold (meshio allocates what the integer tags say)."""
    section = lines[number].strip().decode()
    at = number + 1
    for kind in ("string", "real"):
        count = _gmsh_int(lines, at)
        if count is None:
            return
        if not 0 <= count <= GMSH_MAX_TAGS:
            raise FormatError(f"{section} declares {count} {kind} tags", path, at + 1)
        at += 1 + count
    count = _gmsh_int(lines, at)
    if count is None or not 3 <= count <= GMSH_MAX_TAGS:
        return
    tags = [_gmsh_int(lines, at + 1 + k) for k in range(3)]
    components, items = tags[1], tags[2]
    if components is None or items is None:
        return
    if components < 0 or items < 0 or items * (1 + components) * 2 > size:
        raise FormatError(
            f"{section} declares {items} values of {components} components, more than the "
            f"{size}-byte file holds",
            path,
            at + 4,
        )


def check_gmsh_counts(path: Path) -> None:
    """Refuse counts in a Gmsh file that the file's bytes cannot hold, before meshio allocates
    or loops over them: the nodes of ``$Nodes`` (format 2) and the values and tags of data
    sections (4294967296 tags hung meshio; a 658-byte file declaring 4e8 values took 3.7 GB)."""
    with path.open("rb") as stream:
        lines = stream.read().split(b"\n")
    size = path.stat().st_size
    for number, line in enumerate(lines):
        word = line.strip()
        if word in _GMSH_DATA:
            _gmsh_data_counts(lines, number, size, path)
        elif word == b"$Nodes":
            count = _gmsh_int(lines, number + 1)  # format 2: one count (format 4: four numbers)
            if count is not None and (count < 0 or count * 8 > size):
                message = f"$Nodes declares {count} nodes, more than the {size}-byte file holds"
                raise FormatError(message, path, number + 2)


def _read_gmsh(path: Path) -> Scene:
    check_gmsh_counts(path)
    mesh = read_mesh(path, "gmsh")
    physical = mesh.cell_data.pop("gmsh:physical", None)
    mesh.cell_data.pop("gmsh:geometrical", None)
    mesh.point_data.pop("gmsh:dim_tags", None)
    if physical is not None:
        mesh.cell_data[ENTITY_ARRAY] = physical
    return layout_to_scene(layout_from_mesh(mesh, path), path)


def _sniff_legacy(head: bytes) -> bool:
    return head.lstrip().startswith(b"# vtk DataFile")


def _sniff_vtu(head: bytes) -> bool:
    return b"<VTKFile" in head and b'type="UnstructuredGrid"' in head


def _sniff_gmsh(head: bytes) -> bool:
    return head.lstrip().startswith(b"$MeshFormat")


def _sniff_off(head: bytes) -> bool:
    return head.lstrip().startswith(b"OFF")


def _sniff_stl(head: bytes) -> bool:
    return head.lstrip().startswith(b"solid") and b"facet" in head


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``vtu``, ``vtk``, ``gmsh``, ``obj``, ``stl`` and ``off``."""
    registry.add(
        file_format(
            "vtu",
            "VTK XML unstructured grid (meshio): whole scenes, exact",
            (".vtu",),
            capabilities=CAPABILITIES["vtu"],
            options=VtuOptions,
            read=_read_vtu,
            write=_write_vtu,
            sniff=_sniff_vtu,
        )
    )
    registry.add(
        file_format(
            "vtk",
            "legacy VTK (meshio; POLYDATA through pyvista): whole scenes, exact",
            (".vtk",),
            capabilities=CAPABILITIES["vtk"],
            options=LegacyVtkOptions,
            read=_read_legacy,
            write=_write_legacy,
            sniff=_sniff_legacy,
        )
    )
    registry.add(
        file_format(
            "gmsh",
            "Gmsh 2.2 binary mesh (meshio): entity ids as physical tags",
            (".msh",),
            capabilities=CAPABILITIES["gmsh"],
            options=NoOptions,
            read=_read_gmsh,
            write=_gmsh_write,
            sniff=_sniff_gmsh,
            losses=_gmsh_losses,
        )
    )
    for name, description, sniff, options in (
        ("obj", "Wavefront OBJ (meshio): one surface", None, NoOptions),
        ("stl", "STL (meshio): one triangulated surface", _sniff_stl, StlOptions),
        ("off", "Geomview OFF (meshio): one surface", _sniff_off, NoOptions),
    ):
        registry.add(
            file_format(
                name,
                description,
                (f".{name}",),
                capabilities=CAPABILITIES[name],
                options=options,
                read=_reader(name),
                write=_surface_writer(name),
                sniff=sniff,
            )
        )
