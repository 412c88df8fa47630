"""Where the GOCAD test files are, and a quiet reader for tests."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import geobrep
from geobrep.adapters.gocad._parser import GocadWarning

DATA = Path(__file__).resolve().parent.parent / "data" / "gocad"
#: The GOCAD files (not SOURCES.md, nor the ``@@`` property files of their grids).
FILES = sorted(p.name for p in DATA.iterdir() if p.suffix != ".md" and not p.name.endswith("@@"))


def read_quietly(path: Path | str, **options: Any) -> geobrep.Scene:
    """``geobrep.read`` with GOCAD warnings silenced (tests that check them say so)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GocadWarning)
        return geobrep.read(path, **options)


def write_quietly(scene: geobrep.Scene, path: Path, **options: Any) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GocadWarning)
        return geobrep.write(scene, path, **options)
