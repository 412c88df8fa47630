"""pyvista bridge (extra ``viz``): ``to_pyvista`` / ``from_pyvista``, ``.vtp`` files, pictures.

Registers the ``vtp`` format (VTK XML PolyData through pyvista: point sets, polylines and
surfaces with names, ids, patch labels, properties and CRS) and the write-only ``png`` format
(a rendered picture, see :class:`~geobrep.adapters.pyvista._render.RenderOptions`). pyvista is
imported only when one of them is used; without it they raise
:class:`~geobrep.errors.MissingDependencyError` naming the ``viz`` extra.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from geobrep.adapters._file_format import file_format, full_capabilities
from geobrep.adapters._vtk_xml import check_vtu_sizes, check_xml_counts
from geobrep.adapters.cell_layout import layout_to_scene, scene_to_layout
from geobrep.adapters.pyvista._convert import (
    dataset_to_layout,
    from_pyvista,
    import_pyvista,
    layout_to_dataset,
    scene_blocks_to_pyvista,
    to_pyvista,
)
from geobrep.adapters.pyvista._render import RenderOptions, render_scene
from geobrep.errors import FormatError
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec
from geobrep.model.scene import Scene

__all__ = [
    "PNG_CAPABILITIES",
    "VTP_CAPABILITIES",
    "RenderOptions",
    "VtpOptions",
    "from_pyvista",
    "geobrep_register_formats",
    "read_vtk_dataset",
    "render_scene",
    "scene_blocks_to_pyvista",
    "to_pyvista",
]

VTP_CAPABILITIES = full_capabilities({"PointSet", "PolyLine", "Surface"})
PNG_CAPABILITIES = FormatCapabilities(
    entity_types=frozenset({"PointSet", "PolyLine", "Surface", "TetMesh", "LinearOctree"}),
    multiple_entities=True,
)


class VtpOptions(BaseModel):
    """Options of the ``vtp`` writer."""

    model_config = ConfigDict(extra="forbid")

    binary: bool = True
    """Binary arrays (exact); False writes ASCII."""


def read_vtk_dataset(path: Path, extension: str | None = None) -> Scene:
    """Any file VTK reads (legacy POLYDATA included), as a scene.

    VTK reports a file it cannot parse as error messages and hands back what it got so far
    (often nothing): an error VTK reports while reading is a :class:`FormatError`, never an
    empty or partial scene.
    """
    pv = import_pyvista(f"reading {path.name}")
    from pyvista.core.utilities import VtkErrorCatcher

    catcher = VtkErrorCatcher(raise_errors=False, send_to_logging=False)
    try:
        with catcher:
            dataset = pv.read(path, force_ext=extension) if extension else pv.read(path)
    except Exception as exc:
        raise FormatError(
            f"VTK could not read this file: {type(exc).__name__}: {exc}", path
        ) from exc
    errors = [event for event in catcher.events if event.kind == "ERROR"]
    if errors:
        said = (errors[0].alert.strip().splitlines() or ["an error"])[0]
        raise FormatError(f"VTK could not read this file: {said}", path)
    if isinstance(dataset, pv.MultiBlock):
        result = from_pyvista(dataset)
        return result if isinstance(result, Scene) else Scene(entities=[result])
    return layout_to_scene(dataset_to_layout(dataset), path)


def _read_vtp(path: Path) -> Scene:
    check_xml_counts(path)  # VTK allocates what the counts say, and inflates every block
    check_vtu_sizes(path)
    return read_vtk_dataset(path, ".vtp")


def _write_vtp(scene: Scene, path: Path, options: VtpOptions) -> None:
    import_pyvista("writing .vtp files")
    layout = scene_to_layout(scene)
    dataset = layout_to_dataset(layout)
    if not hasattr(dataset, "verts"):
        raise FormatError("a .vtp file holds no tetrahedra", path)
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    writer = vtkXMLPolyDataWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(dataset)
    writer.SetCompressorTypeToZLib()  # VTK's default compressor setting is twice as slow
    if options.binary:
        writer.SetDataModeToBinary()
    else:
        writer.SetDataModeToAscii()
    if writer.Write() != 1:
        raise FormatError("VTK could not write the file", path)


def _write_png(scene: Scene, path: Path, options: RenderOptions) -> None:
    render_scene(scene, path, options)


def _sniff_vtp(head: bytes) -> bool:
    return b"<VTKFile" in head and b'type="PolyData"' in head


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``vtp`` and ``png``."""
    registry.add(
        file_format(
            "vtp",
            "VTK XML PolyData (pyvista, extra 'viz'): exact, whole scenes of meshes",
            (".vtp",),
            capabilities=VTP_CAPABILITIES,
            options=VtpOptions,
            read=_read_vtp,
            write=_write_vtp,
            sniff=_sniff_vtp,
        )
    )
    registry.add(
        FormatSpec(
            name="png",
            description="a rendered picture (pyvista, off-screen; extra 'viz'); write only",
            extensions=(".png",),
            writer=_write_png,
            options=RenderOptions,
            capabilities=PNG_CAPABILITIES,
        )
    )
