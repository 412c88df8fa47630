"""Bulk runs of element lines read as the line-by-line parser reads them, whatever the line
ends (LF, CRLF, lone CR, a blank before the break): VRTX, PVRTX, ATOM, PATOM and TRGL runs."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.errors import FormatError

LINES = [
    "GOCAD TSurf 1",
    "HEADER {",
    "name:s",
    "}",
    "PROPERTIES a b",
    "TFACE",
    "PVRTX 1 0 0 0 1.5 -99999",
    "PVRTX 2 1 0 0.25 2.5 7",
    "PVRTX 3 0 1 1e-3 3.5 8",
    "TRGL 1 2 3",
    "TFACE",
    "PATOM 4 2 9.5 10",
    "PATOM 5 3 11.5 12",
    "PVRTX 6 1 1 -0.5 13.5 14",
    "PVRTX 7 2 1 0.125 15.5 16",
    "TRGL 4 6 5",
    "TRGL 4 7 6",
    "END",
]


def _read(path: Path) -> geobrep.Surface:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.read(path).surfaces[0]


def _same(a: geobrep.Surface, b: geobrep.Surface) -> None:
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.faces, b.faces)
    assert np.array_equal(a.patch_labels, b.patch_labels)
    for name in ("a", "b"):
        assert np.array_equal(a.point_data[name].values, b.point_data[name].values)


@pytest.mark.parametrize(
    ("end", "trailing"),
    [("\n", ""), ("\r\n", ""), ("\n", " "), ("\r\n", " "), ("\r", ""), ("\n", "  "), ("\n", "\t")],
)
def test_runs_read_as_the_line_parser_reads_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, end: str, trailing: str
) -> None:
    path = tmp_path / "s.ts"
    path.write_bytes(end.join(line + trailing for line in LINES).encode() + end.encode())
    bulk = _read(path)
    assert bulk.vertices[4].tolist() == [0.0, 1.0, 1e-3]  # PATOM 5 at vertex 3
    assert bulk.point_data["a"].values.tolist() == [1.5, 2.5, 3.5, 9.5, 11.5, 13.5, 15.5]
    monkeypatch.setattr("geobrep.adapters.gocad._lexer.ORJSON", None)  # line by line
    _same(bulk, _read(path))
    plain = tmp_path / "plain.ts"
    plain.write_text("\n".join(LINES) + "\n")
    _same(bulk, _read(plain))


def test_a_bad_id_in_a_crlf_patom_run_is_reported_on_its_line(tmp_path: Path) -> None:
    lines = [line.replace("PATOM 5 3", "PATOM 5 3.5") for line in LINES]
    path = tmp_path / "bad.ts"
    path.write_bytes(("\r\n".join(line + " " for line in lines) + "\r\n").encode())
    with pytest.raises(FormatError, match=r"bad\.ts:13"):
        _read(path)
