"""``geobrep blocks IN... OUT``."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from blocks_models import box_model, vertical_fault

import geobrep
from geobrep import Block, Scene
from geobrep.cli import main
from geobrep.model.crs import CRS


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def split_cake(layer_cake: Scene, folder: Path) -> list[Path]:
    """The sample's surfaces in two native files, without their patches or blocks."""
    bare = [s.replace(patch_labels=None, patch_names=()) for s in layer_cake.surfaces]
    first = geobrep.write(Scene(entities=bare[:4], crs=layer_cake.crs), folder / "a.geobrep")
    second = geobrep.write(Scene(entities=bare[4:], crs=layer_cake.crs), folder / "b.geobrep")
    return [first, second]


def test_several_files_merge_into_one_model(
    layer_cake: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = split_cake(layer_cake, tmp_path)
    output = tmp_path / "model.geobrep"
    code, out, err = run(capsys, "blocks", *map(str, inputs), str(output))
    assert (code, err) == (0, "")
    assert out.splitlines()[0] == "6 blocks + universe, 31 patches, 52 arcs, 28 corners"
    assert f"wrote {output}" in out
    built = geobrep.read(output)
    assert len(built.blocks) == 6
    assert built.crs == layer_cake.crs
    assert sorted(s.name for s in built.surfaces) == sorted(s.name for s in layer_cake.surfaces)


def test_ts_files_in_model3d_out(
    layer_cake: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = []
    for surface in layer_cake.surfaces:
        bare = surface.replace(patch_labels=None, patch_names=())
        inputs.append(geobrep.write(Scene(entities=[bare]), tmp_path / f"{surface.name}.ts"))
    output = tmp_path / "model.ml"
    code, _, err = run(capsys, "blocks", *map(str, inputs), str(output))
    assert code == 0, err
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        again = geobrep.read(output)
    assert len(again.blocks) == 6
    assert again.universe is not None
    volumes = sorted(again.block_mesh(b).volume for b in again.blocks)
    expected = sorted(layer_cake.block_mesh(b).volume for b in layer_cake.blocks)
    assert volumes == pytest.approx(expected, rel=1e-9)


def test_json_report_and_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    surfaces = [*box_model(extra_rows=(0.75,)), vertical_fault(0.5, [0, 0.25, 0.5, 0.75])]
    source = geobrep.write(Scene(entities=surfaces), tmp_path / "dying.geobrep")
    report_file = tmp_path / "report.json"
    code, out, _ = run(
        capsys, "blocks", str(source), str(tmp_path / "out.geobrep"),
        "--free-borders", "remove", "--report", str(report_file), "--json",
    )  # fmt: skip
    assert code == 0
    printed = json.loads(out)
    assert printed["output"] == str(tmp_path / "out.geobrep")
    assert printed["report"]["blocks"] == 3
    assert [d["reason"] for d in printed["report"]["dangling"]] == ["free border"]
    assert json.loads(report_file.read_text()) == printed["report"]


def test_errors_exit_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Non-conformal: a horizon meeting walls that have no row at its height.
    side = box_model(levels=())
    bad = box_model(levels=(0.6,))[-1]
    source = geobrep.write(Scene(entities=[*side, bad]), tmp_path / "bad.geobrep")
    output = tmp_path / "out.geobrep"
    code, out, err = run(capsys, "blocks", str(source), str(output))
    assert code == 1
    assert out == ""
    assert err.startswith("geobrep: error: non-conformal input:")
    assert len(err.strip().splitlines()) == 1
    assert not output.exists()  # nothing half-written
    # Inputs in different CRSs are not merged silently.
    first = geobrep.write(Scene(entities=side[:3], crs=CRS(epsg=32631)), tmp_path / "a.geobrep")
    second = geobrep.write(Scene(entities=side[3:], crs=CRS(epsg=32632)), tmp_path / "b.geobrep")
    code, _, err = run(capsys, "blocks", str(first), str(second), str(output))
    assert code == 1
    assert "differs from that of" in err
    code, _, err = run(capsys, "blocks", str(tmp_path / "missing.ts"), str(output))
    assert code == 1
    assert "no such file" in err


def test_merge_keeps_groups_and_drops_old_blocks(layer_cake: Scene) -> None:
    from geobrep.cli.blocks import merge_scenes

    merged = merge_scenes([layer_cake, layer_cake], ["one", "two"])
    assert len(merged.entities) == 2 * len(layer_cake.surfaces)
    assert not merged.of_type(Block)
    horizons = [g for g in merged.groups if g.name == "horizons"]
    assert len(horizons) == 2
    assert {merged[m].name for g in horizons for m in g.members} == {"H1", "H2"}
