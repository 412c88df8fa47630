"""``geobrep info`` on grids and wells: the counts a user checks against the reference reader."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from geobrep.cli import main

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


@pytest.mark.parametrize(
    ("name", "counts"),
    [
        ("Simple20x20x5_Fault.grdecl", {"ni": 20, "nj": 20, "nk": 5, "cells": 2000}),
        ("test.vo", {"ni": 9, "nj": 9, "nk": 9, "cells": 729, "points": 1000}),
        ("test.wl", {"vertices": 55, "segments": 54, "markers": 0}),
    ],
)
def test_info_counts(name: str, counts: dict[str, int], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(OPENGEODE / name), "--json"]) == 0
    entity = json.loads(capsys.readouterr().out)["entities"][0]
    assert counts.items() <= entity["counts"].items()
