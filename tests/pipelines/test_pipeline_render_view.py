"""The ``render`` and ``view`` steps: the pictures and pages ``geobrep render`` and ``geobrep
view`` write, from the same declarations, anywhere in a pipeline."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from geobrep.batch.pipeline import Pipeline
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.cli.main import main
from geobrep.errors import OptionsError

pytest.importorskip("pyvista")


def _pixels(path: Path) -> NDArray[np.uint8]:
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"))


def test_render_step_draws_what_geobrep_render_draws(cake_file: Path, tmp_path: Path) -> None:
    flags = ["--size", "320", "240", "--view", "top", "--color-by", "block", "--no-scale-bar"]
    assert main(["render", str(cake_file), str(tmp_path / "cli.png"), *flags]) == 0
    summary = run_pipeline(
        {
            "steps": [
                {
                    "render": {
                        "size": [320, 240],
                        "view": "top",
                        "color_by": "block",
                        "scale_bar": False,
                    }
                },
                {"write": {"format": "native"}},
            ]
        },
        inputs=[cake_file],
        output=tmp_path / "out",
    )
    assert summary.ok, summary.table()
    [report] = summary.reports
    assert [p.name for p in report.outputs] == ["cake.png", "cake.geobrep"]
    assert [s.kind for s in report.steps] == ["read", "render", "write"]
    piped, direct = _pixels(tmp_path / "out" / "cake.png"), _pixels(tmp_path / "cli.png")
    assert piped.shape == direct.shape == (240, 320, 3)
    assert np.abs(piped.astype(int) - direct.astype(int)).max() <= 8
    assert len(np.unique(piped.reshape(-1, 3), axis=0)) > 20  # drawn, not blank
    assert report.steps[-1].entities == report.steps[1].entities  # the scene flowed on


def test_view_step_writes_the_page_geobrep_view_writes(cake_file: Path, tmp_path: Path) -> None:
    page = tmp_path / "cli.html"
    assert main(["view", str(cake_file), "-o", str(page), "--title", "Cake", "--no-blocks"]) == 0
    summary = run_pipeline(
        {"steps": [{"view": {"title": "Cake", "blocks": False, "name": "{stem}_page.html"}}]},
        inputs=[cake_file],
        output=tmp_path / "out",
    )
    assert summary.ok, summary.table()
    written = (tmp_path / "out" / "cake_page.html").read_text(encoding="utf-8")
    assert "<title>Cake</title>" in written
    assert written == page.read_text(encoding="utf-8")


def test_after_a_split_each_half_gets_its_picture(cake_file: Path, tmp_path: Path) -> None:
    summary = run_pipeline(
        {
            "steps": [
                {"clip": {"plane": [1, 0, 0, -450500], "keep": "both"}},
                {"render": {"size": [160, 120], "name": "{stem}_{half}.png"}},
            ]
        },
        inputs=[cake_file],
        output=tmp_path / "out",
    )
    assert summary.ok, summary.table()
    names = [p.name for p in summary.reports[0].outputs]
    assert names == ["cake_negative.png", "cake_positive.png"]
    negative, positive = (_pixels(tmp_path / "out" / name) for name in names)
    assert negative.shape == (120, 160, 3)
    assert not np.array_equal(negative, positive)


def test_a_half_plane_fails_before_anything_runs(cake_file: Path, tmp_path: Path) -> None:
    pipeline = Pipeline.from_data({"steps": [{"render": {"clip_origin": [1, 2, 3]}}]})
    with pytest.raises(OptionsError, match=r"step 1 \(render\): .*go together"):
        pipeline.check()
    with pytest.raises(OptionsError, match=r"step 1 \(render\): option .legendd.: unknown option"):
        Pipeline.from_data({"steps": [{"render": {"legendd": False}}]})
    assert not (tmp_path / "out").exists()
