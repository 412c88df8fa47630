"""``geobrep check`` and ``geobrep repair``, and the pipeline's check and repair steps."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import geobrep
from geobrep.cli import main

DATA = Path(__file__).parents[1] / "data" / "gocad"


def run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_check_exit_codes_and_json(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(capsys, "check", DATA / "modelA1.ml", "-q")
    assert code == 0
    assert "clean" in out
    code, out, _ = run(capsys, "check", DATA / "split_cube.ml", DATA / "modelA1.ml", "--json", "-q")
    assert code == 3
    reports = json.loads(out)
    assert [r["file"] for r in reports] == [str(DATA / "split_cube.ml"), str(DATA / "modelA1.ml")]
    sides = next(s for s in reports[0]["sections"] if s["check"] == "region_sides")
    assert sides["count"] == 2
    code, out, _ = run(capsys, "check", DATA / "split_cube.ml", "--on-defects", "continue", "-q")
    assert code == 0
    code, _, err = run(capsys, "check", DATA / "modelA1.ml", "--checks", "colocated_vertice")
    assert code == 2
    assert "unknown check 'colocated_vertice'" in err
    code, _, err = run(capsys, "check", DATA / "modelA1.ml", "--tolerance", "-1")
    assert code == 1  # a bad option value, as for every command
    assert "--tolerance" in err
    code, _, err = run(capsys, "check", tmp_path / "missing.ml")
    assert code == 1


def test_check_writes_the_defect_layer(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out_file = tmp_path / "defects.geobrep"
    code, _out, _ = run(capsys, "check", DATA / "split_cube.ml", "--defects", out_file, "-q")
    assert code == 3
    layer = geobrep.read(out_file)
    names = {e.name for e in layer.entities}
    assert "split_cube.region_sides.points" in names
    assert all(e.metadata["colour"].startswith("#") for e in layer.entities)


def test_repair_mends_split_cube(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    fixed = tmp_path / "fixed.ml"
    code, out, _ = run(capsys, "repair", DATA / "split_cube.ml", fixed, "-q")
    assert code == 0
    assert "region_sides: 2 -> 0" in out
    code, out, _ = run(capsys, "check", fixed, "-q")
    assert code == 0, out
    back = geobrep.read(fixed, repair=False)
    volumes = sorted(round(back.block_mesh(b).volume, 9) for b in back.blocks)
    assert volumes == [0.3, 0.7]


def test_pipeline_check_and_repair_steps(tmp_path: Path) -> None:
    source = tmp_path / "in"
    source.mkdir()
    (source / "split_cube.ml").write_bytes((DATA / "split_cube.ml").read_bytes())
    failing = geobrep.Pipeline.from_data(
        {
            "steps": [
                {"read": {"options": {"repair": False}, "format": "gocad"}},
                {"check": {}},
                {"write": {"format": "native"}},
            ]
        }
    )
    summary = geobrep.run_pipeline(
        failing, inputs=source / "split_cube.ml", output=tmp_path / "out1"
    )
    assert not summary.ok
    assert "region_sides 2" in str(summary.failed[0])
    mended = geobrep.Pipeline.from_data(
        {
            "steps": [
                {"read": {"options": {"repair": False}, "format": "gocad"}},
                {"repair": {}},
                {"check": {"on_defects": "fail"}},
                {"write": {"format": "native"}},
            ]
        }
    )
    summary = geobrep.run_pipeline(
        mended, inputs=source / "split_cube.ml", output=tmp_path / "out2"
    )
    written = list((tmp_path / "out2").glob("*.geobrep"))
    assert len(written) == 1
    assert geobrep.inspect(geobrep.read(written[0])).ok


def _progress(err: str, command: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith(f"geobrep {command}: ")]


def test_check_progress_goes_to_stderr_and_keeps_json_clean(
    capsys: pytest.CaptureFixture[str],
) -> None:
    files = (DATA / "modelA1.ml", DATA / "split_cube.ml")
    code, out, err = run(capsys, "check", *files, "--json", "--progress", "-q")
    assert code == 3
    reports = json.loads(out)  # stdout is the JSON alone
    lines = _progress(err, "check")
    reads = [line for line in lines if " read " in line]
    assert reads[0].startswith("geobrep check: file 1/2 ")
    assert [str(f) in line for f, line in zip(files, reads, strict=True)] == [True, True]
    for path, report in zip(files, reports, strict=True):
        checks = [line for line in lines if line.startswith(f"geobrep check: {path} check ")]
        names = [line.split()[5] for line in checks]
        assert names == [s["check"] for s in report["sections"]]
        assert checks[-1].split()[4] == f"{len(names)}/{len(names)}"
    assert len(lines) == len(reads) + sum(len(r["sections"]) for r in reports)


def test_check_progress_only_when_long_or_on_a_terminal(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # short (whatever the machine's load), stderr no terminal: no progress lines
    monkeypatch.setattr("geobrep.cli.common.LONG_WORK_SECONDS", 1e9)
    code, _, err = run(capsys, "check", DATA / "modelA1.ml", "-q")
    assert code == 0
    assert _progress(err, "check") == []
    monkeypatch.setattr("geobrep.cli.common.LONG_WORK_SECONDS", 0.0)  # every run is long
    code, out, err = run(capsys, "check", DATA / "modelA1.ml", "-q")
    assert code == 0
    assert len(_progress(err, "check")) > 10
    assert "geobrep check:" not in out
    code, _, err = run(capsys, "check", DATA / "modelA1.ml", "--no-progress", "-q")
    assert _progress(err, "check") == []


def test_repair_progress_lines(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    fixed = tmp_path / "fixed.ml"
    code, out, err = run(capsys, "repair", DATA / "split_cube.ml", fixed, "--json", "--progress")
    assert code == 0
    report = json.loads(out)
    steps = [line.split()[-3] for line in _progress(err, "repair") if " step " in line]
    actions = [a["action"] for a in report["actions"]]
    assert steps == ["before", *actions, "after"]
    assert _progress(err, "repair")[-1].startswith(f"geobrep repair: {fixed} written ")
