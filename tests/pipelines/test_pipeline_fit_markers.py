"""Pipelines fit horizons to scattered points with well markers, as ``geobrep fit`` does.

The well files are relative to the pipeline's folder and confined to it: an absolute path or a
``..`` part is refused when the pipeline is loaded, a symlink that leads out when it is read.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import WellMarker
from geobrep.batch.operations import operations, read_wells
from geobrep.cli.main import main
from geobrep.errors import FileAccessError, FormatError, OptionsError

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "fit"))
from test_fit_markers import MIXED_WELLS


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """A pipeline folder: the survey points and the wells under wells/, the two in the core as
    GOCAD .wl files (a .wl marker names no surface: its name is the surface's), the one in the
    rim as .geobrep."""
    folder = tmp_path / "project"
    (folder / "wells").mkdir(parents=True)
    geobrep.write(geobrep.datasets.scattered_points(), folder / "points.geobrep")
    for well, name in zip(MIXED_WELLS, WELL_FILES, strict=True):
        if name.endswith(".wl"):
            top, base = well.markers
            well = well.replace(markers=(WellMarker(name="dome", md=top.md),
                                         WellMarker(name="base", md=base.md)))  # fmt: skip
        geobrep.write(geobrep.Scene(entities=[well]), folder / name)
    return folder


WELL_FILES = ["wells/C1.wl", "wells/C2.wl", "wells/W1.geobrep"]
FIT = (
    "  - fit: {method: hybrid, options: {epsilon: 0.5, core_property: core},\n"
    "          markers: [" + ", ".join(WELL_FILES) + "], marker_surface: dome,\n"
    "          marker_weight: WEIGHT}\n"
)


def _pipeline(folder: Path, weight: str = "hard", fit: str = FIT) -> Path:
    path = folder / "pipeline.yaml"
    path.write_text(
        "inputs: [points.geobrep]\noutput: out\nsteps:\n"
        + fit.replace("WEIGHT", weight)
        + "  - write: {name: '{stem}_top.geobrep'}\n",
        encoding="utf-8",
    )
    return path


def _misfit(surface: geobrep.NurbsSurface, folder: Path) -> np.ndarray:
    """|distance| of each well's first (dome) marker to ``surface``."""
    from geobrep.plugins.fit.distance import surface_distances

    wells = read_wells(WELL_FILES, folder)
    where = np.concatenate([w.marker_positions()[:1] for w in wells])
    return np.abs(surface_distances(surface, where))


def _surface(path: Path) -> geobrep.NurbsSurface:
    (surface,) = geobrep.read(path).entities
    assert isinstance(surface, geobrep.NurbsSurface)
    return surface


def test_a_pipeline_fit_with_markers_is_the_cli_fit(
    project: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(tmp_path)  # the well files are found from the pipeline's folder
    summary = geobrep.run_pipeline(_pipeline(project))
    assert summary.ok, summary.table()
    (report,) = summary.reports
    notes = [note for step in report.steps for note in step.notes]
    assert any("3 well marker(s)" in note for note in notes), notes
    piped = _surface(project / "out" / "points_top.geobrep")
    monkeypatch.chdir(project)
    code = main(["fit", "points.geobrep", str(tmp_path / "cli.geobrep"), "--method", "hybrid",
                 "--option", "epsilon=0.5", "--option", "core_property=core",
                 "--markers", *WELL_FILES, "--marker-surface", "dome",
                 "--marker-weight", "hard"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    cli = _surface(tmp_path / "cli.geobrep")
    assert np.array_equal(piped.control_points, cli.control_points)
    assert np.array_equal(piped.knots_u, cli.knots_u)
    assert np.array_equal(piped.knots_v, cli.knots_v)
    misfit = _misfit(piped, project)
    assert misfit.max() < 1e-6  # two markers in the skinned core, one in the rim


def test_weighted_markers_in_a_pipeline_pull_the_surface(project: Path) -> None:
    plain = "  - fit: {method: hybrid, options: {epsilon: 0.5, core_property: core}}\n"
    assert geobrep.run_pipeline(_pipeline(project, fit=plain)).ok
    without = _misfit(_surface(project / "out" / "points_top.geobrep"), project)
    assert geobrep.run_pipeline(_pipeline(project, weight="100")).ok
    weighted = _misfit(_surface(project / "out" / "points_top.geobrep"), project)
    assert np.all(weighted < without / 5)


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("../wells/W1.wl", "leaves the pipeline's folder"),
        ("wells/../../W1.wl", "leaves the pipeline's folder"),
        ("/etc/passwd", "is not a path relative to the pipeline's folder"),
    ],
)
def test_a_well_file_outside_the_folder_is_refused_on_load(
    project: Path, path: str, message: str
) -> None:
    fit = FIT.replace(WELL_FILES[0], path)
    with pytest.raises(OptionsError, match=f"step 1 \\(fit\\): markers: '{path}' {message}"):
        geobrep.Pipeline.load(_pipeline(project, fit=fit))


def test_a_symlink_out_of_the_folder_fails_the_input(project: Path, tmp_path: Path) -> None:
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    geobrep.write(geobrep.Scene(entities=[MIXED_WELLS[0]]), outside / "W.wl")
    (project / "wells" / "link.wl").symlink_to(outside / "W.wl")
    summary = geobrep.run_pipeline(
        _pipeline(project, fit=FIT.replace(WELL_FILES[0], "wells/link.wl"))
    )
    (report,) = summary.reports
    assert report.status == "failed"
    assert "outside the pipeline's folder" in str(report.error)
    assert not (project / "out" / "points_top.geobrep").exists()


def test_a_missing_well_file_is_an_error_naming_it(project: Path) -> None:
    fit = FIT.replace(WELL_FILES[1], "wells/W9.wl")
    summary = geobrep.run_pipeline(_pipeline(project, fit=fit))
    (report,) = summary.reports
    assert report.status == "failed"
    assert report.failed_step == 1
    assert "wells/W9.wl" in str(report.error)
    assert "no such well file" in str(report.error)


def test_read_wells_errors(project: Path) -> None:
    with pytest.raises(FileAccessError, match="no such well file"):
        read_wells(["wells/none.wl"], project)
    with pytest.raises(FileAccessError, match="leaves the pipeline's folder"):
        read_wells(["../x.wl"], project)
    with pytest.raises(FormatError, match="holds no well"):
        read_wells(["points.geobrep"], project)
    assert [w.name for w in read_wells([str(project / WELL_FILES[2])])] == ["W1"]


def test_marker_options_need_markers() -> None:
    with pytest.raises(OptionsError, match="need markers"):
        geobrep.Pipeline.from_data(
            {"steps": [{"fit": {"marker_surface": "dome"}}, {"write": {"format": "native"}}]}
        )


def test_the_fit_operation_reads_markers_from_the_working_folder(
    project: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(project)
    scene = geobrep.read("points.geobrep")
    fitted = operations().get("fit")(
        scene, method="hybrid", options={"epsilon": 0.5, "core_property": "core"},
        markers=WELL_FILES, marker_surface="dome", marker_weight="hard",
    )  # fmt: skip
    (surface,) = fitted.entities
    assert isinstance(surface, geobrep.NurbsSurface)
    assert _misfit(surface, project).max() < 1e-6
    with pytest.raises(FileAccessError, match="leaves the pipeline's folder"):
        operations().get("fit")(scene, markers=["../W1.wl"], marker_surface="dome")


def test_worker_processes_find_the_well_files(
    project: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    geobrep.write(geobrep.datasets.scattered_points(seed=1), project / "points_b.geobrep")
    path = _pipeline(project)
    path.write_text(
        path.read_text(encoding="utf-8").replace("[points.geobrep]", "[points*.geobrep]"),
        encoding="utf-8",
    )
    summary = geobrep.run_pipeline(path, jobs=2)
    assert summary.ok, summary.table()
    for name in ("points_top.geobrep", "points_b_top.geobrep"):
        assert _misfit(_surface(project / "out" / name), project).max() < 1e-6
