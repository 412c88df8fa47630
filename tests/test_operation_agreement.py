"""Every built-in operation agrees with itself: its function's options, its command's flags, its
pipeline step's JSON Schema and its documentation are one set of names (one declaration)."""

from __future__ import annotations

import inspect
import re
from pathlib import Path
from typing import Any

import pytest

import geobrep
import geobrep.plugins
import geobrep.schemas
from geobrep.batch.operations import builtin_operations, docs_tables, update_docs
from geobrep.batch.pipeline import option_names
from geobrep.cli.main import build_parser
from geobrep.host.operations import cli_flags

DOCS = Path(__file__).resolve().parent.parent / "docs"
SPECS = {spec.name: spec for spec in builtin_operations()}

#: The public function of each operation, and the keys of its step it takes under another name.
FUNCTIONS = {
    "reproject": (geobrep.Scene.to_crs, {"to": "target", "from": "source"}),
    "clip": (geobrep.clip, {}),
    "clip_box": (geobrep.clip_box, {"planes": "bounds"}),
    "section": (geobrep.section, {}),
    "fit": (geobrep.fit, {}),
    "build_blocks": (geobrep.build_blocks, {}),
    "build": (geobrep.build_blocks, {}),
    "voxelize": (geobrep.voxelize, {}),
    "check": (geobrep.inspect, {}),
    "repair": (geobrep.repair, {}),
    "convert": (geobrep.convert, {"format": "to", "options": "write_options"}),
    "map_products": (geobrep.map_products, {}),
}
#: Keys that say what a step does with the scene, not how the function works.
STEP_ONLY = {
    "fit": {"points", "keep_input", "check", "max_triangles"},
    "check": {"on_defects"},  # what the step does with defects: fail, warn or continue
    "convert": {"name", "allow_empty"},  # the output's name and empty results: the command's
}
#: Commands whose parser is derived from the declaration (the rest are listed in the report).
DERIVED = {
    "render",
    "view",
    "reproject",
    "clip",
    "section",
    "voxelize",
    "fit",
    "build_blocks",
    "check",
    "repair",
    "convert",
    "map_products",
}


#: Operations whose result is a file a format's writer makes (their function is geobrep.write):
#: a value for every option that is not the default, so each can be seen reaching the writer.
WRITERS: dict[str, tuple[str, dict[str, Any]]] = {
    "render": (
        "png",
        {
            "color_by": "block",
            "property": "depth",
            "clip_origin": (1.0, 2.0, 3.0),
            "clip_normal": (0.0, 0.0, 1.0),
            "section_origin": (4.0, 5.0, 6.0),
            "section_normal": (1.0, 0.0, 0.0),
            "view": "top",
            "azimuth": 30.0,
            "elevation": -10.0,
            "title": "T",
            "legend": False,
            "axes": False,
            "scale_bar": False,
            "size": (640, 480),
            "edges": True,
            "vertical_exaggeration": 2.5,
        },
    ),
    "view": ("html", {"title": "T", "blocks": False, "all_surfaces": True, "property": "p"}),
}
#: Options every step that writes a file has: where its file goes and whether it may be empty.
OUTPUT_KEYS = {"name", "allow_empty"}
PAIRS = {"clip_origin": "clip_normal", "section_origin": "section_normal"}


def test_every_operation_has_a_function() -> None:
    assert set(FUNCTIONS) | set(WRITERS) == set(SPECS)
    assert not set(FUNCTIONS) & set(WRITERS)


@pytest.mark.parametrize("name", sorted(WRITERS))
def test_every_option_reaches_the_writer(name: str) -> None:
    spec = SPECS[name]
    format_name, sample = WRITERS[name]
    assert spec.output == "files"
    assert spec.options.fixed_format == format_name
    assert set(sample) == set(option_names(spec.options)) - OUTPUT_KEYS
    writer = geobrep.plugins.registries().formats.get(format_name)
    default = spec.options().writer_options()
    writer.validate_options(default)
    writer.validate_options(spec.options(**sample).writer_options())
    pairs = {**PAIRS, **{b: a for a, b in PAIRS.items()}}
    for key, value in sample.items():
        changed = {key: value, **({pairs[key]: sample[pairs[key]]} if key in pairs else {})}
        assert spec.options(**changed).writer_options() != default, f"{name}: {key} is lost"


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_function_takes_every_option(name: str) -> None:
    function, renamed = FUNCTIONS[name]
    parameters = inspect.signature(function).parameters
    forwards = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values())
    for key in option_names(SPECS[name].options):
        if key in STEP_ONLY.get(name, set()):
            continue
        if key == "options" and forwards:
            continue  # the plugin's options, passed on as keywords
        assert renamed.get(key, key) in parameters, f"{name}: the function lacks {key!r}"


@pytest.mark.parametrize("name", sorted(SPECS))
def test_step_schema_has_every_option(name: str) -> None:
    schema = geobrep.schemas.load("pipeline")["$defs"][SPECS[name].options.__name__]
    assert sorted(schema["properties"]) == sorted(option_names(SPECS[name].options))


@pytest.mark.parametrize("name", sorted(DERIVED))
def test_command_has_a_flag_for_every_option(name: str) -> None:
    spec = SPECS[name]
    parser = build_parser()
    command = parser._subparsers._group_actions[0].choices[spec.command_name]  # type: ignore[union-attr]
    flags = {option for action in command._actions for option in action.option_strings}
    for field, info in spec.options.model_fields.items():
        for flag in cli_flags(field, info):
            assert flag in flags, f"geobrep {spec.command_name} lacks {flag}"


@pytest.mark.parametrize("name", sorted(SPECS))
def test_docs_name_every_option(name: str) -> None:
    text = (DOCS / "pipelines.md").read_text(encoding="utf-8")
    paragraph = re.search(rf"^\*\*`{name}`\*\*.*?(?=^\*\*`|^## )", text, re.M | re.S)
    assert paragraph is not None, f"docs/pipelines.md has no paragraph for {name!r}"
    inherited = re.findall(r"`(\w+)`(?:, `\w+`)* as for `(\w+)`", paragraph.group(0))
    named = set(re.findall(r"`(\w+)`", paragraph.group(0)))
    for _, other in inherited:
        block = re.search(rf"^\*\*`{other}`\*\*.*?(?=^\*\*`|^## )", text, re.M | re.S)
        assert block is not None
        named |= set(re.findall(r"`(\w+)`", block.group(0)))
    missing = [key for key in option_names(SPECS[name].options) if key not in named]
    assert not missing, f"docs/pipelines.md, step {name!r}, does not describe {missing}"


def test_docs_tables_are_current() -> None:
    page = DOCS / "pipelines.md"
    text = page.read_text(encoding="utf-8")
    assert update_docs(text) == text, "docs/pipelines.md option tables are stale: make docs-tables"
    for kind in docs_tables():
        assert f"<!-- options: {kind} -->" in text, f"docs/pipelines.md lacks the table of {kind}"


@pytest.mark.parametrize("name", sorted(SPECS))
def test_docs_table_rows_are_the_options_and_flags(name: str) -> None:
    spec = SPECS[name]
    rows = [line for line in docs_tables()[name].splitlines()[2:]]
    keys = [re.match(r"\| `([^`]+)` \|", row).group(1) for row in rows]  # type: ignore[union-attr]
    assert keys == option_names(spec.options)
    for row, (field, info) in zip(rows, spec.options.model_fields.items(), strict=True):
        flags = cli_flags(field, info) if spec.command_name else ()
        for flag in flags:
            assert f"`{flag}`" in row
        assert row.split("|")[4].strip(), f"{name}: option {field!r} has no description"
