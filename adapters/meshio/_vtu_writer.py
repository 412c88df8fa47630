"""geobrep's own VTU writer: the file meshio 5.3.5 writes, with the arrays streamed in chunks.

meshio's writer holds, for each array, its bytes, the bytes with their length header, the
base64 bytes and the base64 text at once (about 4.7 times the array), after building the
connectivity, offsets and types of all cells (the connectivity a copy of every block). Here
each array goes to the file :data:`CHUNK_BYTES` at a time, the cell arrays are made a chunk at
a time from the blocks, and the bytes written are meshio's (binary, uncompressed or zlib/lzma
compressed in meshio's 32 kB blocks; only the comment naming the writer differs): files read
back the same through meshio, VTK and ParaView.
"""

from __future__ import annotations

import base64
import lzma
import sys
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any, Final, Literal

import numpy as np
from numpy.typing import NDArray

import geobrep
from geobrep.adapters.cell_layout import CellLayout
from geobrep.errors import FormatError

__all__ = ["CHUNK_BYTES", "write_vtu"]

#: Bytes of an array encoded at a time (a multiple of 3 and of meshio's compressed block).
CHUNK_BYTES: Final = 3 * (1 << 20)
#: meshio's compressed block size.
_BLOCK: Final = 32768

_VTK_CELL: Final = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "tetra": 10}
_VTU_TYPE: Final = {
    np.dtype(np.float32): "Float32",
    np.dtype(np.float64): "Float64",
    np.dtype(np.int8): "Int8",
    np.dtype(np.int16): "Int16",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
    np.dtype(np.uint8): "UInt8",
    np.dtype(np.uint16): "UInt16",
    np.dtype(np.uint32): "UInt32",
    np.dtype(np.uint64): "UInt64",
}
_COMPRESSORS: Final[dict[str, Callable[[bytes], bytes]]] = {
    "zlib": zlib.compress,
    "lzma": lzma.compress,
}
_COMPRESSOR_NAMES: Final = {"zlib": "vtkZLibDataCompressor", "lzma": "vtkLZMADataCompressor"}

Compression = Literal["zlib", "lzma"] | None
Chunks = Callable[[], Iterator[NDArray[Any]]]


def write_vtu(layout: CellLayout, path: Path, compression: Compression = None) -> None:
    """Write ``layout`` to ``path`` as a binary VTU UnstructuredGrid (no field data)."""
    points = np.asarray(layout.points)
    if points.ndim != 2 or points.shape[1] != 3:
        raise FormatError(f"VTU points must be (n, 3), not {points.shape}", path)
    header_type = "UInt32"
    largest = max(
        [points.nbytes, 8 * sum(int(c.size) for _, c in layout.blocks)]
        + [np.asarray(v).nbytes for v in (*layout.point_data.values(), *layout.cell_data.values())]
    )
    if largest + 64 >= 1 << 32:
        header_type = "UInt64"  # a UInt32 length header cannot hold the size
    order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    attributes = f'type="UnstructuredGrid" version="0.1" byte_order="{order}"'
    if header_type != "UInt32":
        attributes += f' header_type="{header_type}"'
    if compression:
        attributes += f' compressor="{_COMPRESSOR_NAMES[compression]}"'
    writer = _ArrayWriter(compression, np.dtype(header_type.lower()), path)
    n_cells = sum(int(conn.shape[0]) for _, conn in layout.blocks)
    with path.open("w", encoding="ascii", newline="\n") as stream:
        stream.write('<?xml version="1.0"?>\n')
        stream.write(f"<VTKFile {attributes}>\n")
        stream.write(f"<!--This file was created by geobrep v{geobrep.__version__}-->\n")
        stream.write("<UnstructuredGrid>\n")
        stream.write(f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{n_cells}">\n')
        stream.write("<Points>\n")
        writer.array(stream, "Points", points)
        stream.write("</Points>\n")
        if layout.blocks:
            stream.write("<Cells>\n")
            _write_cells(stream, writer, layout.blocks, path)
            stream.write("</Cells>\n")
        cell_data = layout.cell_data if layout.blocks else {}
        for tag, arrays in (("PointData", layout.point_data), ("CellData", cell_data)):
            if arrays:
                stream.write(f"<{tag}>\n")
                for name, values in arrays.items():
                    writer.array(stream, name, np.asarray(values))
                stream.write(f"</{tag}>\n")
        stream.write("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def _write_cells(
    stream: IO[str], writer: _ArrayWriter, blocks: list[tuple[str, NDArray[np.int64]]], path: Path
) -> None:
    """connectivity, offsets and types, each made from the blocks a chunk at a time."""
    unknown = sorted({kind for kind, _ in blocks if kind not in _VTK_CELL})
    if unknown:
        raise FormatError(f"cell types this VTU writer does not know: {', '.join(unknown)}", path)
    dtype = np.result_type(*(conn.dtype for _, conn in blocks))

    def rows(conn: NDArray[Any]) -> int:
        return max(1, CHUNK_BYTES // max(1, int(conn.shape[1]) * int(dtype.itemsize)))

    def connectivity() -> Iterator[NDArray[Any]]:
        for _, conn in blocks:
            step = rows(conn)
            for start in range(0, conn.shape[0], step):
                yield np.ascontiguousarray(conn[start : start + step], dtype=dtype).reshape(-1)

    def offsets() -> Iterator[NDArray[Any]]:
        end = 0
        for _, conn in blocks:
            width, step = conn.shape[1], rows(conn)
            for start in range(0, conn.shape[0], step):
                stop = min(start + step, conn.shape[0])
                yield end + width * np.arange(start + 1, stop + 1, dtype=dtype)
            end += width * conn.shape[0]

    def types() -> Iterator[NDArray[Any]]:
        for kind, conn in blocks:
            step = max(1, CHUNK_BYTES // 8)
            for start in range(0, conn.shape[0], step):
                stop = min(start + step, conn.shape[0])
                yield np.full(stop - start, _VTK_CELL[kind], dtype=np.int64)

    n_values = sum(int(conn.size) for _, conn in blocks)
    n_cells = sum(int(conn.shape[0]) for _, conn in blocks)
    writer.chunked(stream, "connectivity", dtype, 0, n_values, connectivity)
    writer.chunked(stream, "offsets", dtype, 0, n_cells, offsets)
    writer.chunked(stream, "types", np.dtype(np.int64), 0, n_cells, types)


class _ArrayWriter:
    """Writes ``<DataArray>`` elements as meshio does, their data encoded chunk by chunk."""

    def __init__(self, compression: Compression, header: np.dtype[Any], path: Path) -> None:
        self.compress = _COMPRESSORS[compression] if compression else None
        self.header, self.path = header, path

    def array(self, stream: IO[str], name: str, values: NDArray[Any]) -> None:
        """One whole array (1-D, or 2-D with its components)."""
        values = values.astype(values.dtype.newbyteorder("="), copy=False)
        width = int(values.shape[1]) if values.ndim == 2 else 0
        flat_rows = values.reshape(len(values), -1) if values.ndim == 2 else values.reshape(-1)
        step = max(1, CHUNK_BYTES // max(1, values.itemsize * max(width, 1)))

        def chunks() -> Iterator[NDArray[Any]]:
            for start in range(0, len(flat_rows), step):
                yield np.ascontiguousarray(flat_rows[start : start + step]).reshape(-1)

        self.chunked(stream, name, values.dtype, width, values.size, chunks)

    def chunked(
        self,
        stream: IO[str],
        name: str,
        dtype: np.dtype[Any],
        width: int,
        size: int,
        chunks: Chunks,
    ) -> None:
        """A DataArray of ``size`` values of ``dtype`` given as ``chunks()`` (``width``: its
        components, 0 for a 1-D array)."""
        vtu_type = _VTU_TYPE.get(np.dtype(dtype).newbyteorder("="))
        if vtu_type is None:
            raise FormatError(
                f"array {name!r}: VTU cannot hold {np.dtype(dtype)} values", self.path
            )
        components = f' NumberOfComponents="{width}"' if width else ""
        stream.write(f'<DataArray type="{vtu_type}" Name="{name}"{components} format="binary">\n')
        nbytes = size * np.dtype(dtype).itemsize
        if self.compress is None:
            _Base64(stream).feed(np.array(nbytes, dtype=self.header).tobytes()).drain(chunks())
        else:
            self._compressed(stream, nbytes, chunks())
        stream.write("\n</DataArray>\n")

    def _compressed(self, stream: IO[str], nbytes: int, chunks: Iterator[NDArray[Any]]) -> None:
        assert self.compress is not None
        blocks = [self.compress(block) for block in _blocks(chunks)]
        last = nbytes - (len(blocks) - 1) * _BLOCK  # meshio's figure, also for no block
        sizes = [len(blocks), _BLOCK, last, *(len(b) for b in blocks)]
        stream.write(base64.b64encode(np.array(sizes, dtype=self.header).tobytes()).decode())
        encoder = _Base64(stream)
        for block in blocks:
            encoder.feed(block)
        encoder.finish()


def _blocks(chunks: Iterator[NDArray[Any]]) -> Iterator[bytes]:
    """The bytes of ``chunks`` cut in meshio's 32 kB blocks (the last one shorter)."""
    rest = b""
    for chunk in chunks:
        data = rest + chunk.tobytes()
        whole = len(data) - len(data) % _BLOCK
        for start in range(0, whole, _BLOCK):
            yield data[start : start + _BLOCK]
        rest = data[whole:]
    if rest:
        yield rest


class _Base64:
    """Base64 of a byte stream written as it comes (what one b64encode of it all gives)."""

    def __init__(self, stream: IO[str]) -> None:
        self.stream, self.rest = stream, b""

    def feed(self, data: bytes) -> _Base64:
        data = self.rest + data
        whole = len(data) - len(data) % 3
        if whole:
            self.stream.write(base64.b64encode(data[:whole]).decode("ascii"))
        self.rest = data[whole:]
        return self

    def drain(self, chunks: Iterator[NDArray[Any]]) -> None:
        for chunk in chunks:
            self.feed(chunk.tobytes())
        self.finish()

    def finish(self) -> None:
        if self.rest:
            self.stream.write(base64.b64encode(self.rest).decode("ascii"))
        self.rest = b""
