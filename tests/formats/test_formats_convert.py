"""Batch conversion: losses reported, corrupt files isolated, processes and Dask, the CLI."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geobrep.batch.conversion import ConversionSummary, convert, demo_stage, expand
from geobrep.cli.main import main
from geobrep.demo import DemoContext
from geobrep.errors import FileAccessError, OptionsError
from geobrep.model.entities import Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

BATCH = 200


def _tile(index: int) -> Surface:
    """A small UTM-located surface with a property, different for every index."""
    x, y = np.meshgrid(np.arange(4.0), np.arange(4.0))
    vertices = np.column_stack([x.ravel() * 10 + 450000.0 + index, y.ravel() * 10 + 6.7e6,
                                np.sin(x.ravel() + index)])  # fmt: skip
    corner = (np.arange(3)[None, :] + 4 * np.arange(3)[:, None]).ravel()
    quads = np.concatenate(
        [np.column_stack([corner, corner + 1, corner + 5]),
         np.column_stack([corner, corner + 5, corner + 4])]
    )  # fmt: skip
    return Surface(vertices=vertices, faces=quads, name=f"tile {index}",
                   point_data={"z": vertices[:, 2]})  # fmt: skip


@pytest.fixture(scope="module")
def batch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("batch")
    for index in range(BATCH - 1):
        write(_tile(index), folder / f"tile_{index:03d}.ply")
    (folder / "tile_corrupt.ply").write_bytes(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 9\n"
    )
    return folder


def _check_batch(summary: ConversionSummary, out: Path) -> None:
    assert len(summary.reports) == BATCH
    assert not summary.ok
    [failed] = summary.failed
    assert failed.source.name == "tile_corrupt.ply"
    assert "tile_corrupt.ply" in (failed.error or "")
    assert not (out / "tile_corrupt.vtu").exists()
    assert len(summary.converted) == BATCH - 1
    assert sorted(p.name for p in out.iterdir()) == sorted(
        f"tile_{i:03d}.vtu" for i in range(BATCH - 1)
    )
    sample = read(out / "tile_123.vtu").surfaces[0]
    assert sample == _tile(123).replace(id=0)
    assert all(r.lost == () for r in summary.converted)


def test_batch_with_two_processes(batch: Path, tmp_path: Path) -> None:
    seen: list[int] = []
    summary = convert(
        [str(batch / "*.ply")], out_dir=tmp_path, to="vtu", jobs=2,
        progress=lambda report, done, total: seen.append(done),
    )  # fmt: skip
    _check_batch(summary, tmp_path)
    assert seen == list(range(1, BATCH + 1))


def test_batch_on_a_dask_local_cluster(batch: Path, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        summary = convert(str(batch / "*.ply"), out_dir=tmp_path, to="vtu", client=client)
        assert len(client.scheduler_info()["workers"]) == 2
    _check_batch(summary, tmp_path)


def test_one_file_reports_what_the_target_cannot_hold(layer_cake: Scene, tmp_path: Path) -> None:
    source = write(layer_cake, tmp_path / "cake.geobrep")
    summary = convert(source, tmp_path / "cake.stl")
    [report] = summary.reports
    assert report.status == "converted"
    assert "7 Block entities dropped (format holds Surface)" in report.lost
    assert "9 entities merged into one" in report.lost
    assert "topology dropped (31 patches)" in report.lost
    assert "CRS EPSG:32631 dropped" in report.lost
    assert "nothing lost" not in summary.table()


def test_arguments_are_checked(tmp_path: Path) -> None:
    with pytest.raises(OptionsError, match="output folder"):
        convert(["a.ply", "b.ply"], tmp_path / "x.vtu")
    with pytest.raises(OptionsError, match="to='vtu'"):
        convert(["a.ply"], out_dir=tmp_path)
    with pytest.raises(OptionsError, match="jobs"):
        convert(["a.ply"], out_dir=tmp_path, to="vtu", jobs=0)


def test_batch_on_a_dask_cluster_of_worker_processes(batch: Path, tmp_path: Path) -> None:
    """Workers in separate processes: the per-file work and its reports travel by pickling."""
    distributed = pytest.importorskip("distributed")
    sources = [*sorted(batch.glob("tile_0*.ply"))[:20], batch / "tile_corrupt.ply"]
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        summary = convert(sources, out_dir=tmp_path / "new" / "folder", to="vtu", client=client)
    assert [r.source.name for r in summary.failed] == ["tile_corrupt.ply"]
    assert len(summary.converted) == 20
    assert all(r.target is not None and r.target.is_file() for r in summary.converted)


def test_output_folder_is_created_or_refused(tmp_path: Path) -> None:
    source = write(_tile(1), tmp_path / "t.ply")
    summary = convert(source, out_dir=tmp_path / "a" / "b", to="vtu")
    assert summary.ok
    assert (tmp_path / "a" / "b" / "t.vtu").is_file()
    (tmp_path / "file").write_text("")
    with pytest.raises(FileAccessError, match="cannot create the output folder"):
        convert(source, out_dir=tmp_path / "file" / "sub", to="vtu")


def test_missing_inputs_and_name_clashes_are_reported(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    write(_tile(1), tmp_path / "a" / "t.ply")
    write(_tile(2), tmp_path / "b" / "t.ply")
    out = tmp_path / "out"
    out.mkdir()
    summary = convert(
        [tmp_path / "a" / "t.ply", tmp_path / "b" / "t.ply", tmp_path / "none*.ply"],
        out_dir=out,
        to="vtu",
    )
    statuses = [r.status for r in summary.reports]
    assert statuses == ["converted", "failed", "failed"]
    assert "same output name" in (summary.reports[1].error or "")
    assert "no such file" in (summary.reports[2].error or "")
    assert expand([str(tmp_path / "a" / "*.ply")]) == [tmp_path / "a" / "t.ply"]


def test_cli_single_and_batch(
    batch: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    single = tmp_path / "one.vtk"
    assert main(["convert", str(batch / "tile_007.ply"), str(single)]) == 0
    assert read(single).surfaces[0] == _tile(7).replace(id=0)
    out = tmp_path / "many"
    out.mkdir()
    code = main(["convert", str(batch / "tile_00*.ply"), str(batch / "tile_corrupt.ply"),
                 "--to", "vtu", "-o", str(out), "--jobs", "2"])  # fmt: skip
    captured = capsys.readouterr()
    assert code == 1
    assert "10 converted, 1 failed" in captured.out
    assert "failed: " in captured.err
    assert "tile_corrupt.ply" in captured.err
    assert main(["convert", str(batch / "tile_007.ply")]) == 1  # neither OUT nor --to
    assert "IN OUT" in capsys.readouterr().err


def test_demo_stage_writes_picture_and_conversions(layer_cake: Scene, tmp_path: Path) -> None:
    ctx = DemoContext(output=tmp_path, scene=layer_cake)
    demo_stage(ctx)
    assert (tmp_path / "layer_cake.vtu").exists()
    assert (tmp_path / "layer_cake.ply").exists()
    assert (tmp_path / "layer_cake.png").stat().st_size > 10_000
    section = ctx.summary["conversion"]
    assert section["vtu"]["status"] == "converted"
    assert any("Block" in line for line in section["ply"]["lost"])
    assert any(line.startswith("render: layer_cake.png") for line in ctx.lines)
    assert not (tmp_path / "conversion_source.geobrep").exists()
    page = (tmp_path / "layer_cake.html").read_text()
    assert section["page"] == "layer_cake.html"
    assert all(f'"name": "{b.name}"' in page for b in layer_cake.blocks if b.kind != "universe")
