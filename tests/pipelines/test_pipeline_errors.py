"""Bad pipelines fail at once, before any file is read, naming the step, its kind and option."""

from __future__ import annotations

from pathlib import Path

import pytest

from geobrep.batch.pipeline import Pipeline
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.errors import FileAccessError, FormatError, OptionsError


def _load(tmp_path: Path, text: str, name: str = "pipeline.yaml") -> Pipeline:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return Pipeline.load(path)


def test_unknown_step_kind_lists_the_kinds(tmp_path: Path) -> None:
    with pytest.raises(OptionsError) as caught:
        _load(tmp_path, "steps:\n  - read: {}\n  - clipp: {plane: [1, 0, 0, 0]}\n")
    message = str(caught.value)
    assert message.startswith(f"{tmp_path / 'pipeline.yaml'}: step 2: unknown step kind 'clipp'")
    assert "step kinds: read, reproject, clip, clip_box, section, fit" in message


def test_a_misspelt_step_option_names_step_kind_and_option(tmp_path: Path) -> None:
    with pytest.raises(OptionsError, match=r"step 2 \(voxelize\): option 'detph': unknown option "
                       r"\(valid options: depth, method, "):  # fmt: skip
        _load(tmp_path, "steps:\n  - clip: {plane: [1, 0, 0, 0]}\n  - voxelize: {detph: 5}\n"
                        "  - write: {format: vtu}\n")  # fmt: skip


def test_a_bad_value_is_explained(tmp_path: Path) -> None:
    with pytest.raises(OptionsError, match=r"step 1 \(clip\): option 'keep': Input should be "
                       r"'negative', 'positive' or 'both'"):  # fmt: skip
        _load(tmp_path, "steps:\n  - clip: {plane: [1, 0, 0, 0], keep: middle}\n"
                        "  - write: {format: vtu}\n")  # fmt: skip


def test_options_left_unindented_get_a_hint(tmp_path: Path) -> None:
    text = "steps:\n  - clip:\n    plane: [1, 0, 0, 0]\n  - write: {format: vtu}\n"
    with pytest.raises(OptionsError, match="indent the options of 'clip' under it"):
        _load(tmp_path, text)


@pytest.mark.parametrize(
    ("step", "expected"),
    [
        ("fit: {method: kriging, options: {variogram: linear}}",
         r"step 1 \(fit\): fitter 'kriging': option 'variogram': unknown option \(valid options: "
         r".*variogram_model"),
        ("fit: {method: krigging}",
         r"step 1 \(fit\): option 'method': unknown fitter 'krigging'; registered fitters: "
         r"approximation, hybrid, kriging, skinning"),
        ("voxelize: {depth: 30}",
         r"step 1 \(voxelize\): voxelizer 'voxelize': option 'depth': .*less than or equal to 12"),
        ("build_blocks: {options: {tolerence: 0.1}}",
         r"step 1 \(build_blocks\): builder 'blocks': option 'tolerence': unknown option"),
        ("build: {builder: nope}", r"step 1 \(build\): option 'builder': unknown builder 'nope'"),
        ("clip: {plane: [1, 0, 0, 0], options: {surface: {cap: false}}}",
         r"step 1 \(clip\): clipper 'surface': option 'cap': unknown option"),
        ("clip: {plane: [1, 0, 0, 0], clippers: {PolyLine: surface}}",
         r"step 1 \(clip\): option 'clippers': clipper 'surface' cuts Surface, not PolyLine"),
        ("read: {format: png}", r"step 1 \(read\): format 'png' cannot read"),
        ("read: {options: {layer: x}}", r"step 1 \(read\): options need a format name"),
        ("reproject: {to: 'EPSG:1'}", r"step 1 \(reproject\): option 'to': "),
    ],
)  # fmt: skip
def test_plugin_options_are_checked_at_load_time(tmp_path: Path, step: str, expected: str) -> None:
    pipeline = _load(tmp_path, f"steps:\n  - {step}\n  - write: {{format: native}}\n")
    with pytest.raises(OptionsError, match=expected):
        pipeline.check()


def test_write_steps_are_checked(tmp_path: Path) -> None:
    for text, expected in [
        ("- write: {format: vtx}", r"step 1 \(write\): option 'format': unknown format 'vtx'"),
        ("- write: {name: '{stem}.vtx'}", r"step 1 \(write\): .*no installed format writes"),
        ("- write: {format: vtu, options: {compresion: zlib}}",
         r"step 1 \(write\): format 'vtu': option 'compresion': unknown option"),
        ("- write: {format: vtu}\n  - convert: {name: '{stem}.vtu'}",
         r"steps 1 and 2 both write '\{stem\}.vtu'"),
    ]:  # fmt: skip
        with pytest.raises(OptionsError, match=expected):
            _load(tmp_path, f"steps:\n  {text}\n").check()
    with pytest.raises(OptionsError, match=r"unknown field \{stem_\}; fields: \{stem\}"):
        _load(tmp_path, "steps:\n  - write: {name: '{stem_}.vtu'}\n")
    with pytest.raises(OptionsError, match="give a format, a file name pattern"):
        _load(tmp_path, "steps:\n  - write: {}\n")


def test_structure_errors(tmp_path: Path) -> None:
    with pytest.raises(OptionsError, match="the pipeline writes nothing: add a write step"):
        _load(tmp_path, "steps:\n  - clip: {plane: [1, 0, 0, 0]}\n")
    with pytest.raises(OptionsError, match="step 2: read must be the first step"):
        _load(tmp_path, "steps:\n  - write: {format: vtu}\n  - read: {}\n")
    with pytest.raises(OptionsError, match=r"outputs: unknown field \(fields: version, inputs"):
        _load(tmp_path, "outputs: x\nsteps:\n  - write: {format: vtu}\n")
    with pytest.raises(OptionsError, match="version: Input should be 1"):
        _load(tmp_path, "version: 2\nsteps:\n  - write: {format: vtu}\n")
    with pytest.raises(OptionsError, match="a pipeline is a mapping"):
        _load(tmp_path, "- write: {format: vtu}\n")


def test_file_errors(tmp_path: Path) -> None:
    with pytest.raises(FileAccessError, match="no such file"):
        Pipeline.load(tmp_path / "missing.yaml")
    with pytest.raises(FormatError, match=r"pipeline.yaml:3: not valid YAML"):
        _load(tmp_path, "steps:\n  - clip: {plane: [1, 0\n  - write: {format: vtu}\n")
    with pytest.raises(FormatError, match=r"pipeline.json:1: not valid JSON"):
        _load(tmp_path, '{"steps": [}', name="pipeline.json")


def test_nothing_is_touched_when_the_pipeline_is_bad(tmp_path: Path, cake_file: Path) -> None:
    pipeline = _load(tmp_path, f"inputs: ['{cake_file}']\noutput: out\nsteps:\n"
                               "  - fit: {method: approximation, options: {epsilom: 1}}\n"
                               "  - write: {format: native}\n")  # fmt: skip
    with pytest.raises(OptionsError, match="option 'epsilom'"):
        run_pipeline(pipeline)
    assert not (tmp_path / "out").exists()


def test_no_inputs_and_bad_jobs(tmp_path: Path) -> None:
    pipeline = _load(tmp_path, "steps:\n  - write: {format: vtu}\n")
    with pytest.raises(OptionsError, match="the pipeline has no inputs"):
        run_pipeline(pipeline)
    with pytest.raises(OptionsError, match="jobs must be at least 1"):
        run_pipeline(pipeline, inputs=["a.ts"], jobs=0)


def test_a_missing_input_fails_alone(tmp_path: Path, cake_file: Path) -> None:
    pipeline = _load(tmp_path, f"inputs: ['{cake_file}', '{tmp_path}/nope.geobrep']\n"
                               "output: out\nsteps:\n  - write: {format: native, "
                               "name: '{stem}_copy.geobrep'}\n")  # fmt: skip
    summary = run_pipeline(pipeline)
    assert [r.status for r in summary.reports] == ["done", "failed"]
    failed = summary.failed[0]
    assert failed.error == f"read: {tmp_path / 'nope.geobrep'}: no such file"
    assert failed.failed_step == 0
    assert (tmp_path / "out" / "cake_copy.geobrep").is_file()
    assert not (tmp_path / "out" / "nope_copy.geobrep").exists()


def test_outputs_that_clash_or_overwrite_an_input_fail_that_input(
    tmp_path: Path, cake_file: Path
) -> None:
    twin = tmp_path / "other" / "cake.geobrep"
    twin.parent.mkdir()
    twin.write_bytes(cake_file.read_bytes())
    pipeline = _load(tmp_path, "steps:\n  - write: {format: native}\n")
    summary = run_pipeline(pipeline, inputs=[cake_file, twin], output=tmp_path / "out")
    assert [r.status for r in summary.reports] == ["done", "failed"]
    assert summary.reports[1].error == (
        f"output {tmp_path / 'out' / 'cake.geobrep'} is also the output of {cake_file}"
    )
    summary = run_pipeline(pipeline, inputs=[cake_file], output=cake_file.parent)
    assert summary.reports[0].error == f"output {cake_file} would overwrite an input"
