"""A pipeline over many files: a corrupt one fails alone, in processes and on a Dask cluster."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from shapes import CUBE_FACES, CUBE_VERTICES

import geobrep
from geobrep.batch.pipeline_run import PipelineSummary, run_pipeline

FILES = 20
ORIGIN = np.array([450_000.0, 6_700_000.0, -500.0])

PIPELINE = """\
version: 1
inputs: [cubes/*.ply]
output: octrees
steps:
  - read: {format: ply}
  - voxelize: {depth: 3}
  - write: {format: native, name: "{stem}_octree.geobrep"}
"""


def _edge(index: int) -> float:
    return 10.0 + index


@pytest.fixture(scope="module")
def batch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``FILES - 1`` cubes of edge 10, 11, ... m as PLY, a corrupt PLY, and the pipeline."""
    folder = tmp_path_factory.mktemp("batch")
    (folder / "cubes").mkdir()
    for index in range(FILES - 1):
        cube = geobrep.Surface(
            vertices=CUBE_VERTICES * _edge(index) + ORIGIN, faces=CUBE_FACES, name=f"cube {index}"
        )
        geobrep.write(cube, folder / "cubes" / f"cube_{index:02d}.ply")
    (folder / "cubes" / "cube_corrupt.ply").write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 8\n"
    )
    (folder / "pipeline.yaml").write_text(PIPELINE, encoding="utf-8")
    return folder


def _check(summary: PipelineSummary, out: Path) -> None:
    assert len(summary.reports) == FILES
    [failed] = summary.failed
    assert failed.source.name == "cube_corrupt.ply"
    assert failed.error is not None
    assert failed.error.startswith("step 1 (read): ")
    assert "cube_corrupt.ply" in failed.error
    assert sorted(p.name for p in out.iterdir()) == [
        f"cube_{i:02d}_octree.geobrep" for i in range(FILES - 1)
    ]
    for index in (0, 7, FILES - 2):
        [octree] = geobrep.read(out / f"cube_{index:02d}_octree.geobrep").octrees
        [body] = octree.metadata["voxelization"]["bodies"]
        # The octree cube is the cube's own bounding box: the voxels fill it exactly.
        assert octree.size == pytest.approx(_edge(index))
        assert body["octree_volume"] == pytest.approx(_edge(index) ** 3, rel=1e-9)
        assert body["mesh_volume"] == pytest.approx(_edge(index) ** 3, rel=1e-9)


def test_batch_in_two_processes(batch: Path, tmp_path: Path) -> None:
    seen: list[int] = []
    summary = run_pipeline(
        batch / "pipeline.yaml",
        output=tmp_path / "octrees",
        jobs=2,
        progress=lambda report, done, total: seen.append(done),
    )
    assert seen == list(range(1, FILES + 1))
    _check(summary, tmp_path / "octrees")


def test_batch_on_a_dask_local_cluster(batch: Path, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    started = time.perf_counter()
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        summary = run_pipeline(batch / "pipeline.yaml", output=tmp_path / "octrees", client=client)
        workers = client.scheduler_info()["workers"]
        assert len(workers) == 2
    print(f"dask batch of {FILES} files: {time.perf_counter() - started:.2f} s")
    _check(summary, tmp_path / "octrees")


def test_batch_serially_with_relative_paths(batch: Path, tmp_path: Path) -> None:
    """The pipeline's inputs and output are relative to its file, not to the working folder."""
    pipeline = geobrep.Pipeline.load(batch / "pipeline.yaml")
    summary = run_pipeline(pipeline, output=tmp_path / "serial")
    _check(summary, tmp_path / "serial")
    assert all(r.source.parent == batch / "cubes" for r in summary.reports)
