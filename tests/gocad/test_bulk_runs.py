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


TWO_SURFACES = """GOCAD TSurf 1
HEADER {
name:a
}
PROPERTIES p
TFACE
PVRTX 1 0 0 0 1
PVRTX 2 1 0 0 2
PVRTX 3 0 1 0 3
TRGL 1 2 3
TFACE
PVRTX 4 1 1 0 4
PVRTX 5 2 1 0 5
TRGL 2 4 3
TRGL 4 5 2
END
GOCAD TSurf 1
HEADER {
name:b
}
PROPERTIES p q
TFACE
PVRTX 1 0 0 5 1 10
PVRTX 2 1 0 5 2 20
PVRTX 3 0 1 5 3 30
TRGL 1 2 3
TRGL 3 2 1
END
"""


@pytest.mark.parametrize("flag", ["", " CNXYZ"])
def test_runs_of_several_objects_parsed_together_read_as_each_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, flag: str
) -> None:
    """Runs of one keyword and width are parsed in one batch; a run the batch cannot take
    (a flag: the whole batch falls back) reads the same."""
    path = tmp_path / "two.ts"
    path.write_text(TWO_SURFACES.replace("PVRTX 5 2 1 0 5", "PVRTX 5 2 1 0 5" + flag))
    together = _scene(path).surfaces
    monkeypatch.setattr("geobrep.adapters.gocad._lexer.ORJSON", None)
    alone = _scene(path).surfaces
    assert [s.name for s in together] == ["a", "b"]
    assert together[1].point_data["q"].values.tolist() == [10, 20, 30]
    for x, y in zip(together, alone, strict=True):
        assert np.array_equal(x.vertices, y.vertices)
        assert np.array_equal(x.faces, y.faces)
        assert np.array_equal(x.patch_labels, y.patch_labels)
        assert dict(x.point_data).keys() == dict(y.point_data).keys()
        for name in dict(x.point_data):
            assert np.array_equal(x.point_data[name].values, y.point_data[name].values)


def _scene(path: Path) -> geobrep.Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.read(path)


def test_a_bad_id_in_a_batched_run_is_reported_on_its_line(tmp_path: Path) -> None:
    path = tmp_path / "bad2.ts"
    path.write_text(TWO_SURFACES.replace("TRGL 3 2 1", "TRGL 3 2 1.5"))
    with pytest.raises(FormatError, match=r"bad2\.ts:27"):
        _scene(path)


@pytest.mark.parametrize("blank", [" ", "\t ", "  "])
def test_a_run_ending_with_a_keyword_and_blanks_is_reported_on_its_line(
    tmp_path: Path, blank: str
) -> None:
    """An ATOM line without ids at the end of its run: the bulk parse gives way to the line
    parser, which names the line (it used to fail with an IndexError)."""
    head = ["GOCAD TSurf 1", "HEADER {", "name:a", "}", "TFACE"]
    body = ["VRTX 1 0 0 0", "VRTX 2 1 0 0", "VRTX 3 0 1 0", "ATOM 4 1", "ATOM" + blank]
    text = "\n".join([*head, *body, "TRGL 1 2 3", "END", ""])
    path = tmp_path / "blank.ts"
    path.write_text(text)
    with pytest.raises(FormatError, match=r"blank\.ts:10: ATOM needs a new id"):
        _scene(path)
