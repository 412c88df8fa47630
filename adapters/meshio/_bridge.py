"""Scenes to and from ``meshio.Mesh``, with meshio's failure modes contained.

meshio may call ``sys.exit``, print to stderr, or raise anything from ``KeyError`` to
``struct.error`` on a bad file; :func:`read_mesh` and :func:`write_mesh` turn every such failure
into a :class:`~geobrep.errors.FormatError` naming the file, and keep its chatter out of the
caller's stderr (it is added to the error message instead).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.casting import cast_exactly
from geobrep.adapters.cell_layout import (
    HEADER_ARRAY,
    CellLayout,
    decode_header,
    encode_header,
    header_applies,
    layout_to_scene,
    scene_to_layout,
)
from geobrep.errors import FormatError
from geobrep.model.scene import Scene

__all__ = ["layout_from_mesh", "mesh_from_layout", "read_mesh", "write_mesh"]

_KNOWN_CELLS = frozenset({"vertex", "line", "triangle", "quad", "tetra"})


def mesh_from_layout(layout: CellLayout, *, field_data: bool = True) -> Any:
    """A ``meshio.Mesh`` holding ``layout`` (header as uint8 field data when ``field_data``)."""
    import meshio

    slices = layout.block_slices()
    cells = [meshio.CellBlock(kind, conn) for kind, conn in layout.blocks]
    cell_data = {
        name: [np.asarray(values[cells_of]) for cells_of in slices]
        for name, values in layout.cell_data.items()
    }
    fields: dict[str, Any] = {}
    if field_data and layout.header is not None:
        fields[HEADER_ARRAY] = encode_header(layout.header)
    return meshio.Mesh(
        layout.points,
        cells,
        point_data=dict(layout.point_data),
        cell_data=cell_data if cells else {},
        field_data=fields,
    )


def layout_from_mesh(mesh: Any, path: Path | None = None) -> CellLayout:
    """The layout of a ``meshio.Mesh``; cell types geobrep has no entity for are an error."""
    blocks: list[tuple[str, NDArray[np.int64]]] = []
    keep: list[bool] = []
    for block in mesh.cells:
        known = block.type in _KNOWN_CELLS
        keep.append(known)
        if known:
            what = f"{block.type} connectivity"
            blocks.append((block.type, cast_exactly(np.asarray(block.data), np.int64, what, path)))
    unknown = sorted({b.type for b, k in zip(mesh.cells, keep, strict=True) if not k})
    if unknown:
        raise FormatError(f"cell types geobrep has no entity for: {', '.join(unknown)}", path)
    cell_data: dict[str, NDArray[Any]] = {}
    for name, per_block in mesh.cell_data.items():
        arrays = [np.asarray(a) for a, k in zip(per_block, keep, strict=True) if k]
        if arrays:
            cell_data[name] = arrays[0] if len(arrays) == 1 else np.concatenate(arrays)
    header = None
    raw = mesh.field_data.get(HEADER_ARRAY)
    if raw is not None:
        header = decode_header(raw)
    return CellLayout(
        points=np.asarray(mesh.points, dtype=np.float64),
        blocks=blocks,
        point_data={name: np.asarray(v) for name, v in mesh.point_data.items()},
        cell_data=cell_data,
        header=header if header_applies(header, cell_data) else None,
    )


@contextlib.contextmanager
def _contained(path: Path, action: str) -> Any:
    """Run meshio with stdout/stderr captured; any failure (even SystemExit) is ours."""
    chatter = io.StringIO()
    try:
        with (
            contextlib.redirect_stderr(chatter),
            contextlib.redirect_stdout(chatter),
            warnings.catch_warnings(),
        ):
            warnings.simplefilter("ignore")
            yield
    except FormatError:
        raise
    except (Exception, SystemExit) as exc:
        said = " ".join(chatter.getvalue().split())
        detail = f"{type(exc).__name__}: {exc}".strip()
        if said:
            detail += f" (meshio said: {said[:300]})"
        raise FormatError(f"meshio could not {action} this file: {detail}", path) from exc


def read_mesh(path: Path, file_format: str) -> Any:
    """``meshio.read`` with failures contained."""
    import meshio

    with _contained(path, "read"):
        return meshio.read(path, file_format=file_format)
    raise AssertionError("unreachable")  # pragma: no cover


def write_mesh(mesh: Any, path: Path, file_format: str, **kwargs: Any) -> None:
    """``meshio.write`` with failures contained; a mesh without points is refused.

    meshio (and the VTK legacy reader) cannot read back a file without points, so none is
    written: the error says there is nothing this format can hold.
    """
    import meshio

    if len(mesh.points) == 0:
        raise FormatError(
            f"nothing to write: the scene has no points or cells a {file_format} file holds "
            "(a file without points cannot be read back)",
            path,
        )

    with _contained(path, "write"):
        meshio.write(path, mesh, file_format=file_format, **kwargs)


def read_scene(path: Path, file_format: str) -> Scene:
    """Read ``path`` with meshio into a scene (exactly, when geobrep wrote it)."""
    mesh = read_mesh(path, file_format)
    return layout_to_scene(layout_from_mesh(mesh, path), path)


def layout_for_writing(scene: Scene) -> CellLayout:
    """The layout of ``scene`` (an alias kept for the format modules)."""
    return scene_to_layout(scene)
