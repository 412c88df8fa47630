"""Pipelines on the built-in models: clip, voxelize, fit, GIS layers in and out, atomic outputs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.batch.pipeline import Pipeline, VoxelizeStep, WriteStep
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.datasets.scattered import dome_elevation
from geobrep.model.entities import LinearOctree, NurbsSurface, Surface

#: The layer cake is 1000 × 800 × 600 m; folding moves columns vertically, keeping volumes.
WEST_VOLUME = 500.0 * 800.0 * 600.0
WEST_SECTION_AREA = 500.0 * 600.0


def test_clip_voxelize_write_on_the_layer_cake(tmp_path: Path, cake_file: Path) -> None:
    (tmp_path / "west.yaml").write_text(
        "version: 1\n"
        "inputs: [models/*.geobrep]\n"
        "output: out\n"
        "steps:\n"
        "  - read: {format: native}\n"
        "  - clip: {plane: [1, 0, 0, -450500], keep: negative}\n"
        "  - voxelize: {depth: 6, method: auto}\n"
        "  - write: {format: native, name: '{stem}_west.geobrep'}\n"
        "  - convert: {format: vtu}\n",
        encoding="utf-8",
    )
    summary = run_pipeline(tmp_path / "west.yaml")
    assert summary.ok, summary.table()
    [report] = summary.reports
    out = tmp_path / "out"
    assert report.outputs == (out / "cake_west.geobrep", out / "cake.vtu")
    assert [(s.step, s.kind) for s in report.steps] == [
        (1, "read"), (2, "clip"), (3, "voxelize"), (4, "write"), (5, "convert")
    ]  # fmt: skip
    assert any("LinearOctree" in loss for loss in report.lost)  # vtu holds no octree

    west = geobrep.read(out / "cake_west.geobrep")
    assert max(float(s.vertices[:, 0].max()) for s in west.surfaces) == pytest.approx(450_500.0)
    blocks = [b for b in west.blocks if b.kind != "universe"]
    assert len(blocks) == 6
    mesh_volume = sum(west.block_mesh(b).volume for b in blocks)
    assert mesh_volume == pytest.approx(WEST_VOLUME, rel=1e-4)
    [octree] = west.of_type(LinearOctree)
    assert octree.depth == 6
    bodies = octree.metadata["voxelization"]["bodies"]
    assert sum(b["octree_volume"] for b in bodies) == pytest.approx(WEST_VOLUME, rel=0.01)
    assert sorted(set(octree.labels.tolist())) == sorted(b.id for b in blocks)
    # The vtu holds the surfaces of the clipped model.
    assert len(geobrep.read(out / "cake.vtu").surfaces) == len(west.surfaces)


def test_section_to_geopackage_and_geojson(tmp_path: Path, cake_file: Path) -> None:
    pipeline = Pipeline.from_data(
        {
            "steps": [
                {"clip_box": {"bounds": [450_000, 450_500, 6_700_000, 6_700_800, -1000, 1000]}},
                {"section": {"plane": [0, 1, 0, -6_700_400]}},
                {"write": {"format": "gpkg"}},
                {"write": {"name": "{stem}_section.geojson"}},
            ]
        }
    )
    summary = run_pipeline(pipeline, inputs=[cake_file], output=tmp_path / "gis")
    assert summary.ok, summary.table()
    for name in ("cake.gpkg", "cake_section.geojson"):
        layers = geobrep.read(tmp_path / "gis" / name)
        assert layers.crs is not None
        assert layers.crs.epsg == 32631
        assert len(layers.polygons) == 6  # one per block
        assert sum(p.area for p in layers.polygons) == pytest.approx(WEST_SECTION_AREA, rel=1e-4)
        assert {e.kind for e in layers.polylines} >= {"horizon", "fault"}


def _dome_error(surface: Surface, origin: tuple[float, float, float]) -> float:
    local = surface.vertices - np.asarray(origin)
    inside = np.all((local[:, :2] > 100.0) & (local[:, :2] < 900.0), axis=1)
    truth = dome_elevation(local[inside, 0], local[inside, 1])
    return float(np.median(np.abs(local[inside, 2] - truth)))


def test_fit_pipeline_from_csv_points(tmp_path: Path, points_csv: Path) -> None:
    (tmp_path / "fit.yaml").write_text(
        "inputs: [survey.csv]\n"
        "output: surfaces\n"
        "steps:\n"
        "  - fit: {method: approximation, options: {epsilon: 0.5}, check: true}\n"
        "  - write: {format: native}\n"
        "  - write: {format: vtu}\n",
        encoding="utf-8",
    )
    summary = run_pipeline(tmp_path / "fit.yaml")
    assert summary.ok, summary.table()
    [fit_step] = [s for s in summary.reports[0].steps if s.kind == "fit"]
    assert "approximation σ = " in fit_step.notes[0]
    assert "(meets ε)" in fit_step.notes[0]
    [nurbs] = geobrep.read(tmp_path / "surfaces" / "survey.geobrep").entities
    assert isinstance(nurbs, NurbsSurface)
    # The vtu cannot hold NURBS: the write step tessellated it.
    [mesh] = geobrep.read(tmp_path / "surfaces" / "survey.vtu").surfaces
    assert _dome_error(mesh, (450_000.0, 6_700_000.0, 0.0)) < 0.5


def test_fit_from_geojson_points_keeps_them_and_fails_an_unmet_epsilon(tmp_path: Path) -> None:
    points = geobrep.datasets.scattered_points()
    scene = geobrep.Scene(entities=[points], crs=geobrep.CRS(epsg=32631))
    source = geobrep.write(scene, tmp_path / "survey.geojson")
    steps = [
        {"read": {"format": "geojson"}},
        {"fit": {"method": "kriging", "keep_input": True, "options": {"grid_size": 40}}},
        {"write": {"format": "native"}},
    ]
    summary = run_pipeline({"steps": steps}, inputs=[source], output=tmp_path / "out")
    assert summary.ok, summary.table()
    result = geobrep.read(tmp_path / "out" / "survey.geobrep")
    assert len(result.point_sets) == 1
    assert len(result.surfaces) == 1
    assert result.crs is not None
    assert result.crs.epsg == 32631
    assert _dome_error(result.surfaces[0], (450_000.0, 6_700_000.0, 0.0)) < 1.0

    strict = [
        {"fit": {"method": "approximation", "options": {"epsilon": 1e-6}, "check": True}},
        {"write": {"format": "native", "name": "{stem}_strict.geobrep"}},
    ]
    summary = run_pipeline({"steps": strict}, inputs=[source], output=tmp_path / "out")
    [report] = summary.failed
    assert report.failed_step == 1
    assert report.error is not None
    assert report.error.startswith(
        "step 1 (fit): the approximation fit of 'survey points' does not meet ε = 1e-06 (σ = "
    )
    assert not (tmp_path / "out" / "survey_strict.geobrep").exists()


def test_fit_needs_points(tmp_path: Path, cake_file: Path) -> None:
    steps = [{"fit": {"method": "approximation"}}, {"write": {"format": "native"}}]
    summary = run_pipeline({"steps": steps}, inputs=[cake_file], output=tmp_path)
    assert summary.failed[0].error == "step 1 (fit): the scene holds no PointSet to fit"
    steps[0] = {"fit": {"method": "approximation", "points": ["wells"]}}
    summary = run_pipeline({"steps": steps}, inputs=[cake_file], output=tmp_path)
    assert summary.failed[0].error == ("step 1 (fit): no PointSet or PolyLine named 'wells' to fit")


def test_steps_built_in_python_and_build_blocks(tmp_path: Path, layer_cake: geobrep.Scene) -> None:
    surfaces_only = geobrep.Scene(entities=layer_cake.surfaces, crs=layer_cake.crs)
    source = geobrep.write(surfaces_only, tmp_path / "surfaces.geobrep")
    pipeline = Pipeline.from_data(
        {"steps": [{"build_blocks": {}}, VoxelizeStep(depth=4), WriteStep(format="native")]}
    )
    summary = run_pipeline(pipeline, inputs=[source], output=tmp_path / "built")
    assert summary.ok, summary.table()
    built = geobrep.read(tmp_path / "built" / "surfaces.geobrep")
    assert len(built.blocks) == len(layer_cake.blocks)
    assert len(built.octrees) == 1
    assert summary.reports[0].steps[1].notes == (
        f"{len(layer_cake.blocks)} blocks, {len(layer_cake.patches)} patches",
    )


def test_reproject_step(tmp_path: Path, cake_file: Path) -> None:
    steps = [{"reproject": {"to": "EPSG:32632"}}, {"write": {"format": "native"}}]
    summary = run_pipeline({"steps": steps}, inputs=[cake_file], output=tmp_path / "utm32")
    assert summary.ok, summary.table()
    moved = geobrep.read(tmp_path / "utm32" / "cake.geobrep")
    assert moved.crs is not None
    assert moved.crs.epsg == 32632
    assert moved.bounds is not None
    assert moved.bounds.mins[0] < 200_000


def test_a_failed_write_leaves_no_outputs_of_that_input(tmp_path: Path, cake_file: Path) -> None:
    target = tmp_path / "out"
    target.mkdir()
    (target / "cake.ply").mkdir()  # the second output cannot be written over a folder
    steps = [{"write": {"format": "native"}}, {"write": {"format": "ply"}}]
    summary = run_pipeline({"steps": steps}, inputs=[cake_file], output=target)
    [report] = summary.failed
    assert report.failed_step == 2
    assert report.error is not None
    assert report.error.startswith("step 2 (write): ")
    assert not (target / "cake.geobrep").exists()
    assert sorted(p.name for p in target.iterdir()) == ["cake.ply"]
