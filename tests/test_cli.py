"""The ``geobrep`` command line: info, plugins, demo, exit codes and the console script."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

import geobrep
from geobrep import Scene
from geobrep.cli import main
from geobrep.demo import STAGES


@pytest.fixture
def cake_file(layer_cake: Scene, tmp_path: Path) -> Path:
    return geobrep.write(layer_cake, tmp_path / "cake.geobrep")


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


class TestInfo:
    def test_text(self, cake_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, err = run(capsys, "info", str(cake_file))
        assert code == 0
        assert err == ""
        lines = out.splitlines()
        assert lines[0] == f"{cake_file}: 16 entities"
        assert lines[1] == (
            "  CRS     EPSG:32631 (axes X Y Z, units m m m, z positive up in the source)"
        )
        if importlib.util.find_spec("pyproj") is not None:  # the gis extra parses the CRS
            parsed = lines.pop(2)
            assert parsed.strip().startswith("WGS 84 / UTM zone 31N (Projected CRS; units metre")
        assert lines[2] == (
            "  bounds  x [450000.000, 451000.000]  y [6700000.000, 6700800.000]"
            "  z [-600.000, 40.000]"
        )
        assert lines[3] == "  topology  28 corners, 52 arcs, 31 patches, 6 blocks + universe"
        assert lines[4].startswith("  #0 Surface 'H1' [horizon]: ")
        assert lines[4].endswith(" vertices, 672 faces, 2 patches")
        assert "  #15 Block 'universe' [universe]: " in out

    def test_json(
        self, cake_file: Path, layer_cake: Scene, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, out, _ = run(capsys, "info", str(cake_file), "--json")
        assert code == 0
        summary = json.loads(out)
        assert summary["file"] == str(cake_file)
        assert summary["name"] == "faulted layer cake"
        assert summary["crs"]["epsg"] == 32631
        assert summary["crs"]["z_positive"] == "up"
        assert summary["bounds"] == [450000.0, 451000.0, 6700000.0, 6700800.0, -600.0, 40.0]
        assert summary["topology"] == {
            "corners": 28,
            "arcs": 52,
            "patches": 31,
            "blocks": 6,
            "universe": True,
        }
        assert summary["groups"] == ["horizons", "faults", "boundaries", "blocks"]
        entities = summary["entities"]
        assert len(entities) == 16
        assert [e["type"] for e in entities].count("Surface") == 9
        assert [e["type"] for e in entities].count("Block") == 7
        for described, entity in zip(entities, layer_cake.entities, strict=True):
            assert described["id"] == entity.id
            assert described["name"] == entity.name
            if described["type"] == "Surface":
                assert described["counts"] == {
                    "vertices": entity.n_vertices,
                    "faces": entity.n_faces,
                    "patches": entity.n_patches,
                }
        assert sum(e["counts"].get("faces", 0) for e in entities) == 4296

    def test_properties_are_listed(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        path = geobrep.write(geobrep.datasets.scattered_points(), tmp_path / "points.geobrep")
        code, out, _ = run(capsys, "info", str(path))
        assert code == 0
        assert "  CRS     none" in out
        assert "  #0 PointSet 'survey points' [horizon]: 600 vertices" in out
        assert "      point_data 'core': int8" in out
        assert "      point_data 'true_z': float64 m" in out
        code, out, _ = run(capsys, "info", str(path), "--json")
        described = json.loads(out)["entities"][0]
        assert described["point_data"][1] == {
            "name": "true_z",
            "dtype": "float64",
            "element_size": 1,
            "unit": "m",
            "no_data_value": None,
        }

    def test_explicit_format(
        self, layer_cake: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        path = geobrep.write(layer_cake, tmp_path / "model.bin", format="native")
        code, out, _ = run(capsys, "info", str(path), "--format", "native")
        assert code == 0
        assert out.startswith(f"{path}: 16 entities")


class TestPlugins:
    def test_text(self, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, _ = run(capsys, "plugins")
        assert code == 0
        native = next(line for line in out.splitlines() if line.startswith("native "))
        assert "[loaded]" in native
        assert f"geobrep {geobrep.__version__}" in native
        assert "(geobrep.adapters.native)" in native
        assert "    formats: native" in out

    def test_json(self, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, _ = run(capsys, "plugins", "--json")
        assert code == 0
        plugins = {p["name"]: p for p in json.loads(out)}
        native = plugins["native"]
        assert native["distribution"] == "geobrep"
        assert native["version"] == geobrep.__version__
        assert native["module"] == "geobrep.adapters.native"
        assert native["status"] == "loaded"
        assert native["error"] is None
        assert native["registered"]["formats"] == ["native"]


class TestDemo:
    def test_demo_writes_its_outputs(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        output = tmp_path / "demo"
        code, out, err = run(capsys, "demo", "-o", str(output))
        assert code == 0, err
        written = {p.name for p in output.iterdir()}
        assert {"layer_cake.geobrep", "summary.json", "survey_points.geobrep"} <= written
        assert {name for name, _ in STAGES} <= set(
            json.loads((output / "summary.json").read_text())
        )
        summary = json.loads((output / "summary.json").read_text())
        assert summary["model"]["blocks"] == 6
        assert summary["model"]["patches"] == 31
        assert summary["model"]["crs"] == "EPSG:32631"
        blocks = summary["blocks"]
        assert len(blocks) == 6
        assert all(b["closed"] and b["oriented"] and b["volume_m3"] > 0 for b in blocks)
        assert summary["volume_check"]["relative_difference"] < 1e-9
        assert summary["native"]["round_trip_identical"] is True
        assert [tuple(pair) for pair in summary["adjacency"]] == (
            geobrep.datasets.faulted_layer_cake().block_adjacency()
        )
        assert geobrep.read(output / "layer_cake.geobrep") == geobrep.datasets.faulted_layer_cake()
        points = geobrep.read(output / "survey_points.geobrep")
        assert points.entities[0].n_points == 600
        assert "model: 'faulted layer cake' (EPSG:32631): 9 surfaces" in out
        assert f"summary: {output / 'summary.json'}" in out


class TestExitCodes:
    def test_missing_file(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        path = tmp_path / "nope.geobrep"
        code, out, err = run(capsys, "info", str(path))
        assert code == 1
        assert out == ""
        assert err == f"geobrep: error: {path}: no such file\n"

    def test_unknown_format(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        path = tmp_path / "model.xyz123"
        path.write_text("1 2 3\n")
        code, _, err = run(capsys, "info", str(path))
        assert code == 1
        assert err.count("\n") == 1
        assert err.startswith(f"geobrep: error: {path}: no installed format can read this file")
        assert "native (.geobrep" in err

    def test_corrupt_file(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        path = tmp_path / "bad.geobrep"
        path.write_bytes(b"not a zip")
        code, _, err = run(capsys, "info", str(path))
        assert code == 1
        assert err.startswith(f"geobrep: error: {path}: not a readable .geobrep container")

    @pytest.mark.parametrize(
        "args", [[], ["bogus"], ["info"], ["info", "a", "b"], ["plugins", "--nope"]]
    )
    def test_usage_errors(self, args: list[str], capsys: pytest.CaptureFixture[str]) -> None:
        code, out, err = run(capsys, *args)
        assert code == 2
        assert out == ""
        assert "usage: geobrep" in err

    def test_version_and_help(self, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, _ = run(capsys, "--version")
        assert code == 0
        assert out == f"geobrep {geobrep.__version__}\n"
        code, out, _ = run(capsys, "--help")
        assert code == 0
        assert "info" in out
        assert "plugins" in out
        assert "demo" in out

    def test_internal_error(
        self, cake_file: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
    ) -> None:
        def broken(*args: object, **kwargs: object) -> None:
            raise RuntimeError("kaboom")

        monkeypatch.setattr("geobrep.cli.info.read", broken)
        monkeypatch.delenv("GEOBREP_TRACEBACK", raising=False)
        code, _, err = run(capsys, "info", str(cake_file))
        assert code == 70
        assert err == (
            "geobrep: internal error: RuntimeError: kaboom "
            "(set GEOBREP_TRACEBACK=1 to see the traceback)\n"
        )
        monkeypatch.setenv("GEOBREP_TRACEBACK", "1")
        code, _, err = run(capsys, "info", str(cake_file))
        assert code == 70
        assert "Traceback (most recent call last)" in err

    def test_interrupt(
        self, cake_file: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
    ) -> None:
        def interrupted(*args: object, **kwargs: object) -> None:
            raise KeyboardInterrupt

        monkeypatch.setattr("geobrep.cli.info.read", interrupted)
        code, _, err = run(capsys, "info", str(cake_file))
        assert code == 130
        assert err == "geobrep: interrupted\n"


class TestConsoleScript:
    def test_installed_script(self) -> None:
        script = Path(sys.executable).parent / "geobrep"
        assert script.exists(), f"console script missing: {script}"
        result = subprocess.run(
            [str(script), "--version"], capture_output=True, text=True, timeout=60, check=False
        )
        assert result.returncode == 0, result.stderr
        assert result.stdout == f"geobrep {geobrep.__version__}\n"

    def test_module_entry_point(self, tmp_path: Path) -> None:
        result = subprocess.run(
            [sys.executable, "-m", "geobrep.cli", "info", str(tmp_path / "missing.geobrep")],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert result.returncode == 1
        assert result.stderr.startswith("geobrep: error: ")
        assert result.stderr.count("\n") == 1
