"""``fit`` facade, the registered fitters, the ``geobrep fit`` command and the demo stage."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import NurbsSurface, PointSet, Scene
from geobrep.cli import main
from geobrep.demo import DemoContext
from geobrep.errors import EntityValidationError, FormatError, OptionsError, PluginError
from geobrep.host.registry import UnknownItemError
from geobrep.ops.fitting import FitReport, FitResult, demo_stage, fit
from geobrep.plugins import FitterSpec, list_plugins, registries


def test_builtin_fitters_are_registered() -> None:
    fitters = registries().fitters
    assert {"skinning", "approximation", "kriging", "hybrid"} <= set(fitters.names())
    info = next(p for p in list_plugins() if p.name == "fit")
    assert info.status == "loaded"
    assert set(info.registered["fitters"]) == {"skinning", "approximation", "kriging", "hybrid"}
    schema = fitters.get("kriging").options.model_json_schema()
    assert {"variogram_model", "variogram_parameters", "gridx", "gridy"} <= set(
        schema["properties"]
    )


def test_fit_takes_arrays_and_pointsets() -> None:
    points = geobrep.datasets.scattered_points(n_core=64, n_rim=100)
    from_array = fit(np.asarray(points.vertices), method="approximation", epsilon=1.0)
    from_set = fit(points, method="approximation", epsilon=1.0)
    assert isinstance(from_array, FitResult)
    assert isinstance(from_array.report, FitReport)
    np.testing.assert_array_equal(
        from_array.surface.control_points, from_set.surface.control_points
    )
    assert from_set.method == "approximation"
    assert from_set.report.method == "approximation"


def test_fit_errors_name_the_problem() -> None:
    points = geobrep.datasets.scattered_points(n_core=64, n_rim=100)
    with pytest.raises(UnknownItemError, match=r"unknown fitter 'spline'.*approximation"):
        fit(points, method="spline")
    with pytest.raises(OptionsError, match="option 'epsilon'"):
        fit(points, method="hybrid", epsilon="tight")
    with pytest.raises(OptionsError, match="option 'variogram_modle': unknown option"):
        fit(points, method="kriging", variogram_modle="gaussian")
    with pytest.raises(EntityValidationError, match=r"points: expected shape \(N, 3\)"):
        fit(np.zeros((5, 2)), method="approximation")
    with pytest.raises(EntityValidationError, match="not an array of numbers"):
        fit([["a", "b", "c"]], method="approximation")
    with pytest.raises(EntityValidationError, match=r"expected an .* not a Surface"):
        fit(geobrep.datasets.faulted_layer_cake()["fault"], method="approximation")


def test_a_third_party_fitter_returning_a_bare_surface() -> None:
    class Plugin:
        @geobrep.plugins.hookimpl
        def geobrep_register_fitters(self, registry):  # type: ignore[no-untyped-def]
            def corners(entities, options):  # type: ignore[no-untyped-def]
                v = entities[0].vertices
                net = np.stack(
                    [[v.min(0), v.min(0) + np.array([0.0, 1.0, 0.0])], [v.max(0), v.max(0)]]
                )
                return NurbsSurface(
                    degree_u=1,
                    degree_v=1,
                    knots_u=[0, 0, 1, 1],
                    knots_v=[0, 0, 1, 1],
                    control_points=net,
                )

            def broken(entities, options):  # type: ignore[no-untyped-def]
                return 42

            registry.add(FitterSpec(name="corners", function=corners))
            registry.add(FitterSpec(name="broken", function=broken))

    from geobrep.host import loader as plugin_loader

    previous = plugin_loader.set_host(None)
    try:
        geobrep.plugins.register(Plugin(), "test-corners")
        result = fit(np.random.default_rng(0).uniform(size=(10, 3)), method="corners")
        assert result.report is None
        assert isinstance(result.surface, NurbsSurface)
        with pytest.raises(PluginError, match="returned a int"):
            fit(np.zeros((3, 3)) + np.eye(3), method="broken")
    finally:
        plugin_loader.set_host(previous)


def test_report_text_and_json() -> None:
    result = fit(
        geobrep.datasets.scattered_points(), method="hybrid", epsilon=0.5, core_property="core"
    )
    report = result.report
    assert report is not None
    text = report.to_text()
    assert "accuracy of the hybrid against ε = 0.5: PASSED" in text
    assert "core   n =    300" in text
    assert "seam gap" in text
    again = FitReport.model_validate_json(report.model_dump_json())
    assert again == report


@pytest.fixture
def survey_csv(tmp_path: Path) -> Path:
    points = geobrep.datasets.scattered_points()
    path = tmp_path / "survey.csv"
    data = np.column_stack([points.vertices, points.point_data["core"].values])
    np.savetxt(path, data, delimiter=",", header="X,Y,Z,core", comments="", fmt="%.17g")
    return path


class TestCommandLine:
    def test_hybrid_fit_from_csv(
        self, survey_csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        out = tmp_path / "horizon.geobrep"
        report_file = tmp_path / "report.json"
        code = main(
            [
                "fit",
                str(survey_csv),
                str(out),
                "--method",
                "hybrid",
                "--epsilon",
                "0.5",
                "--option",
                "core_property=core",
                "--report",
                str(report_file),
            ]
        )
        stdout = capsys.readouterr().out
        assert code == 0
        assert "hybrid fit of 600 points" in stdout
        assert "PASSED" in stdout
        surface = geobrep.read(out).entities[0]
        assert isinstance(surface, NurbsSurface)
        saved = json.loads(report_file.read_text())
        assert saved["passed"] is True
        assert saved["subsets"]["core"]["n"] == 300

    def test_json_check_and_other_formats(
        self, survey_csv: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        out = tmp_path / "a.geobrep"
        code = main(
            [
                "fit",
                str(survey_csv),
                str(out),
                "--method",
                "approximation",
                "--epsilon",
                "0.01",
                "--json",
                "--check",
            ]
        )
        payload = json.loads(capsys.readouterr().out)
        assert code == 3
        assert payload["report"]["passed"] is False
        # a native file holding a PointSet is read through the format registry
        native = tmp_path / "survey.geobrep"
        geobrep.write(geobrep.datasets.scattered_points(), native)
        code = main(
            [
                "fit",
                str(native),
                str(tmp_path / "k.geobrep"),
                "--method",
                "kriging",
                "--option",
                "grid_size=20",
                "--option",
                'variogram_model="exponential"',
            ]
        )
        assert code == 0
        assert "kriging fit of 600 points" in capsys.readouterr().out

    def test_errors(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        bad = tmp_path / "bad.csv"
        bad.write_text("x,y,z\n1,2,3\n4,5\n7,8,9\n")
        assert main(["fit", str(bad), str(tmp_path / "o.geobrep")]) == 1
        assert f"{bad}:3: expected 3 values, found 2" in capsys.readouterr().err
        nan = tmp_path / "nan.csv"
        nan.write_text("1 2 3\n4 5 nan\n")
        assert main(["fit", str(nan), str(tmp_path / "o.geobrep")]) == 1
        assert ":2: coordinates must be finite" in capsys.readouterr().err
        assert main(["fit", str(tmp_path / "missing.csv"), str(tmp_path / "o.geobrep")]) == 1
        assert "no such file" in capsys.readouterr().err
        good = tmp_path / "good.csv"
        good.write_text("0 0 0\n1 0 0\n0 1 0\n1 1 1\n")
        assert (
            main(["fit", str(good), str(tmp_path / "o.geobrep"), "--option", "oops"]) == 2
        )  # malformed: usage
        assert "expected KEY=VALUE" in capsys.readouterr().err
        assert not (tmp_path / "o.geobrep").exists()

    def test_csv_without_header(self, tmp_path: Path) -> None:
        path = tmp_path / "p.txt"
        path.write_text("# comment\n1 2 3 9\n4;5;6;9\n\n7,8,9,9\n")
        points = geobrep.read(path).point_sets[0]
        np.testing.assert_array_equal(points.vertices[:, 0], [1.0, 4.0, 7.0])
        assert list(points.point_data) == ["column_4"]
        (tmp_path / "two.csv").write_text("1,2\n3,4\n")
        with pytest.raises(FormatError, match="need x, y, z"):
            geobrep.read(tmp_path / "two.csv")


def test_demo_stage(tmp_path: Path, layer_cake: Scene) -> None:
    ctx = DemoContext(output=tmp_path, scene=layer_cake)
    demo_stage(ctx)
    assert ctx.summary["fit"]["passed"] is True
    assert ctx.summary["fit"]["subsets"]["core"]["n"] == 300
    assert ctx.summary["fit"]["written"]["agrees"] is True  # the mesh is as accurate
    assert any("accuracy of the mesh written" in line for line in ctx.lines)
    assert any("hybrid NURBS fit of 600 survey points" in line for line in ctx.lines)
    written = geobrep.read(tmp_path / "fitted_surface.geobrep")
    kinds = sorted(type(e).__name__ for e in written.entities)
    assert kinds == ["NurbsSurface", "PointSet", "Surface"]
    json.dumps(ctx.summary)  # the summary stays JSON-ready
    assert isinstance(written.entities[1], PointSet | NurbsSurface | geobrep.Surface)
