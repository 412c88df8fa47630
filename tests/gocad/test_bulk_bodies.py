"""Whole object bodies read in bulk (``_bodies.read_body``) give what the run-by-run parser
gives: the same parsed objects, the same warnings, the same errors on the same lines."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from gocad_files import DATA, FILES, read_quietly

from geobrep.adapters.gocad import _bodies
from geobrep.adapters.gocad._lexer import BulkParseError, Source, parse_rows
from geobrep.adapters.gocad._parser import GocadObject, parse_source
from geobrep.errors import FormatError


def _parse(path: Path, bulk: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[Any, list[str]]:
    """The parsed objects (or the error's text) and the warnings, bulk bodies on or off."""
    monkeypatch.setattr(_bodies, "BULK_BODIES", bulk)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result: Any = parse_source(Source.read(path))
        except FormatError as exc:
            result = f"FormatError: {exc}"
    return result, [str(w.message) for w in caught]


def _equal(a: Any, b: Any, where: str = "") -> None:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        assert a.dtype == b.dtype, where
        assert a.shape == b.shape, where
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), where
    elif dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), where
        for f in dataclasses.fields(a):
            _equal(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b), where
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _equal(x, y, f"{where}[{k}]")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            _equal(a[key], b[key], f"{where}[{key!r}]")
    else:
        assert a == b, where


def _bulk_bodies(path: Path, monkeypatch: pytest.MonkeyPatch) -> int:
    """How many bodies of the file the bulk reader takes."""
    taken = []
    read = _bodies.read_body

    def counting(*args: Any) -> Any:
        body = read(*args)
        taken.append(body is not None)
        return body

    monkeypatch.setattr("geobrep.adapters.gocad._parser.read_body", counting)
    _parse(path, True, monkeypatch)
    monkeypatch.setattr("geobrep.adapters.gocad._parser.read_body", read)
    return sum(taken)


@pytest.mark.parametrize("name", FILES)
def test_every_test_file_parses_as_run_by_run(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    bulk, bulk_warnings = _parse(DATA / name, True, monkeypatch)
    runs, run_warnings = _parse(DATA / name, False, monkeypatch)
    _equal(bulk, runs, name)
    assert bulk_warnings == run_warnings


@pytest.mark.parametrize(("name", "at_least"), [("modelA1.ml", 9), ("modelA4.ml", 11)])
def test_the_model3d_files_are_read_in_bulk(
    name: str, at_least: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert _bulk_bodies(DATA / name, monkeypatch) >= at_least


def test_the_scene_is_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_bodies, "BULK_BODIES", True)
    bulk = read_quietly(DATA / "modelA1.ml")
    monkeypatch.setattr(_bodies, "BULK_BODIES", False)
    runs = read_quietly(DATA / "modelA1.ml")
    assert [e.name for e in bulk.entities] == [e.name for e in runs.entities]
    for x, y in zip(bulk.surfaces, runs.surfaces, strict=True):
        assert np.array_equal(x.vertices, y.vertices)
        assert np.array_equal(x.faces, y.faces)
        assert np.array_equal(x.patch_labels, y.patch_labels)
        assert x.metadata == y.metadata
    assert bulk.topology == runs.topology


SURFACE = """GOCAD TSurf 1
HEADER {
name:s
}
PROPERTIES a b
TFACE one
PVRTX 1 0 0 0 1.5 -99999
PVRTX 2 1 0 0.25 2.5 7
PVRTX 3 0 1 1e-3 3.5 8
TRGL 1 2 3
# a comment

TFACE "two"
PATOM 4 2 9.5 10
PATOM 5 3 11.5 12
PVRTX 6 1 1 -0.5 13.5 14
VRTX 7 2 1 0.125
ATOM 8 7
TRGL 4 6 5
TRGL 4 7 6
TRGL 8 6 5
BSTONE 2
BORDER 9 2 3
BORDER 10 3 1
END
"""

#: (line to change, its replacement): each a body the bulk reader must read as the parser
#: does, or give up on so that the parser reads it (same objects, warnings or error).
MUTATIONS = [
    ("TRGL 4 6 5", "TRGL 4 6 x"),
    ("TRGL 4 6 5", "TRGL 4 6"),
    ("TRGL 4 6 5", "TRGL 4 6 5 9"),
    ("TRGL 4 6 5", "TRGL 4 6 99"),
    ("TRGL 4 6 5", "TRGL 4.0 6 5"),
    ("TRGL 4 6 5", "TRGL 4 6-5"),
    ("TRGL 4 6 5", "TRGL 4 6 -999"),
    ("TRGL 4 6 5", "TRGL 4 6 -"),
    ("TRGL 1 2 3", "TRGL 1.5 2 3"),
    ("TRGL 1 2 3", "TRGL  1   2\t3  "),
    ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 2 1 0 0.25 2.5"),
    ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 2.5 1 0 0.25 2.5 7"),
    ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 2 1 0 0.25 2.5 inf"),
    ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 2 1 0 0.25 2.5 7 CNXYZ"),
    ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 1 1 0 0.25 2.5 7"),
    ("PVRTX 6 1 1 -0.5 13.5 14", "PVRTX 6.0 1 1 -0.5 13.5 14"),
    ("VRTX 7 2 1 0.125", "VRTX 7.0 2 1 0.125"),
    ("VRTX 7 2 1 0.125", "VRTX 7 2 1 0.125 5"),
    ("ATOM 8 7", "ATOM 8 99"),
    ("ATOM 8 7", "ATOM 8 7.5"),
    ("PATOM 4 2 9.5 10", "PATOM 4 2 9.5"),
    ("BSTONE 2", "BSTONE x"),
    ("BSTONE 2", "BSTONE 2 3"),
    ("BORDER 9 2 3", "BORDER 9 2"),
    ("BORDER 9 2 3", "BORDER 9 2 3.5"),
    ("TFACE one", "TFACE"),
    ("TFACE one", "tface one"),
    ("TFACE one", "ILINE one"),
    ("TFACE one", "SUBVSET one"),
    ("TFACE one", "# no part"),
    ('TFACE "two"', "HEADER {"),
    ("TRGL 8 6 5", "vrtx 9 0 0 0"),
    ("TRGL 8 6 5", "SEG 8 6"),
    ("TRGL 8 6 5", "TETRA 8 6 5 4"),
    ("END", "GOCAD TSurf 1"),
    ("END", "END extra"),
    ("BORDER 10 3 1", "BORDER 10 3 1\nBSTONE 99"),
    ("# a comment", "PROPERTIES c"),
]


@pytest.mark.parametrize(("old", "new"), MUTATIONS)
@pytest.mark.parametrize("ending", ["\n", "\r\n"])
def test_odd_bodies_read_as_run_by_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, old: str, new: str, ending: str
) -> None:
    lines = SURFACE.splitlines()
    lines[lines.index(old)] = new
    path = tmp_path / "odd.ts"
    path.write_bytes(ending.join(lines).encode() + ending.encode())
    bulk, bulk_warnings = _parse(path, True, monkeypatch)
    runs, run_warnings = _parse(path, False, monkeypatch)
    _equal(bulk, runs)
    assert bulk_warnings == run_warnings


def test_the_plain_surface_is_read_in_bulk(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "plain.ts"
    path.write_text(SURFACE)
    assert _bulk_bodies(path, monkeypatch) == 1
    (obj,) = _parse(path, True, monkeypatch)[0]
    assert isinstance(obj, GocadObject)
    assert obj.part_names == ["one", "two"]
    assert obj.part_vertex_starts == [0, 3]
    assert obj.vertices is not None
    assert obj.cells is not None
    assert obj.vertices.ids.tolist() == [1, 2, 3, 4, 5, 6, 7, 8]
    assert obj.vertices.xyz[7].tolist() == [2.0, 1.0, 0.125]  # ATOM 8 at VRTX 7
    np.testing.assert_array_equal(
        obj.vertices.values[:, 0], [1.5, 2.5, 3.5, 9.5, 11.5, 13.5, np.nan, np.nan]
    )
    assert obj.cells.parts.tolist() == [0, 1, 1, 1]
    assert obj.cells.lines.tolist() == [10, 19, 20, 21]
    assert [(b.vertex_id, b.line) for b in obj.bstones] == [(2, 22)]
    assert [tuple(b) for b in obj.borders] == [(9, 2, 3, 23), (10, 3, 1, 24)]


@pytest.mark.parametrize(
    ("old", "new", "line"),
    [
        ("TRGL 4 6 5", "TRGL 4 6 x", 19),
        ("TRGL 4 6 5", "TRGL 4 6 99", 19),
        ("PVRTX 2 1 0 0.25 2.5 7", "PVRTX 2.5 1 0 0.25 2.5 7", 8),
        ("ATOM 8 7", "ATOM 8 99", 18),
        ("BORDER 9 2 3", "BORDER 9 2", 23),
    ],
)
def test_a_malformed_row_is_reported_on_its_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, old: str, new: str, line: int
) -> None:
    path = tmp_path / "bad.ts"
    path.write_text(SURFACE.replace(old + "\n", new + "\n"))
    monkeypatch.setattr(_bodies, "BULK_BODIES", True)
    with pytest.raises(FormatError, match=rf"bad\.ts:{line}\b") as bulk:
        read_quietly(path)
    monkeypatch.setattr(_bodies, "BULK_BODIES", False)
    with pytest.raises(FormatError) as runs:
        read_quietly(path)
    assert str(bulk.value) == str(runs.value)


def test_a_malformed_row_in_a_real_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    lines = (DATA / "modelA4.ml").read_text().splitlines()
    index = next(i for i, text in enumerate(lines) if text.startswith("TRGL")) + 500
    lines[index] = "TRGL 1 2 three"
    path = tmp_path / "modelA4.ml"
    path.write_text("\n".join(lines) + "\n")
    monkeypatch.setattr(_bodies, "BULK_BODIES", True)
    with pytest.raises(FormatError, match=rf"modelA4\.ml:{index + 1}\b") as bulk:
        read_quietly(path)
    monkeypatch.setattr(_bodies, "BULK_BODIES", False)
    with pytest.raises(FormatError) as runs:
        read_quietly(path)
    assert str(bulk.value) == str(runs.value)


@pytest.mark.parametrize(
    "rows",
    [
        ["1 2 3", "4 5 6"],
        ["1 2 3 ", "4 5 6 "],
        ["-1 2 3", "4 -5 6"],
        ["-999 2 3", "4 5 -999"],  # the marker value itself
        ["1  2\t3", "4 5 6"],
        ["007 2 3", "4 5 6"],
        ["1 2 3", "4 5"],
        ["1 2 3 4", "4 5"],
        ["1 2 3", "4 5 6 7", "8 9"],
        ["12-3 4", "1 2 3"],
        ["1 2 -", "4 5 6"],
        ["1 2 3-", "4 5 6"],
        ["1 2 +3", "4 5 6"],
        ["99999999999999999999 2 3", "4 5 6"],
    ],
)
@pytest.mark.parametrize("keyword", ["TRGL", "SEG", "BORDER"])
def test_integer_rows_are_what_the_line_parser_reads(
    tmp_path: Path, rows: list[str], keyword: str
) -> None:
    """One bulk parse of integer lines: the ids each line holds, or no bulk result when the
    lines are ragged or hold a token the line parser would not read as one integer."""
    path = tmp_path / "rows.txt"
    path.write_text("".join(f"{keyword} {row}\n" for row in rows))
    source = Source.read(path)
    source.codes  # noqa: B018 - the runs come from the keyword codes
    from geobrep.adapters.gocad._bodies import _FileRuns

    runs = _FileRuns.of(source).runs
    tokens = [row.split() for row in rows]
    plain = all(t.lstrip("-").isdigit() and len(t) < 19 for row in tokens for t in row)
    if plain and len({len(row) for row in tokens}) == 1:
        assert parse_rows(source, runs, integer=True).tolist() == [
            [int(t) for t in row] for row in tokens
        ]
    else:
        with pytest.raises(BulkParseError):
            parse_rows(source, runs, integer=True)
