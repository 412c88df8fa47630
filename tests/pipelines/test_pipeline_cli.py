"""``geobrep run``: exit codes, failures listed, --check, --json, inputs and output folder."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from geobrep.cli.main import main

PIPELINE = """\
inputs: [models/*.geobrep]
output: out
steps:
  - clip: {plane: [1, 0, 0, -450500]}
  - section: {plane: [0, 1, 0, -6700400]}
  - write: {format: gpkg}
"""


@pytest.fixture
def pipeline(tmp_path: Path, cake_file: Path) -> Path:
    path = tmp_path / "sections.yaml"
    path.write_text(PIPELINE, encoding="utf-8")
    return path


def test_run_writes_the_outputs(pipeline: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(pipeline)]) == 0
    out = capsys.readouterr().out
    assert "cake.gpkg" in out
    assert out.rstrip().endswith("1 done, 0 failed")
    assert (pipeline.parent / "out" / "cake.gpkg").is_file()


def test_failures_are_listed_and_exit_1(
    pipeline: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "models" / "broken.geobrep"
    bad.write_text("not a zip", encoding="utf-8")
    assert main(["run", str(pipeline), "--json"]) == 1
    captured = capsys.readouterr()
    reports = json.loads(captured.out)
    assert [(Path(r["source"]).name, r["status"]) for r in reports] == [
        ("broken.geobrep", "failed"),
        ("cake.geobrep", "done"),
    ]
    assert reports[1]["steps"][1]["kind"] == "clip"
    assert f"geobrep: failed: {bad}: read: {bad}: " in captured.err


def test_inputs_and_output_folder_from_the_command_line(
    pipeline: Path, cake_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "elsewhere" / "deep"
    assert main(["run", str(pipeline), str(cake_file), "-o", str(target), "--jobs", "2"]) == 0
    assert [p.name for p in target.iterdir()] == ["cake.gpkg"]
    assert not (pipeline.parent / "out").exists()


def test_check_validates_and_lists_the_inputs(
    pipeline: Path, cake_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", str(pipeline), "--check"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines() == [
        f"{pipeline}: valid; steps: clip, section, write",
        f"  {cake_file}",
    ]
    assert not (pipeline.parent / "out").exists()


def test_a_bad_pipeline_is_one_error_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("steps:\n  - clip: {plane: [1, 0, 0, 0], kep: negative}\n"
                    "  - write: {format: vtu}\n", encoding="utf-8")  # fmt: skip
    assert main(["run", str(path)]) == 1
    err = capsys.readouterr().err
    assert err == (
        f"geobrep: error: {path}: step 1 (clip): option 'kep': unknown option (valid options: "
        "tolerance, options, clippers, plane, keep)\n"
    )
    assert main(["run", str(tmp_path / "missing.yaml")]) == 1
    assert "missing.yaml: no such file" in capsys.readouterr().err


def test_run_is_in_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    assert "run a pipeline file" in capsys.readouterr().out


MISSING = """\
inputs: [models/*.geobrep]
output: out
steps:
  - clip: {plane: [1, 0, 0, -1.0e9], keep: positive}
  - write: {format: native}
"""


def test_an_empty_result_fails_its_input_unless_allowed(
    tmp_path: Path, cake_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A clip plane that misses the model leaves nothing: that is not a result (issue 12/7)."""
    path = tmp_path / "missing.yaml"
    path.write_text(MISSING, encoding="utf-8")
    assert main(["run", str(path)]) == 1
    out = capsys.readouterr().out
    assert "holds nothing to write" in out
    assert not (tmp_path / "out" / "cake.geobrep").exists()
    assert main(["run", str(path), "--allow-empty"]) == 0
    assert (tmp_path / "out" / "cake.geobrep").is_file()
