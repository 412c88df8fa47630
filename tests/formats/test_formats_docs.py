"""docs/formats.md carries the capability table of the installed built-in formats."""

from __future__ import annotations

from pathlib import Path

import geobrep.plugins
from geobrep.host.capabilities import capability_table
from geobrep.host.registry import FormatRegistry
from geobrep.plugins import registries

PAGE = Path(__file__).parents[2] / "docs" / "formats.md"


def _builtin_table() -> str:
    builtin = {
        info.name for info in geobrep.plugins.list_plugins() if info.module.startswith("geobrep.")
    }
    formats = FormatRegistry(s for s in registries().formats if s.plugin in builtin)
    return capability_table(formats)


def test_capability_table_in_docs_matches_the_registry() -> None:
    text = PAGE.read_text(encoding="utf-8")
    start = text.index("<!-- capability-table:start -->\n") + len(
        "<!-- capability-table:start -->\n"
    )
    end = text.index("\n<!-- capability-table:end -->")
    expected = _builtin_table()
    assert text[start:end] == expected, (
        "docs/formats.md is out of date; replace its table with:\n" + expected
    )


def test_table_lists_every_format_of_this_issue() -> None:
    table = _builtin_table()
    for name in ("vtu", "vtk", "ply", "vtp", "gmsh", "obj", "stl", "off", "png", "native"):
        assert f"| {name} |" in table
