"""Issue 15 item 1: a pipeline or a conversion writes only inside its output folder.

Name patterns substitute bare fields only (the reproducers spell a ``/`` with
``{index.__truediv__.__doc__[11]}``), and every output path is resolved, symlinks included, and
must lie inside the output folder when it is planned and again when it is written.
"""

from __future__ import annotations

import shutil
import time
import tracemalloc
from pathlib import Path

import pytest

import geobrep
from geobrep.batch.conversion import convert, convert_file
from geobrep.batch.outputs import check_name_pattern, format_name, name_fields
from geobrep.batch.pipeline import Pipeline
from geobrep.batch.pipeline_run import plan_outputs, run_file, run_pipeline
from geobrep.cli.main import main
from geobrep.errors import OptionsError

TRAVERSAL = Path(__file__).resolve().parents[1] / "data" / "reliability" / "pipeline_traversal"


@pytest.fixture
def traversal(tmp_path: Path) -> Path:
    """The reproducer folder (pipelines and ``in/tri.ts``), copied to a folder of its own."""
    folder = tmp_path / "work"
    shutil.copytree(TRAVERSAL, folder)
    return folder


def _files(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize("name", ["pipeline.yaml", "pipeline_abs.yaml"])
def test_reproducer_patterns_are_refused_before_anything_is_written(
    traversal: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    before = _files(traversal.parent)
    absolute = Path("/tmp/ABSOLUTE_tri.geobrep")
    existed = absolute.exists()
    with pytest.raises(OptionsError) as raised:
        Pipeline.load(traversal / name)
    message = str(raised.value)
    assert str(traversal / name) in message  # the pipeline file
    assert "step 1 (write)" in message  # the step
    assert "{index.__truediv__.__doc__[11]}" in message  # the pattern
    assert "not a plain field" in message
    assert main(["run", str(traversal / name), "--no-progress"]) not in (0, 70)
    assert "not a plain field" in capsys.readouterr().err
    assert _files(traversal.parent) == before  # nothing written, not even the output folder
    assert not (traversal / "out").exists()
    assert absolute.exists() == existed


@pytest.mark.parametrize(
    "pattern",
    [
        "{index.__class__}.geobrep",  # attribute access
        "{stem[0]}.geobrep",  # indexing
        "{name!r}.geobrep",  # conversion
        "{index:>900000000}.geobrep",  # a format spec that allocates
        "{index:{stem}}.geobrep",  # a nested field in the spec
        "{}.geobrep",  # positional fields
        "{0}.geobrep",
        "{stem_}.geobrep",  # unknown field
        "sub/{stem}.geobrep",  # a path
        "..\\{stem}.geobrep",
    ],
)
def test_only_bare_fields_are_substituted(pattern: str) -> None:
    with pytest.raises(OptionsError, match="name pattern"):
        check_name_pattern(pattern)
    with pytest.raises(OptionsError, match=r"pipeline: step 2 \(write\): name pattern"):
        Pipeline.from_data(
            {"steps": [{"read": {}}, {"write": {"format": "native", "name": pattern}}]}
        )


def test_a_format_spec_bomb_costs_nothing() -> None:
    """``{index:>900000000}`` made str.format allocate 0.9 GB per name (3.5 GB in a run)."""
    tracemalloc.start()
    started = time.perf_counter()
    with pytest.raises(OptionsError):
        Pipeline.from_data({"steps": [{"write": {"name": "{index:>900000000}.geobrep"}}]})
    seconds = time.perf_counter() - started
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert seconds < 30.0  # a hang guard, not a timing test: the memory bound is the test
    assert peak < 10 * 2**20


def test_plain_fields_name_the_outputs(traversal: Path) -> None:
    inputs = traversal / "in"
    shutil.copy(inputs / "tri.ts", inputs / "b.part.ts")
    summary = run_pipeline(
        {
            "inputs": [str(inputs / "*.ts")],
            "output": str(traversal / "out"),
            "steps": [
                {"write": {"format": "native", "name": "{stem}_{index}{ext}.geobrep"}},
                {"write": {"format": "native", "name": "{{x}}_{name}.geobrep"}},
            ],
        }
    )
    assert summary.ok, summary.table()
    sources = sorted(inputs.glob("*.ts"))
    expected = set()
    for index, source in enumerate(sources):
        stem = source.name.split(".")[0]
        expected |= {
            f"{stem}_{index}{source.name[len(stem) :]}.geobrep",
            "{x}_" + source.name + ".geobrep",
        }
    assert {p.name for p in (traversal / "out").iterdir()} == expected
    assert "b_0.part.ts.geobrep" in expected  # {ext} is what follows the stem
    for path in (traversal / "out").iterdir():
        assert geobrep.read(path).surfaces[0].n_cells == 2


def test_format_name_never_calls_str_format() -> None:
    fields = name_fields(Path("models/cake.tar.gz"), 7)
    assert fields == {
        "stem": "cake",
        "name": "cake.tar.gz",
        "ext": ".tar.gz",
        "index": 7,
        "half": "",
    }
    assert format_name("{{{stem}}}-{index}{ext}", fields) == "{cake}-7.tar.gz"
    with pytest.raises(OptionsError):
        format_name("{index.real}", fields)


def _escape_link(folder: Path, name: str, outside: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    link = folder / name
    link.symlink_to(outside)
    return link


def test_a_symlink_out_of_the_output_folder_fails_that_input(traversal: Path) -> None:
    outside = traversal / "outside.geobrep"
    outside.write_text("keep me", encoding="utf-8")
    _escape_link(traversal / "out", "tri.geobrep", outside)
    summary = run_pipeline(_ok_pipeline(traversal))
    [report] = summary.reports
    assert report.status == "failed"
    assert "outside the output folder" in str(report.error)
    assert outside.read_text(encoding="utf-8") == "keep me"


def _ok_pipeline(folder: Path) -> Path:
    path = folder / "ok.yaml"
    path.write_text(
        "inputs: [in/*.ts]\noutput: out\nsteps:\n  - write: {format: native}\n", encoding="utf-8"
    )
    return path


def test_a_symlink_made_after_planning_is_caught_before_writing(traversal: Path) -> None:
    """The check is repeated where the file is written, not only where its path is planned."""
    pipeline = Pipeline.load(_ok_pipeline(traversal)).check()
    out = traversal / "out"
    out.mkdir()
    source = traversal / "in" / "tri.ts"
    [targets] = plan_outputs(pipeline, [source], out, geobrep.plugins.registries())
    assert isinstance(targets, tuple)
    assert targets == (out / "tri.geobrep",)
    outside = traversal / "outside.geobrep"
    outside.write_text("keep me", encoding="utf-8")
    _escape_link(out, "tri.geobrep", outside)
    report = run_file(pipeline, source, targets)
    assert report.status == "failed"
    assert "outside the output folder" in str(report.error)
    assert outside.read_text(encoding="utf-8") == "keep me"
    again = convert_file(source, out / "tri.geobrep", out_dir=out)
    assert again.status == "failed"
    assert "outside the output folder" in str(again.error)
    assert outside.read_text(encoding="utf-8") == "keep me"


def test_convert_into_a_folder_stays_inside(traversal: Path) -> None:
    out = traversal / "out"
    outside = traversal / "outside.vtu"
    outside.write_text("keep me", encoding="utf-8")
    _escape_link(out, "tri.vtu", outside)
    shutil.copy(traversal / "in" / "tri.ts", traversal / "in" / "other.ts")
    summary = convert([str(traversal / "in" / "*.ts")], out_dir=out, to="vtu")
    by_name = {r.source.name: r for r in summary.reports}
    assert by_name["other.ts"].status == "converted"
    assert geobrep.read(out / "other.vtu").surfaces[0].n_cells == 2
    assert by_name["tri.ts"].status == "failed"
    assert "outside the output folder" in str(by_name["tri.ts"].error)
    assert outside.read_text(encoding="utf-8") == "keep me"


def test_convert_refuses_a_path_as_extension(traversal: Path) -> None:
    with pytest.raises(OptionsError, match="not a plain file name"):
        convert([str(traversal / "in" / "*.ts")], out_dir=traversal / "out", to="vtu/../../x.vtu")
    assert not list(traversal.parent.rglob("x.vtu"))
