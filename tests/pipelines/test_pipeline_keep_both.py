"""``clip: {keep: both}`` in a pipeline: both halves go on through the following steps, and
each write step writes both, named as ``geobrep clip --keep both`` names them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.batch.operations import builtin_operations
from geobrep.batch.pipeline import Pipeline
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.cli.clip import both_paths
from geobrep.errors import OptionsError

X_CUT = 450500.0


def _y_middle(scene: geobrep.Scene) -> float:
    assert scene.bounds is not None
    _, _, ymin, ymax, _, _ = scene.bounds.as_tuple()
    return (ymin + ymax) / 2


def test_both_halves_go_through_the_next_steps(
    tmp_path: Path, cake_file: Path, layer_cake: geobrep.Scene
) -> None:
    y_cut = _y_middle(layer_cake)
    pipeline = {
        "inputs": [str(cake_file)],
        "output": str(tmp_path / "out"),
        "steps": [
            {"clip": {"plane": [1, 0, 0, -X_CUT], "keep": "both"}},
            {"clip": {"plane": [0, 1, 0, -y_cut]}},
            {"write": {"format": "native"}},
            {"write": {"name": "{half}_{stem}.geobrep"}},
        ],
    }
    summary = run_pipeline(pipeline)
    assert summary.ok, summary.table()
    [report] = summary.reports
    out = tmp_path / "out"
    assert [p.name for p in report.outputs] == [
        "cake-negative.geobrep",
        "cake-positive.geobrep",
        "negative_cake.geobrep",
        "positive_cake.geobrep",
    ]
    # the same names as the command line writes for OUT = out/cake.geobrep
    assert tuple(report.outputs[:2]) == both_paths(out / "cake.geobrep")
    negative, positive = geobrep.clip(layer_cake, [1, 0, 0, -X_CUT], keep="both")
    expected = {
        "negative": geobrep.clip(negative, [0, 1, 0, -y_cut]),
        "positive": geobrep.clip(positive, [0, 1, 0, -y_cut]),
    }
    for half, truth in expected.items():
        assert isinstance(truth, geobrep.Scene)
        for name in (f"cake-{half}.geobrep", f"{half}_cake.geobrep"):
            written = geobrep.read(out / name)
            assert len(written.entities) == len(truth.entities)
            assert len(written.blocks) == len(truth.blocks) > 0
            assert written.bounds is not None
            assert truth.bounds is not None
            np.testing.assert_allclose(written.bounds.as_tuple(), truth.bounds.as_tuple())
            xmin, xmax, _, ymax, _, _ = written.bounds.as_tuple()
            assert ymax <= y_cut + 1e-6
            if half == "negative":
                assert xmax <= X_CUT + 1e-6
            else:
                assert xmin >= X_CUT - 1e-6
    clip_step = report.steps[1]
    assert clip_step.kind == "clip"
    assert clip_step.entities == len(negative.entities) + len(positive.entities)
    assert report.steps[2].entities == sum(len(s.entities) for s in expected.values())


def test_two_splits_name_four_halves() -> None:
    pipeline = Pipeline.from_data(
        {
            "steps": [
                {"clip": {"plane": [1, 0, 0, -X_CUT], "keep": "both"}},
                {"clip": {"plane": [0, 0, 1, 0], "keep": "both"}},
                {"write": {"format": "native"}},
            ]
        }
    )
    assert pipeline.halves() == [
        ("negative-negative", "negative-positive", "positive-negative", "positive-positive")
    ]


def test_half_without_a_split_is_refused() -> None:
    pipeline = Pipeline.from_data(
        {
            "steps": [
                {"write": {"name": "{stem}_{half}.geobrep"}},
                {"clip": {"plane": [1, 0, 0, -X_CUT], "keep": "both"}},
            ]
        }
    )
    with pytest.raises(OptionsError, match=r"uses \{half\}, but no clip step before it"):
        pipeline.check()


def test_the_clip_function_refuses_both(layer_cake: geobrep.Scene) -> None:
    [spec] = [s for s in builtin_operations() if s.name == "clip"]
    with pytest.raises(OptionsError, match="keep 'both' gives two scenes"):
        spec(layer_cake, plane=[1, 0, 0, -X_CUT], keep="both")


def test_one_summary_type_for_convert_and_pipelines(tmp_path: Path, cake_file: Path) -> None:
    assert geobrep.ConversionSummary is geobrep.PipelineSummary
    converted = geobrep.convert(cake_file, tmp_path / "vtu", to="vtu")
    piped = run_pipeline(
        {"inputs": [str(cake_file)], "output": str(tmp_path / "out"),
         "steps": [{"write": {"format": "vtu"}}]}
    )  # fmt: skip
    for summary in (converted, piped):
        assert isinstance(summary, geobrep.PipelineSummary)
        assert summary.ok
        assert summary.done == summary.converted
        assert len(summary.done) == 1
        assert summary.failed == ()
    assert converted.table().splitlines()[-1] == "1 converted, 0 failed"
    assert piped.table().splitlines()[-1] == "1 done, 0 failed"
