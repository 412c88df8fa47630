"""``geobrep render``: its parser is derived from :class:`RenderCommand`, with the flags, defaults
and png-writer keywords the hand-written parser had."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import geobrep
from geobrep.cli import render
from geobrep.cli.main import build_parser, main

FLAGS = {
    "--format", "--color-by", "--property", "--clip-origin", "--clip-normal", "--section-origin",
    "--section-normal", "--view", "--azimuth", "--elevation", "--title", "--no-legend",
    "--no-axes", "--no-scale-bar", "--size", "--edges", "--vertical-exaggeration",
    "--allow-empty",
}  # fmt: skip
DEFAULTS = {
    "color_by": "entity",
    "property": None,
    "clip_origin": None,
    "clip_normal": None,
    "window_size": (1200, 900),
    "show_edges": False,
    "vertical_exaggeration": 1.0,
    "section_origin": None,
    "section_normal": None,
    "view": None,
    "azimuth": 0.0,
    "elevation": 0.0,
    "title": None,
    "legend": True,
    "axes": True,
    "scale_bar": True,
}


def _render_parser() -> Any:
    parser = build_parser()
    return parser._subparsers._group_actions[0].choices["render"]  # type: ignore[union-attr]


def test_the_flags_are_those_of_the_hand_written_parser() -> None:
    parser = _render_parser()
    flags = {o for action in parser._actions for o in action.option_strings}
    assert flags - {"-h", "--help", "-v", "--verbose", "-q", "--quiet"} == FLAGS
    positionals = [a.dest for a in parser._actions if not a.option_strings]
    assert positionals == ["scene", "output"]


@pytest.fixture
def written(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[dict[str, Any]]:
    calls: list[dict[str, Any]] = []

    def fake_write(scene: Any, path: Any, **keywords: Any) -> Path:
        calls.append({"path": str(path), "entities": len(scene.entities), **keywords})
        return Path(path)

    monkeypatch.setattr(render, "write", fake_write)
    geobrep.write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.geobrep")
    return calls


def test_defaults_reach_the_png_writer(written: list[dict[str, Any]], tmp_path: Path) -> None:
    assert main(["render", str(tmp_path / "cake.geobrep"), str(tmp_path / "c.png")]) == 0
    [call] = written
    assert call.pop("format") == "png"
    assert call.pop("path") == str(tmp_path / "c.png")
    assert call.pop("entities") > 0
    assert call == DEFAULTS


def test_every_flag_reaches_the_png_writer(written: list[dict[str, Any]], tmp_path: Path) -> None:
    argv = ["render", str(tmp_path / "cake.geobrep"), str(tmp_path / "c.png"), "--property",
            "depth", "--clip-origin", "1,2,3", "--clip-normal", "0 0 1", "--section-origin",
            "4,5,6", "--section-normal", "1,0,0", "--view", "north", "--azimuth", "30",
            "--elevation", "-10", "--title", "T", "--no-legend", "--no-axes", "--no-scale-bar",
            "--size", "640", "480", "--edges", "--vertical-exaggeration", "2.5"]  # fmt: skip
    assert main(argv) == 0
    [call] = written
    assert {k: v for k, v in call.items() if k in DEFAULTS} == {
        "color_by": "property",  # --property without --color-by
        "property": "depth",
        "clip_origin": (1.0, 2.0, 3.0),
        "clip_normal": (0.0, 0.0, 1.0),
        "window_size": (640, 480),
        "show_edges": True,
        "vertical_exaggeration": 2.5,
        "section_origin": (4.0, 5.0, 6.0),
        "section_normal": (1.0, 0.0, 0.0),
        "view": "north",
        "azimuth": 30.0,
        "elevation": -10.0,
        "title": "T",
        "legend": False,
        "axes": False,
        "scale_bar": False,
    }


def test_half_a_plane_is_an_error(
    written: list[dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [
        "render",
        str(tmp_path / "cake.geobrep"),
        str(tmp_path / "c.png"),
        "--clip-origin",
        "1,2,3",
    ]
    assert main(argv) == 1
    assert "--clip-origin and --clip-normal go together" in capsys.readouterr().err
    assert written == []


def test_bad_values_are_usage_errors(tmp_path: Path) -> None:
    path = str(tmp_path / "cake.geobrep")
    assert main(["render", path, "c.png", "--clip-origin", "1,2"]) == 2
    assert main(["render", path, "c.png", "--view", "up"]) == 2
    assert main(["render", path, "c.png", "--size", "640"]) == 2


def test_the_parser_is_derived_from_the_declaration() -> None:
    from geobrep.host.operations import cli_flags

    parser = _render_parser()
    actions = {o: a for a in parser._actions for o in [*a.option_strings, a.dest]}
    declared = set()
    for name, info in render.RenderCommand.model_fields.items():
        for flag in cli_flags(name, info):
            declared.add(flag)
            assert actions[flag].help == info.description, flag
    assert declared - {"scene", "output"} == FLAGS
