"""The command line tells the truth briefly (issue 12, item 7), on the GOCAD files of tests/data.

Warnings are short ``warning:`` lines grouped by kind (``-q`` hides them, ``-v`` shows each); a
local GOCAD CRS is named as such; errors name the user's file, never the temporary one, nor a raw
SQLite message; unknown formats and options are named with a close match and the command's own
usage; a result with nothing in it is a warning and exit 4 unless ``--allow-empty``.
"""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import Scene
from geobrep.cli import main
from geobrep.cli.common import EXIT_EMPTY
from geobrep.cli.main import COMMAND_MODULES
from geobrep.geometry import Plane
from geobrep.ops.clipping import clip

DATA = Path(__file__).parents[1] / "data" / "gocad"
MODEL_A1 = DATA / "modelA1.ml"
MODEL_A4 = DATA / "modelA4.ml"
#: Python's own warning display: "path.py:123: SomeWarning: message" then the source line.
PYTHON_WARNING = re.compile(r"\.py:\d+: \w*Warning: |warnings\.warn\(|Traceback")


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def api_warnings(tmp_path: Path) -> list[str]:
    """The warnings the library itself raises for ``clip modelA4.ml --x 1000 --keep both``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = geobrep.read(MODEL_A4)
        negative, positive = clip(scene, Plane.x(1000.0), keep="both")
        geobrep.write(negative, tmp_path / "api-negative.ml")
        geobrep.write(positive, tmp_path / "api-positive.ml")
    return [str(w.message) for w in caught]


class TestWarnings:
    def test_grouped_by_kind_with_a_count(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        expected = api_warnings(tmp_path)
        assert len(expected) > 5  # several kinds, several of one kind
        code, _, err = run(
            capsys, "clip", MODEL_A4, tmp_path / "cut.ml", "--x", "1000", "--keep", "both"
        )
        assert code == 0, err
        lines = err.splitlines()
        assert lines
        assert all(line.startswith("warning: ") for line in lines), err
        assert not PYTHON_WARNING.search(err)
        assert len(lines) < len(expected)  # grouped
        counted = 0
        for line in lines:
            more = re.search(r" \(and (\d+) more like it; -v shows each\)$", line)
            counted += 1 + (int(more.group(1)) if more else 0)
        assert counted == len(expected)
        assert "warning: modelA4.ml:306: FAULT_BLOCK 'no_fault_block_name'" in err

    def test_verbose_shows_each(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        expected = api_warnings(tmp_path)
        code, _, err = run(
            capsys, "clip", MODEL_A4, tmp_path / "cut.ml", "--x", "1000", "--keep", "both", "-v"
        )
        assert code == 0, err
        assert sorted(err.splitlines()) == sorted(f"warning: {m}" for m in expected)

    @pytest.mark.parametrize("where", ["before", "after"])
    def test_quiet_hides_them(
        self, where: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        args = ["clip", str(MODEL_A4), str(tmp_path / "cut.ml"), "--x", "1000"]
        code, out, err = run(capsys, *(["-q", *args] if where == "before" else [*args, "-q"]))
        assert code == 0
        assert err == ""
        assert out.startswith(f"{tmp_path / 'cut.ml'}: ")

    def test_verbose_before_the_command(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, _, err = run(capsys, "-v", "convert", MODEL_A4, tmp_path / "a4.vtu")
        assert code == 0
        assert err.splitlines() == [
            "warning: modelA4.ml:306: FAULT_BLOCK 'no_fault_block_name': id 65 does not match "
            "a REGION"
        ]


class TestLocalCrs:
    @pytest.mark.parametrize(
        ("name", "crs"), [("modelA1.ml", "Default"), ("normal_lines.pl", "SKUA Local")]
    )
    def test_named_as_local(self, name: str, crs: str, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, err = run(capsys, "info", DATA / name)
        assert code == 0, err
        assert f"local (engineering) CRS {crs!r}, not georeferenced" in out
        assert "pyproj" not in out
        code, out, _ = run(capsys, "info", DATA / name, "--json")
        assert json.loads(out)["crs_parsed"]["local"] is True

    def test_a_georeferenced_crs_is_still_parsed(
        self, layer_cake: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        pytest.importorskip("pyproj")
        path = geobrep.write(layer_cake, tmp_path / "cake.geobrep")
        code, out, _ = run(capsys, "info", path)
        assert code == 0
        assert "WGS 84 / UTM zone 31N" in out
        assert "local (engineering)" not in out


class TestErrorsNameTheTarget:
    def test_writer_error_names_the_target(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        pytest.importorskip("pyogrio")
        target = tmp_path / "section.shp"
        code, _, err = run(capsys, "section", MODEL_A1, target, "--x", "1000")
        assert code == 1
        assert err.startswith(f"geobrep: error: {target}: a shapefile holds one layer")
        assert ".tmp-" not in err
        with pytest.raises(geobrep.FormatError) as caught:
            geobrep.write(
                geobrep.ops.clipping.section(geobrep.read(MODEL_A1), Plane.x(1000.0)), target
            )
        assert caught.value.path == target
        assert list(tmp_path.iterdir()) == []

    @pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
    @pytest.mark.parametrize("name", ["out.geobrep", "out.vtu", "out.ml"])
    def test_nested_temporary_names(self, name: str, capsys: pytest.CaptureFixture[str]) -> None:
        target = Path("/proc") / name  # no file can be created there, even by root
        code, _, err = run(
            capsys, "reproject", MODEL_A1, target, "--to", "EPSG:32631", "--from", "EPSG:32631"
        )
        assert code == 1
        assert err.splitlines()[-1].startswith(f"geobrep: error: {target}: ")
        assert ".tmp-" not in err

    @pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
    def test_geopackage_failure_in_words(self, capsys: pytest.CaptureFixture[str]) -> None:
        pytest.importorskip("pyogrio")
        target = Path("/proc/section.gpkg")
        code, _, err = run(capsys, "section", MODEL_A1, target, "--x", "1000")
        assert code == 1
        assert err == (
            f"geobrep: error: {target}: cannot write the GeoPackage file: the file cannot be "
            "created in its folder (is the folder writable?)\n"
        )


class TestUnknownNames:
    def test_unknown_format(self, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
        code, out, err = run(capsys, "convert", MODEL_A1, "--to", "vtuu", "-o", tmp_path / "out")
        assert code == 2
        assert out == ""
        assert "usage: geobrep convert" in err
        assert "argument --to: unknown format 'vtuu' (known: " in err
        assert "did you mean 'vtu'?" in err
        assert "x.vtuu" not in err
        assert not (tmp_path / "out").exists()

    def test_unknown_output_format(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, _, err = run(
            capsys, "clip", MODEL_A1, tmp_path / "c", "--x", "0", "--output-format", "gocadd"
        )
        assert code == 2
        assert "unknown format 'gocadd'" in err
        assert "did you mean 'gocad'?" in err

    @pytest.mark.parametrize(
        ("args", "option", "close"),
        [
            (["clip", "in.ml", "out.ml", "--xx", "3"], "--xx", "--x"),
            (["voxelize", "in.ml", "out.geobrep", "--depht", "3"], "--depht", "--depth"),
            (
                ["section", "in.ml", "out.gpkg", "--x", "1", "--tolerence", "1"],
                "--tolerence",
                "--tolerance",
            ),
        ],
    )
    def test_unknown_option_is_named(
        self, args: list[str], option: str, close: str, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, out, err = run(capsys, *args)
        assert code == 2
        assert out == ""
        assert f"usage: geobrep {args[0]} " in err
        assert err.rstrip().endswith(
            f"geobrep {args[0]}: error: unknown option {option!r} (did you mean {close!r}?)"
        )

    @pytest.mark.parametrize("command", COMMAND_MODULES)
    def test_every_command(self, command: str, capsys: pytest.CaptureFixture[str]) -> None:
        code, _, err = run(capsys, command, "--no-such-option")
        assert code == 2
        assert f"usage: geobrep {command}" in err
        assert f"geobrep {command}: error: unknown option '--no-such-option'" in err

    def test_leftover_argument_with_the_command_usage(
        self, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, _, err = run(capsys, "info", "a", "b")
        assert code == 2
        assert err.startswith("usage: geobrep info ")
        assert "geobrep info: error: unrecognized arguments: b" in err


class TestEmptyResults:
    def test_clip_plane_missing_the_model(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        target = tmp_path / "east.ml"
        code, out, err = run(
            capsys, "-q", "clip", MODEL_A1, target, "--x", "1e9", "--keep", "positive"
        )
        assert code == EXIT_EMPTY
        assert out == ""
        assert err.startswith(
            f"warning: {target}: nothing on the positive side of the plane x = 1e+09"
        )
        assert "no file written (--allow-empty accepts it)" in err
        assert not target.exists()
        code, _, err = run(
            capsys, "clip", MODEL_A1, target, "--x", "1e9", "--keep", "positive", "--allow-empty"
        )
        assert code == 0
        assert "warning: " in err
        assert "no file written" not in err
        assert geobrep.read(target).bounds is None

    def test_clip_both_with_one_side_empty(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, _, err = run(
            capsys, "clip", MODEL_A1, tmp_path / "c.ml", "--x", "-1e9", "--keep", "both"
        )
        assert code == EXIT_EMPTY
        assert f"{tmp_path / 'c-negative.ml'}: nothing on the negative side" in err
        assert list(tmp_path.iterdir()) == []

    def test_plane_that_keeps_everything_is_said(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        code, _, err = run(capsys, "clip", MODEL_A1, tmp_path / "c.ml", "--x", "1e9")
        assert code == 0
        assert "the plane x = 1e+09 does not meet the model" in err

    def test_section_touching_nothing(
        self, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        target = tmp_path / "s.geobrep"
        code, _, err = run(capsys, "section", MODEL_A1, target, "--z", "1e6")
        assert code == EXIT_EMPTY
        assert f"warning: {target}: the plane z = 1e+06 touches nothing" in err
        assert not target.exists()
        code, out, _ = run(capsys, "section", MODEL_A1, target, "--z", "1e6", "--allow-empty")
        assert code == 0
        assert out == f"{target}: 0 block sections, 0 traces\n"

    @pytest.mark.parametrize("command", ["convert", "info"])
    def test_empty_scene_read(
        self, command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
    ) -> None:
        source = geobrep.write(Scene(), tmp_path / "nothing.geobrep")
        args = [command, str(source)] + (
            [str(tmp_path / "x.geobrep")] if command == "convert" else []
        )
        code, _, err = run(capsys, *args)
        assert code == EXIT_EMPTY
        assert "warning: " in err
        assert "nothing read" in err
        code, _, _ = run(capsys, *args, "--allow-empty")
        assert code == 0


def _points_csv(path: Path) -> Path:
    rng = np.random.default_rng(7)
    xy = rng.uniform(0.0, 100.0, size=(80, 2))
    z = 0.2 * xy[:, 0] - 0.1 * xy[:, 1] + 5.0
    rows = "\n".join(
        f"{float(x)!r},{float(y)!r},{float(v)!r}" for (x, y), v in zip(xy, z, strict=True)
    )
    path.write_text("x,y,z\n" + rows + "\n")
    return path


@pytest.mark.slow
def test_no_python_warning_text_on_stderr(tmp_path: Path) -> None:
    """Every command on the real files: warnings only as ``warning:`` lines, never Python's."""
    points = _points_csv(tmp_path / "points.csv")
    pipeline = tmp_path / "west.yaml"
    pipeline.write_text(
        f"version: 1\ninputs: [{MODEL_A1}]\noutput: {tmp_path / 'run'}\nsteps:\n"
        "  - read: {}\n  - clip: {plane: [1, 0, 0, -1000], keep: negative}\n"
        '  - write: {format: gocad, name: "{stem}_west.ml"}\n'
    )
    commands = {
        "info": ["info", MODEL_A4],
        "convert": ["convert", MODEL_A1, tmp_path / "a1.vtu"],
        "clip": ["clip", MODEL_A4, tmp_path / "cut.ml", "--x", "1000", "--keep", "both"],
        "section": ["section", MODEL_A1, tmp_path / "section.gpkg", "--x", "1000"],
        "blocks": ["blocks", MODEL_A1, tmp_path / "blocks.ml"],
        "voxelize": ["voxelize", MODEL_A1, tmp_path / "octree.geobrep", "--depth", "4"],
        "fit": ["fit", points, tmp_path / "fit.ts", "--method", "approximation"],
        "reproject": [
            "reproject",
            MODEL_A1,
            tmp_path / "moved.ml",
            "--to",
            "EPSG:32631",
            "--from",
            "EPSG:32631",
        ],
        "run": ["run", pipeline],
        "plugins": ["plugins"],
        "view": ["view", MODEL_A1, "-o", tmp_path / "model.html"],
    }
    if importlib.util.find_spec("pyvista") is not None:
        commands["render"] = ["render", MODEL_A1, tmp_path / "model.png"]
    script = Path(sys.executable).parent / "geobrep"
    started = {
        name: subprocess.Popen(
            [str(script), *map(str, args)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=tmp_path,
        )
        for name, args in commands.items()
    }
    results = {name: process.communicate(timeout=300) for name, process in started.items()}
    for name, (_, err) in results.items():
        assert started[name].returncode == 0, f"{name}: {err}"
        assert not PYTHON_WARNING.search(err), f"{name}:\n{err}"
        stray = [line for line in err.splitlines() if not line.startswith("warning: ")]
        assert stray == [], f"{name}: {stray}"
    assert "warning: modelA4.ml:306: FAULT_BLOCK" in results["info"][1]
    assert "more like it; -v shows each" in results["clip"][1]


def test_convert_to_an_extension_writes_that_extension(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--to ml`` writes a Model3d (blocks kept), not the gocad format's first extension."""
    code, _, _ = run(capsys, "convert", MODEL_A1, "--to", "ml", "-o", tmp_path / "out")
    assert code == 0
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == ["modelA1.ml"]
    assert len(geobrep.read(tmp_path / "out" / "modelA1.ml").blocks) == 4


def test_fit_names_an_unknown_input_format(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    points = DATA / "points.vs"
    code, _, err = run(capsys, "fit", points, tmp_path / "x.ts", "--format", "gocadd")
    assert code == 2
    assert "unknown format 'gocadd'" in err
    assert "did you mean 'gocad'" in err
