"""geobrep's VTU writer writes meshio's file (the writer comment aside), its arrays in chunks."""

from __future__ import annotations

import re
import tracemalloc
from pathlib import Path

import meshio
import numpy as np
import pytest

from geobrep.adapters.cell_layout import CellLayout
from geobrep.adapters.meshio import _vtu_writer
from geobrep.adapters.meshio._bridge import mesh_from_layout, write_mesh

_COMMENT = re.compile(rb"<!--.*?-->\n")


def _layout(rng: np.random.Generator) -> CellLayout:
    """Points, every cell type geobrep writes, and point and cell arrays of several dtypes."""
    n = 57
    blocks = [
        ("triangle", rng.integers(0, n, (41, 3))),
        ("line", rng.integers(0, n, (13, 2))),
        ("vertex", rng.integers(0, n, (5, 1))),
        ("tetra", rng.integers(0, n, (17, 4))),
        ("quad", rng.integers(0, n, (3, 4))),
    ]
    n_cells = sum(len(conn) for _, conn in blocks)
    return CellLayout(
        points=rng.normal(size=(n, 3)) * 1e5,
        blocks=[(kind, conn.astype(np.int64)) for kind, conn in blocks],
        point_data={
            "depth": rng.normal(size=n),
            "flag": rng.integers(0, 2, n).astype(np.uint8),
            "normal": rng.normal(size=(n, 3)).astype(np.float32),
        },
        cell_data={
            "id": np.arange(n_cells, dtype=np.int32),
            "tensor": rng.normal(size=(n_cells, 6)),
            "big": rng.integers(-(2**62), 2**62, n_cells),
        },
    )


def _meshio_bytes(layout: CellLayout, path: Path, compression: str | None) -> bytes:
    write_mesh(mesh_from_layout(layout, field_data=False), path, "vtu", compression=compression)
    return _COMMENT.sub(b"", path.read_bytes())


@pytest.mark.parametrize("compression", [None, "zlib", "lzma"])
@pytest.mark.parametrize("chunk", [3, 6, 300, 32769 * 3, 3 << 20])
def test_the_file_is_meshios(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, compression: str | None, chunk: int
) -> None:
    monkeypatch.setattr(_vtu_writer, "CHUNK_BYTES", chunk)
    layout = _layout(np.random.default_rng(chunk))
    ours = tmp_path / "ours.vtu"
    _vtu_writer.write_vtu(layout, ours, compression)  # type: ignore[arg-type]
    assert _COMMENT.sub(b"", ours.read_bytes()) == _meshio_bytes(
        layout, tmp_path / "meshio.vtu", compression
    )
    back = meshio.read(ours)
    np.testing.assert_array_equal(back.points, layout.points)
    assert [(c.type, c.data.tolist()) for c in back.cells] == [
        (kind, conn.tolist()) for kind, conn in layout.blocks
    ]
    for name, values in layout.point_data.items():
        np.testing.assert_array_equal(back.point_data[name], values)
        assert back.point_data[name].dtype == values.dtype


def test_points_only(tmp_path: Path) -> None:
    layout = CellLayout(points=np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]]), blocks=[])
    ours = tmp_path / "ours.vtu"
    _vtu_writer.write_vtu(layout, ours)
    assert _COMMENT.sub(b"", ours.read_bytes()) == _meshio_bytes(layout, tmp_path / "m.vtu", None)


def test_large_arrays_are_written_a_chunk_at_a_time(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(_vtu_writer, "CHUNK_BYTES", 3 << 16)
    rng = np.random.default_rng(3)
    layout = CellLayout(
        points=rng.normal(size=(100_000, 3)),
        blocks=[("triangle", rng.integers(0, 100_000, (200_000, 3)))],
        cell_data={"value": rng.normal(size=200_000)},
    )
    size = layout.points.nbytes + layout.blocks[0][1].nbytes + layout.cell_data["value"].nbytes
    tracemalloc.start()
    try:
        _vtu_writer.write_vtu(layout, tmp_path / "big.vtu")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 0.2 * size  # meshio's writer holds about 4.7x its largest array
    back = meshio.read(tmp_path / "big.vtu")
    np.testing.assert_array_equal(back.cells[0].data, layout.blocks[0][1])
    np.testing.assert_array_equal(back.cell_data["value"][0], layout.cell_data["value"])
