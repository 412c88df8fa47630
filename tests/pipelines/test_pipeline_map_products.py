"""The map products operation: ``geobrep map`` and the ``map_products`` step give what
:func:`geobrep.map_products` gives."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.batch.pipeline_run import run_pipeline
from geobrep.cli.main import main
from geobrep.geometry import Plane

pytest.importorskip("shapely")

PLANE = [1.0, 0.0, 0.0, -450500.0]


def _fingerprint(scene: geobrep.Scene) -> list[tuple[str, str | None, object]]:
    return [(e.type, e.name, e.metadata.get("layer")) for e in scene.entities]


def _same_products(scene: geobrep.Scene, expected: geobrep.Scene) -> None:
    assert _fingerprint(scene) == _fingerprint(expected)
    for got, want in zip(scene.entities, expected.entities, strict=True):
        assert np.allclose(got.vertices, want.vertices, rtol=0, atol=1e-6), got.label
    assert scene.crs == expected.crs


def test_command_and_step_give_the_products_of_the_function(
    cake_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cake = geobrep.read(cake_file)
    expected = geobrep.map_products(cake, section_levels=[-150.0], section_planes=[Plane(*PLANE)])
    layers = {e.metadata["layer"] for e in expected.entities}
    assert layers == {"block_outlines", "traces", "sections", "sections_plane"}
    argv = ["map", str(cake_file), str(tmp_path / "cli.geobrep"), "--section-levels", "-150",
            "--section-plane", ",".join(map(str, PLANE))]  # fmt: skip
    assert main(argv) == 0
    assert f"{len(expected.entities)} map products (block_outlines" in capsys.readouterr().out
    _same_products(geobrep.read(tmp_path / "cli.geobrep"), expected)
    step = {"map_products": {"section_levels": [-150], "section_planes": [PLANE]}}
    summary = run_pipeline(
        {"steps": [step, {"write": {"format": "native"}}]},
        inputs=[cake_file],
        output=tmp_path / "out",
    )
    assert summary.ok, summary.table()
    assert "block_outlines" in summary.reports[0].steps[1].notes[0]
    _same_products(geobrep.read(tmp_path / "out" / "cake.geobrep"), expected)


def test_top_none_leaves_out_the_traces(cake_file: Path, tmp_path: Path) -> None:
    assert main(["map", str(cake_file), str(tmp_path / "m.geobrep"), "--top", "none"]) == 0
    products = geobrep.read(tmp_path / "m.geobrep")
    expected = geobrep.map_products(geobrep.read(cake_file), top=None)
    _same_products(products, expected)
    assert {e.metadata["layer"] for e in products.entities} == {"block_outlines"}


def test_bad_options_are_errors(cake_file: Path, tmp_path: Path) -> None:
    out = str(tmp_path / "m.geobrep")
    assert main(["map", str(cake_file), out, "--section-plane", "1,0,0"]) == 2  # usage
    assert main(["map", str(cake_file), out, "--section-coordinates", "sky"]) == 2
    assert main(["map", str(cake_file), out, "--top", "no_such_surface"]) == 1
    assert not Path(out).exists()
