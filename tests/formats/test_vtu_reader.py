"""geobrep's VTU reader returns what meshio's returns, and leaves to meshio what it does not read.

Each file is read by both; the points, cell blocks, point, cell and field data must agree in
values, dtype (byte order included) and shape. Files written by meshio (ASCII, binary
uncompressed, zlib and lzma, UInt32 and UInt64 headers), by geobrep's writer and by hand
(big-endian, appended base64, headers encoded apart from their data, UInt8 cell types, empty
NumberOfComponents) are read by geobrep's reader; others go to meshio, with the same scene.
"""

from __future__ import annotations

import base64
import json
import lzma
import subprocess
import sys
import zlib
from pathlib import Path
from typing import Any

import meshio
import numpy as np
import pytest
from formats_support import rich_scene
from numpy.typing import NDArray

import geobrep
from geobrep.adapters import meshio as meshio_adapter
from geobrep.adapters.meshio._vtu_reader import VtuMesh, read_vtu_mesh
from geobrep.errors import FormatError

_VTK_TYPES = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "tetra": 10, "hexahedron": 12}
_NODES = {"vertex": 1, "line": 2, "triangle": 3, "quad": 4, "tetra": 4, "hexahedron": 8}
_NAMES = {
    np.dtype(t).newbyteorder("="): name
    for t, name in [
        (np.float32, "Float32"),
        (np.float64, "Float64"),
        (np.int8, "Int8"),
        (np.int32, "Int32"),
        (np.int64, "Int64"),
        (np.uint8, "UInt8"),
        (np.uint64, "UInt64"),
    ]
}


def _mesh(rng: np.random.Generator, kinds: tuple[str, ...] = ("triangle", "line")) -> Any:
    """A mesh with runs of several cell types (one type twice, apart) and arrays of many
    dtypes and widths."""
    n = 23
    runs = [(kind, rng.integers(0, n, (5 + 2 * i, _NODES[kind]))) for i, kind in enumerate(kinds)]
    runs += [("triangle", rng.integers(0, n, (4, 3))), ("vertex", rng.integers(0, n, (3, 1)))]
    runs += [("tetra", rng.integers(0, n, (6, 4))), ("quad", rng.integers(0, n, (2, 4)))]
    cells = [meshio.CellBlock(kind, conn) for kind, conn in runs]
    return meshio.Mesh(
        rng.normal(size=(n, 3)) * 1e5,
        cells,
        point_data={
            "depth": rng.normal(size=n),
            "flag": rng.integers(0, 2, n).astype(np.uint8),
            "normal": rng.normal(size=(n, 3)).astype(np.float32),
            "single": rng.integers(-5, 5, (n, 1)).astype(np.int8),
        },
        cell_data={
            "id": [np.arange(len(c), dtype=np.int32) for _, c in runs],
            "tensor": [rng.normal(size=(len(c), 6)) for _, c in runs],
            "big": [rng.integers(-(2**62), 2**62, len(c)) for _, c in runs],
        },
        field_data={"marker": np.arange(7, dtype=np.uint8)},
    )


def _same_array(ours: NDArray[Any], theirs: Any, what: str) -> None:
    theirs = np.asarray(theirs)
    assert ours.dtype.str == theirs.dtype.str, what
    assert ours.shape == theirs.shape, what
    np.testing.assert_array_equal(ours, theirs, err_msg=what)


def _same_mesh(ours: VtuMesh | None, path: Path) -> None:
    theirs = meshio.read(path, file_format="vtu")
    assert ours is not None, "geobrep's reader left the file to meshio"
    _same_array(ours.points, theirs.points, "points")
    assert [b.type for b in ours.cells] == [b.type for b in theirs.cells]
    for k, (mine, other) in enumerate(zip(ours.cells, theirs.cells, strict=True)):
        _same_array(mine.data, other.data, f"cell block {k}")
    assert list(ours.point_data) == list(theirs.point_data)
    for name, values in ours.point_data.items():
        _same_array(values, theirs.point_data[name], f"point data {name}")
    assert list(ours.cell_data) == list(theirs.cell_data)
    for name, per_block in ours.cell_data.items():
        assert len(per_block) == len(theirs.cell_data[name])
        for k, values in enumerate(per_block):
            _same_array(values, theirs.cell_data[name][k], f"cell data {name} block {k}")
    assert list(ours.field_data) == list(theirs.field_data)
    for name, values in ours.field_data.items():
        _same_array(values, theirs.field_data[name], f"field data {name}")


@pytest.mark.parametrize(
    ("binary", "compression", "header_type"),
    [
        (False, None, "UInt32"),
        *((True, c, h) for c in (None, "zlib", "lzma") for h in ("UInt32", "UInt64")),
    ],
)
def test_files_meshio_writes(
    tmp_path: Path, binary: bool, compression: str | None, header_type: str
) -> None:
    path = tmp_path / "mesh.vtu"
    meshio.write(
        path,
        _mesh(np.random.default_rng(3)),
        file_format="vtu",
        binary=binary,
        compression=compression,
        header_type=header_type,
    )
    _same_mesh(read_vtu_mesh(path), path)


def _encoded(
    values: NDArray[Any], order: str, header: str, compression: str | None, apart: bool
) -> str:
    """One array's base64 text, as VTK writes it (``apart``: header and data encoded apart)."""
    header_type = np.dtype(header.lower()).newbyteorder(order)
    data = np.ascontiguousarray(values).astype(values.dtype.newbyteorder(order)).tobytes()
    if compression is None:
        head = np.array([len(data)], header_type).tobytes()
        if apart:
            return base64.b64encode(head).decode() + base64.b64encode(data).decode()
        return base64.b64encode(head + data).decode()
    compress = zlib.compress if compression == "zlib" else lzma.compress
    step = 40  # small blocks: several per array
    blocks = [compress(data[i : i + step]) for i in range(0, len(data), step)] or [compress(b"")]
    last = len(data) - (len(blocks) - 1) * step
    table = np.array([len(blocks), step, last, *map(len, blocks)], header_type).tobytes()
    return base64.b64encode(table).decode() + base64.b64encode(b"".join(blocks)).decode()


def _by_hand(
    path: Path,
    mesh: Any,
    *,
    order: str = ">",
    header: str = "UInt32",
    compression: str | None = None,
    appended: bool = False,
    apart: bool = False,
) -> None:
    """A VTU written here: byte order, header type, compression, inline or appended base64."""
    conn = np.concatenate([c.data.reshape(-1) for c in mesh.cells]).astype(np.int64)
    widths = np.concatenate([np.full(len(c.data), c.data.shape[1]) for c in mesh.cells])
    types = np.concatenate([np.full(len(c.data), _VTK_TYPES[c.type], np.uint8) for c in mesh.cells])
    cell_data = {name: np.concatenate(blocks) for name, blocks in mesh.cell_data.items()}
    tail: list[str] = []

    def array(name: str, values: NDArray[Any], components: str | None = None) -> str:
        text = _encoded(values, order, header, compression, apart)
        width = (
            components
            if components is not None
            else (str(values.shape[1]) if values.ndim == 2 else None)
        )
        attributes = f'type="{_NAMES[values.dtype.newbyteorder("=")]}" Name="{name}"'
        if width is not None:
            attributes += f' NumberOfComponents="{width}"'
        if appended:
            offset = sum(map(len, tail))
            tail.append(text)
            return f'<DataArray {attributes} format="appended" offset="{offset}"/>\n'
        return f'<DataArray {attributes} format="binary">\n{text}\n</DataArray>\n'

    piece = [
        "<Points>\n",
        array("Points", mesh.points),
        "</Points>\n<Cells>\n",
        array("connectivity", conn),
        array("offsets", np.cumsum(widths).astype(np.int64)),
        array("types", types),
        "</Cells>\n<PointData>\n",
        *(array(n, v, "" if v.ndim == 1 else None) for n, v in mesh.point_data.items()),
        "</PointData>\n<CellData>\n",
        *(array(n, v) for n, v in cell_data.items()),
        "</CellData>\n",
    ]
    fields = [array(n, v) for n, v in mesh.field_data.items()]
    byte_order = "BigEndian" if order == ">" else "LittleEndian"
    attributes = f'type="UnstructuredGrid" version="1.0" byte_order="{byte_order}"'
    attributes += f' header_type="{header}"'
    if compression:
        attributes += (
            ' compressor="vtkZLibDataCompressor"'
            if compression == "zlib"
            else (' compressor="vtkLZMADataCompressor"')
        )
    text = [
        f'<?xml version="1.0"?>\n<VTKFile {attributes}>\n<UnstructuredGrid>\n',
        "<FieldData>\n",
        *fields,
        "</FieldData>\n",
        f'<Piece NumberOfPoints="{len(mesh.points)}" NumberOfCells="{len(types)}">\n',
        *piece,
        "</Piece>\n</UnstructuredGrid>\n",
    ]
    if appended:
        text.append(f'<AppendedData encoding="base64">\n_{"".join(tail)}\n</AppendedData>\n')
    text.append("</VTKFile>\n")
    path.write_text("".join(text))


@pytest.mark.parametrize("order", [">", "<"])
@pytest.mark.parametrize("compression", [None, "zlib", "lzma"])
@pytest.mark.parametrize("appended", [False, True])
@pytest.mark.parametrize(("header", "apart"), [("UInt32", False), ("UInt64", True)])
def test_files_written_by_hand(
    tmp_path: Path,
    order: str,
    compression: str | None,
    appended: bool,
    header: str,
    apart: bool,
) -> None:
    path = tmp_path / "hand.vtu"
    mesh = _mesh(np.random.default_rng(5))
    _by_hand(
        path,
        mesh,
        order=order,
        header=header,
        compression=compression,
        appended=appended,
        apart=apart,
    )
    ours = read_vtu_mesh(path)
    _same_mesh(ours, path)
    assert ours is not None
    # meshio keeps the byte order of uncompressed arrays (its block concatenation makes the
    # others native), and makes the points native when it merges the pieces
    kept = order == ">" and compression is None
    assert (ours.cell_data["big"][0].dtype.byteorder == ">") is kept
    assert ours.points.dtype.isnative


@pytest.mark.parametrize("compression", [None, "zlib", "lzma"])
def test_files_geobrep_writes_read_the_same_as_through_meshio(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, compression: str | None
) -> None:
    path = tmp_path / "scene.vtu"
    scene = rich_scene()
    geobrep.write(scene, path, compression=compression)
    _same_mesh(read_vtu_mesh(path), path)
    ours = geobrep.read(path)
    monkeypatch.setattr(meshio_adapter, "read_vtu_mesh", lambda path: None)
    theirs = geobrep.read(path)
    assert ours.entities == theirs.entities
    assert (ours.crs, ours.groups, ours.name) == (theirs.crs, theirs.groups, theirs.name)
    assert ours.entities == geobrep.read(path).entities  # the meshio path, once more


def _two_pieces(path: Path) -> None:
    meshio.write(path, _mesh(np.random.default_rng(1)), binary=False)
    text = path.read_text()
    start, end = text.index("<Piece"), text.index("</Piece>") + len("</Piece>\n")
    path.write_text(text[:end] + text[start:end] + text[end:])


def _vtk_grid() -> Any:
    pyvista = pytest.importorskip("pyvista")
    cells = np.array([3, 0, 1, 2, 2, 2, 3])
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 5]])
    grid = pyvista.UnstructuredGrid(cells, np.array([5, 3], np.uint8), points)
    grid.point_data["depth"] = np.arange(4, dtype=np.float32)
    grid.cell_data["id"] = np.array([7, 9], np.int32)
    return grid


def test_a_file_vtk_writes(tmp_path: Path) -> None:
    """VTK's writer: UInt8 cell types, arrays with information keys, zlib blocks."""
    path = tmp_path / "vtk.vtu"
    _vtk_grid().save(path, binary=True)
    _same_mesh(read_vtu_mesh(path), path)


def _raw_appended(path: Path) -> None:
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    writer = vtkXMLUnstructuredGridWriter()
    writer.SetInputData(_vtk_grid())
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetFileName(str(path))
    writer.Write()


def _hexahedra(path: Path) -> None:
    cube = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], np.float64)
    meshio.write(path, meshio.Mesh(cube, [("hexahedron", np.array([[0, 1, 3, 2, 4, 5, 7, 6]]))]))


def _no_text(path: Path) -> None:
    meshio.write(path, _mesh(np.random.default_rng(2)), binary=False)
    text = path.read_text()
    start = text.index('<DataArray type="Float64" Name="depth"')
    end = text.index("</DataArray>", start) + len("</DataArray>")
    path.write_text(
        text[:start] + '<DataArray type="Float64" Name="depth" format="ascii"/>' + text[end:]
    )


def _cut_ascii(path: Path) -> None:
    meshio.write(path, _mesh(np.random.default_rng(2)), binary=False)
    text = path.read_text()
    where = text.index('Name="depth"')
    where = text.index("\n", where) + 1
    path.write_text(text[:where] + "1.0 oops " + text[where:])


@pytest.mark.parametrize(
    "make", [_two_pieces, _raw_appended, _hexahedra, _no_text, _cut_ascii], ids=lambda f: f.__name__
)
def test_files_left_to_meshio(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, make: Any) -> None:
    path = tmp_path / "other.vtu"
    make(path)
    assert read_vtu_mesh(path) is None

    def outcome() -> Any:
        try:
            scene = geobrep.read(path)
        except FormatError as exc:
            return str(exc)
        return scene.entities

    ours = outcome()
    monkeypatch.setattr(meshio_adapter, "read_vtu_mesh", lambda path: None)
    assert outcome() == ours


def test_reading_a_vtu_imports_no_meshio(tmp_path: Path) -> None:
    path = tmp_path / "scene.vtu"
    geobrep.write(rich_scene(), path)
    code = (
        "import json, sys, geobrep; scene = geobrep.read(sys.argv[1]); "
        "print(json.dumps([len(scene.entities), sorted(m for m in sys.modules "
        "if m.split('.')[0] == 'meshio')]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(path)], capture_output=True, text=True, check=True
    )
    count, loaded = json.loads(done.stdout.splitlines()[-1])
    assert count == len(geobrep.read(path).entities) > 1
    assert loaded == []


@pytest.mark.parametrize("text", ["", "AAAA"])
def test_a_compressed_array_without_its_block_table_is_a_format_error(
    tmp_path: Path, text: str
) -> None:
    rng = np.random.default_rng(5)
    path = tmp_path / "z.vtu"
    meshio.write(path, _mesh(rng), binary=True, compression="zlib")
    xml = path.read_text()
    start = xml.index(">", xml.index('<DataArray type="Float64" Name="Points"')) + 1
    path.write_text(xml[:start] + text + xml[xml.index("</DataArray>", start) :])
    with pytest.raises(FormatError, match="'Points' holds no compressed data"):
        geobrep.read(path)


def test_split_base64_blocks_decodes_the_table_and_the_blocks_apart() -> None:
    from geobrep.adapters._vtk_xml import split_base64_blocks

    header = np.dtype("<u4")
    packed = zlib.compress(np.arange(10.0).tobytes())
    table = np.array([1, 80, 80, len(packed)], header).tobytes()
    text = (base64.b64encode(table) + base64.b64encode(packed)).decode()
    assert split_base64_blocks(text, header) == (table, packed)
    assert split_base64_blocks("", header) == (b"", b"")
