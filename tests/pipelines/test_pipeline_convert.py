"""``geobrep convert`` is a read → convert pipeline: the same files and the same summary."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import geobrep
import geobrep.batch.conversion
import geobrep.batch.pipeline_run
from geobrep.batch.conversion import FileReport, conversion_pipeline, convert
from geobrep.batch.pipeline import Pipeline
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.cli.main import main

GOCAD = Path(__file__).resolve().parent.parent / "data" / "gocad"
SOURCES = ["modelA1.ml", "split_cube.ml", "ts-2props.ts", "points.vs"]


@pytest.fixture
def models(tmp_path: Path) -> Path:
    """Four GOCAD files and a corrupt one in ``tmp_path/in``."""
    folder = tmp_path / "in"
    folder.mkdir()
    for name in SOURCES:
        shutil.copy(GOCAD / name, folder / name)
    (folder / "broken.ts").write_text("GOCAD TSurf 1\nHEADER {\nVRTX 1 a b c\n", encoding="utf-8")
    return folder


def _unprefixed(lost: tuple[str, ...], target: Path) -> tuple[str, ...]:
    return tuple(loss.removeprefix(f"{target.name}: ") for loss in lost)


def _same_files(a: Path, b: Path) -> None:
    assert sorted(p.name for p in a.iterdir()) == sorted(p.name for p in b.iterdir())
    for path in a.iterdir():
        if path.read_bytes() != (b / path.name).read_bytes():  # compare what they hold
            left, right = geobrep.read(path), geobrep.read(b / path.name)
            assert [e.type for e in left.entities] == [e.type for e in right.entities]
            for x, y in zip(left.entities, right.entities, strict=True):
                assert x.name == y.name
                assert np.array_equal(getattr(x, "vertices", []), getattr(y, "vertices", []))


def test_convert_and_its_pipeline_write_the_same_files_and_summary(
    models: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pattern = str(models / "*")
    code = main(["convert", pattern, "--to", "vtu", "-o", str(tmp_path / "cli"), "--json"])
    assert code == 1  # the corrupt file
    reports = [FileReport.model_validate(r) for r in json.loads(capsys.readouterr().out)]
    summary = run_pipeline(
        {"steps": [{"read": {}}, {"convert": {"format": "vtu"}}]},
        inputs=[pattern],
        output=tmp_path / "pipeline",
    )
    _same_files(tmp_path / "cli", tmp_path / "pipeline")
    assert [r.source for r in reports] == [r.source for r in summary.reports]
    assert [r.status for r in reports].count("failed") == 1
    for report, piped in zip(reports, summary.reports, strict=True):
        assert (report.status == "failed") == (piped.status == "failed")
        if report.status == "failed":
            assert report.source.name == "broken.ts"
            assert piped.error == f"step 1 (read): {report.error}"
            continue
        assert report.target is not None
        assert [path.name for path in piped.outputs] == [report.target.name]
        assert report.lost == _unprefixed(piped.lost, report.target)
        assert report.entities == piped.steps[-1].entities > 0
    assert any("Block entities dropped" in line for r in reports for line in r.lost)


def test_one_file_with_verify_is_the_pipeline_with_verify(tmp_path: Path) -> None:
    source = GOCAD / "modelA1.ml"
    (tmp_path / "a").mkdir()
    converted = convert(source, tmp_path / "a" / "m.vtu", verify=True).reports[0]
    summary = run_pipeline(
        {"steps": [{"read": {}}, {"convert": {"name": "m.vtu", "verify": True}}]},
        inputs=[source],
        output=tmp_path / "b",
    )
    [piped] = summary.reports
    assert converted.status == "converted"
    assert piped.status == "done"
    assert converted.lost == _unprefixed(piped.lost, tmp_path / "b" / "m.vtu")
    assert (tmp_path / "a" / "m.vtu").read_bytes() == (tmp_path / "b" / "m.vtu").read_bytes()


def test_convert_runs_through_the_pipeline_executor(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: list[list[str]] = []
    original = geobrep.batch.pipeline_run.run_steps

    def spy(pipeline, source, targets, **keywords):  # type: ignore[no-untyped-def]
        seen.append([step.kind for step in pipeline.step_list])
        return original(pipeline, source, targets, **keywords)

    monkeypatch.setattr(geobrep.batch.pipeline_run, "run_steps", spy)
    summary = convert(GOCAD / "ts-2props.ts", tmp_path / "t.ply")
    assert summary.ok
    assert seen == [["read", "convert"]]
    assert [s.kind for s in conversion_pipeline(write_format="vtu").step_list] == [
        "read",
        "convert",
    ]


def test_a_pipeline_write_step_verifies_what_it_wrote(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A report that hides a loss is caught by ``verify``, in a pipeline as in convert."""
    steps = [{"write": {"name": "{stem}.ts", "verify": True}}]
    honest = run_pipeline({"steps": steps}, inputs=[GOCAD / "split_cube.ml"], output=tmp_path / "a")
    assert honest.ok, honest.table()
    monkeypatch.setattr(geobrep.batch.conversion, "format_losses", lambda *args: [])
    caught = run_pipeline({"steps": steps}, inputs=[GOCAD / "split_cube.ml"], output=tmp_path / "b")
    [report] = caught.reports
    assert report.status == "failed"
    assert "0 Block entities read, 3 written" in str(report.error)
    assert not (tmp_path / "b" / "split_cube.ts").exists()  # a failed input leaves no output


def _nurbs_scene() -> geobrep.Scene:
    net = np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]], dtype=float)
    surface = geobrep.NurbsSurface(
        degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
        control_points=net, name="sheet",
    )  # fmt: skip
    mesh = geobrep.Surface(vertices=[[0, 0, 5], [1, 0, 5], [0, 1, 5]], faces=[[0, 1, 2]], name="t")
    return geobrep.Scene(entities=[surface, mesh])


def test_convert_tessellates_only_when_asked(tmp_path: Path) -> None:
    source = geobrep.write(_nurbs_scene(), tmp_path / "sheet.geobrep")
    kept = convert(source, tmp_path / "kept.vtu").reports[0]
    assert kept.status == "converted"
    assert any("NurbsSurface entities dropped" in line for line in kept.lost), kept.lost
    meshed = convert(source, tmp_path / "meshed.vtu", tessellate=True).reports[0]
    assert meshed.status == "converted", meshed.error
    assert not any("NurbsSurface" in line for line in meshed.lost)
    surface = next(s for s in geobrep.read(tmp_path / "meshed.vtu").surfaces if s.name == "sheet")
    corners = {tuple(v) for v in surface.vertices.round(9)}
    assert {(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 1)} <= corners
    assert main(["convert", str(source), str(tmp_path / "cli.vtu"), "--tessellate"]) == 0
    names = {s.name: s.n_vertices for s in geobrep.read(tmp_path / "cli.vtu").surfaces}
    assert names == {"sheet": surface.n_vertices, "t": 3}


def test_allow_empty_reaches_convert_steps_too() -> None:
    pipeline = Pipeline.from_data(
        {"steps": [{"write": {"format": "vtu"}}, {"convert": {"format": "ply"}}]}
    )
    assert [step.allow_empty for step in pipeline.allowing_empty().step_list] == [True, True]
