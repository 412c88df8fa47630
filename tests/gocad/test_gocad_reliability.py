"""Untrusted GOCAD files (issue 15 items 5, 8 and 10): linear-time tokenising, every defect a
FormatError with file and line in the user's terms, duplicate and zero-area triangles reported.

The reproducers of the attack-and-fuzz campaign are in ``tests/data/reliability/gocad``.
"""

from __future__ import annotations

import re
import signal
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from gocad_files import DATA

import geobrep
from geobrep.adapters.gocad._lexer import Source, split_tokens
from geobrep.adapters.gocad._parser import GocadWarning
from geobrep.adapters.limits import BUDGET_FLOOR

TESTS_DATA = DATA.parent
RELIABILITY = TESTS_DATA / "reliability" / "gocad"
GUARD_SECONDS = 30
MB = 1_000_000


def split_tokens_reference(text: str) -> list[str]:
    """The tokenizer as it was before issue 15 (quadratic: each token copies the rest of the
    line), kept as the reference the linear one must agree with."""
    if '"' not in text:
        return text.split()
    tokens: list[str] = []
    rest = text
    while True:
        rest = rest.lstrip()
        if not rest:
            return tokens
        if rest[0] == '"':
            close = rest.find('"', 1)
            if close < 0:
                tokens.append(rest[1:])
                return tokens
            tokens.append(rest[1:close])
            rest = rest[close + 1 :]
        else:
            cut = len(rest)
            for index, char in enumerate(rest):
                if char.isspace() or char == '"':
                    cut = index
                    break
            tokens.append(rest[:cut])
            rest = rest[cut:]


@contextmanager
def guard(seconds: int = GUARD_SECONDS) -> Iterator[None]:
    """Fail (TimeoutError) a block that runs longer than ``seconds``: a hang guard, not a
    timing assertion."""

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def timed_read(path: Path) -> tuple[float, geobrep.Scene | geobrep.FormatError]:
    """Seconds to read ``path`` (under the guard) and the scene or the FormatError."""
    with warnings.catch_warnings(), guard():
        warnings.simplefilter("ignore", GocadWarning)
        start = time.perf_counter()
        try:
            result: geobrep.Scene | geobrep.FormatError = geobrep.read(path, format="gocad")
        except geobrep.FormatError as error:
            result = error
        return time.perf_counter() - start, result


def read_warnings(path: Path) -> tuple[geobrep.Scene, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GocadWarning)
        scene = geobrep.read(path)
    return scene, [str(w.message) for w in caught if issubclass(w.category, GocadWarning)]


# -- item 5: the tokenizer ------------------------------------------------------------------------
def _every_test_line() -> Iterator[tuple[Path, int, str]]:
    for path in sorted(TESTS_DATA.rglob("*")):
        if not path.is_file() or path.suffix in (".md", ".py", ".txt", ".sh", ".tif", ".tiff"):
            continue
        source = Source.read(path)
        for index in range(source.n_lines):
            yield path, index + 1, source.text(index)


#: The reference is quadratic: a longer line is compared on its head (cut at a blank).
REFERENCE_LIMIT = 20_000


def test_tokens_are_the_reference_tokens_on_every_line_of_every_test_file() -> None:
    compared = quoted = 0
    for path, number, text in _every_test_line():
        if len(text) > REFERENCE_LIMIT:
            text = text[: text.rindex(" ", 0, REFERENCE_LIMIT)]
        for variant in (text, text.strip()):
            assert split_tokens(variant) == split_tokens_reference(variant), (path, number)
        compared += 1
        quoted += '"' in text
    assert compared > 100_000
    assert quoted > 400  # the corpus really has quoted lines


def test_the_reproducers_long_line_has_its_tokens() -> None:
    source = Source.read(RELIABILITY / "quadratic_quoted_line.pl")
    tokens = split_tokens(source.text(5))
    assert tokens[:2] == ["AXIS_UNIT", "m"]
    assert set(tokens[2:]) == {"1"}
    assert len(tokens) - 2 == source.text(5).count(" 1")


@pytest.mark.parametrize(
    "text",
    [
        "",
        '"',
        '""',
        '"" ""',
        'a"b c"d',
        '  "open to the end  ',
        'KEY "x"y"z" w',
        'PROPERTIES " default property"  def-prop',
        '\u00a0a\u2003"b\u3000c"\x1cd',  # Unicode blanks split as str.split does
        '"a\tb"\t"c"',
    ],
)
def test_tokens_of_quote_corner_cases_are_the_reference_tokens(text: str) -> None:
    assert split_tokens(text) == split_tokens_reference(text)


def _pline(axis_line: str) -> str:
    """A one-segment PLine whose coordinate-system block holds ``axis_line``."""
    return (
        "GOCAD PLine 1\nHEADER {\nname:l\n}\nGOCAD_ORIGINAL_COORDINATE_SYSTEM\n"
        f"{axis_line}\nEND_ORIGINAL_COORDINATE_SYSTEM\n"
        "ILINE\nVRTX 1 0 0 0\nVRTX 2 1 0 0\nSEG 1 2\nEND\n"
    )


def _model3d_with_long_region_line(size: int) -> str:
    """modelA1.ml with the Universe's side list repeated on one line of about ``size`` bytes
    (before its closing 0): the same model, every side listed many times."""
    text = (DATA / "modelA1.ml").read_text()
    head, tail = text.split("REGION 22  Universe \n", 1)
    sides, rest = tail.split("  0\n", 1)
    once = " ".join(sides.split())
    line = " ".join([once] * (size // (len(once) + 1)))
    return f"{head}REGION 22  Universe \n{line}  0\n{rest}"


def _tsolid_with_region_line(size: int) -> str:
    text = (DATA / "cube_model_equi.so").read_text()
    return text.replace("\nMODEL\n", '\nMODEL\nREGION "r"' + " 1" * (size // 2) + "\n", 1)


def _vertex_with_flags(size: int) -> str:
    return _pline("AXIS_NAME X Y Z").replace(
        "VRTX 2 1 0 0", "VRTX 2 1 0 0" + " CNXYZ" * (size // 6)
    )


#: Files with one line of about the size given: (suffix, text).
LONG_LINES: dict[str, tuple[str, Callable[[int], str]]] = {
    "quoted AXIS_UNIT line (the reproducer)": (
        ".pl",
        lambda n: _pline('AXIS_UNIT "m"' + " 1" * (n // 2)),
    ),
    "a line of quoted tokens": (".pl", lambda n: _pline("AXIS_NAME" + ' "x"' * (n // 4))),
    "an unbalanced quote": (".pl", lambda n: _pline('AXIS_NAME "' + "x " * (n // 2))),
    "a quoted REGION line in a TSolid MODEL": (".so", _tsolid_with_region_line),
    "a REGION side list on one line of a Model3d": (".ml", _model3d_with_long_region_line),
    "repeated flags after a VRTX": (".pl", _vertex_with_flags),
}


@pytest.mark.parametrize("case", sorted(LONG_LINES))
def test_a_3mb_line_reads_within_the_hang_guard(case: str, tmp_path: Path) -> None:
    """A reader quadratic in the length of a line took over 120 s on these 3 MB lines (19 s at
    1 MB, the reproducer); linear ones take about a second. The guard (GUARD_SECONDS) tells
    them apart on any machine, however loaded, with no timing assertion; the time itself is
    printed by ``benchmarks/long_lines.py`` next to an ordinary file of the same size."""
    suffix, build = LONG_LINES[case]
    long = tmp_path / f"long{suffix}"
    long.write_text(build(3 * MB))
    assert long.stat().st_size >= 2.9 * MB
    _, result = timed_read(long)
    assert isinstance(result, geobrep.Scene), result


def test_the_long_region_line_reads_as_the_model_with_one_warning(tmp_path: Path) -> None:
    path = tmp_path / "long.ml"
    path.write_text(_model3d_with_long_region_line(MB))
    scene, messages = read_warnings(path)
    original, _ = read_warnings(DATA / "modelA1.ml")
    assert scene.blocks == original.blocks
    repeats = [m for m in messages if "lists" in m and "again" in m]
    assert len(repeats) == 1
    assert repeats[0].startswith("long.ml:118: REGION 'Universe' lists ")
    assert repeats[0].endswith(" side(s) again (the first -4); each is kept once")


def test_the_1mb_quoted_line_reproducer_reads_quickly_and_says_what_it_ignored() -> None:
    path = RELIABILITY / "quadratic_quoted_line.pl"
    with guard():
        scene, messages = read_warnings(path)
    (line,) = scene.polylines
    assert line.n_points == 2
    assert any(
        re.match(r"quadratic_quoted_line\.pl:6: AXIS_UNIT needs 3 entries", m) for m in messages
    )


# -- item 8: each internal failure is a FormatError at its cause -----------------------------------
REPRODUCERS = {
    "crs_empty_axis.pl": (3, r"AXIS_NAME entry 3 is empty"),
    "ml_parse_int_hex.ml": (2, r"REGION: '0x10' is not an integer"),
    "so_surface_overflow.so": (5, r"TRGL: '18446744073709551616' is too large for an id"),
    "trgl_id_huge.ts": (9, r"TRGL: '99999999999999999999' is too large for an id"),
    "trgl_no_vertices.ts": (6, r"TRGL refers to vertex 1 which is not defined"),
    "vrtx_id_2pow64.ts": (6, r"VRTX: '18446744073709551616' is too large for an id"),
}


@pytest.mark.parametrize("name", sorted(REPRODUCERS))
def test_each_reproducer_is_a_format_error_with_file_line_and_cause(name: str) -> None:
    line, message = REPRODUCERS[name]
    path = RELIABILITY / name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GocadWarning)
        with pytest.raises(geobrep.FormatError) as caught:
            geobrep.read(path)
    error = caught.value
    assert (error.path, error.line) == (path, line)
    assert re.match(message, error.message), error.message
    assert "reader failed" not in error.message
    assert error.__cause__ is None  # raised where the defect is, not re-wrapped


#: Reproducers an earlier fix turned into a clear result: data after the stray PROPERTIES line
#: is read; the line itself is reported (with its line number) and ignored.
READ_WITH_WARNINGS = {
    "props_index_error.pl": (1, "props_index_error.pl:3: PROPERTIES after the data lines"),
    "props_reshape.ts": (1, "props_reshape.ts:2: unknown keyword 'END_ORIGINAL_COORDINATE"),
    "vertex_concat.pl": (3, "vertex_concat.pl:3: PROPERTIES after the data lines"),
}


@pytest.mark.parametrize("name", sorted(READ_WITH_WARNINGS))
def test_reproducers_fixed_earlier_read_and_say_what_they_ignored(name: str) -> None:
    n_vertices, message = READ_WITH_WARNINGS[name]
    scene, messages = read_warnings(RELIABILITY / name)
    (entity,) = scene.entities
    assert entity.n_points == n_vertices  # type: ignore[attr-defined]
    assert any(m.startswith(message) for m in messages), messages


HANDLED = {
    "atom_chain.ts": "atom_chain.ts:12: ATOM 6 refers to vertex 6 which is not defined before it",
    "dup_vrtx_id.ts": "dup_vrtx_id.ts:9: vertex id 2 is already defined on line 7",
    "pvrtx_missing_value.ts": "pvrtx_missing_value.ts:9: PVRTX needs 6 numbers, found 5",
}


@pytest.mark.parametrize("name", sorted(HANDLED))
def test_handled_reproducers_stay_rejected_as_before(name: str) -> None:
    with pytest.raises(geobrep.FormatError) as caught:
        geobrep.read(RELIABILITY / "handled_ok" / name)
    assert str(caught.value).endswith(HANDLED[name])


def test_handled_reproducers_stay_read_as_before() -> None:
    scene, messages = read_warnings(RELIABILITY / "handled_ok" / "no_end.ts")
    assert scene.surfaces[0].n_faces == 1
    assert messages == ["no_end.ts:1: TSurf 't' has no END"]
    scene, messages = read_warnings(RELIABILITY / "handled_ok" / "two_objects_same.ts")
    assert [s.name for s in scene.surfaces] == ["t", "t2"]
    assert messages == []


def test_huge_tokens_are_cut_in_messages(tmp_path: Path) -> None:
    path = tmp_path / "huge.ts"
    path.write_text(
        (RELIABILITY / "trgl_id_huge.ts").read_text().replace("99999999999999999999", "9" * MB)
    )
    with pytest.raises(geobrep.FormatError) as caught:
        geobrep.read(path)
    assert caught.value.line == 9
    assert len(str(caught.value)) < 300
    assert f"({MB} characters) is not an integer" in caught.value.message


# -- item 10: duplicate and zero-area triangles ------------------------------------------------
def test_duplicate_and_zero_area_triangles_are_reported_once_and_kept() -> None:
    scene, messages = read_warnings(RELIABILITY / "dup_trgl.ts")
    (surface,) = scene.surfaces
    assert surface.faces.tolist() == [[0, 1, 2], [0, 1, 2], [0, 0, 1]]  # as read
    (message,) = messages
    assert message == (
        "dup_trgl.ts:10: TSurf 't': 1 duplicated triangle(s) (the same three vertices as an "
        "earlier TRGL) and 1 zero-area triangle(s) (the first on this line); kept as read"
    )


def test_triangle_counts_are_those_of_the_geometry(tmp_path: Path) -> None:
    """Reversed and rotated repeats are duplicates; three collinear distinct vertices have zero
    area; the first line named is the first bad triangle's."""
    rows = ["1 2 3", "2 3 4", "3 2 1", "4 2 3", "1 2 5", "2 1 3"]  # 5 is on the 1-2 line
    text = (
        "GOCAD TSurf 1\nHEADER {\nname:s\n}\nTFACE\nVRTX 1 0 0 0\nVRTX 2 1 0 0\nVRTX 3 0 1 0\n"
        "VRTX 4 1 1 0\nVRTX 5 2 0 0\n" + "".join(f"TRGL {r}\n" for r in rows) + "END\n"
    )
    path = tmp_path / "s.ts"
    path.write_text(text)
    _, messages = read_warnings(path)
    assert messages == [
        "s.ts:13: TSurf 's': 3 duplicated triangle(s) (the same three vertices as an earlier "
        "TRGL) and 1 zero-area triangle(s) (the first on this line); kept as read"
    ]


def test_clean_test_files_get_no_triangle_warning() -> None:
    for path in sorted(DATA.iterdir()):
        if path.suffix == ".md":
            continue
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", GocadWarning)
            try:
                geobrep.read(path)
            except geobrep.FormatError:
                continue
        assert not [w for w in caught if "duplicated triangle" in str(w.message)], path


def test_a_property_header_declaring_more_values_than_the_file_holds_is_refused(
    tmp_path: Path,
) -> None:
    """120 bytes declaring ESIZES 100000000 took 4.8 GB (a NaN row of 1e8 per vertex)."""
    path = tmp_path / "bomb.vs"
    path.write_text(
        "GOCAD VSet 1\nHEADER {\nname: bomb\n}\nPROPERTIES a\nESIZES 100000000\n"
        "VRTX 1 0 0 0\nVRTX 2 1 0 0\nEND\n",
        encoding="utf-8",
    )
    with pytest.raises(geobrep.FormatError, match="declares 100000000 values per vertex"):
        geobrep.read(path)


@pytest.mark.parametrize(
    ("line", "message"),
    [("TFACE -2147483649 boundary box", "TFACE id -2147483649"), ("REGION 0 Top", "REGION id 0")],
)
def test_model3d_ids_must_be_positive(tmp_path: Path, line: str, message: str) -> None:
    """The readers' fuzz run (seed 2, case 759) ended in a Patch ValidationError."""
    path = tmp_path / "ids.ml"
    path.write_text(f"GOCAD Model3d 1\nHEADER {{\nname: ids\n}}\n{line}\nEND\n", encoding="utf-8")
    with pytest.raises(geobrep.FormatError, match=re.escape(message)) as caught:
        geobrep.read(path)
    assert caught.value.line == 5


def _vrtx_without_values(tmp_path: Path, rows: int) -> Path:
    path = tmp_path / "wide.vs"
    vertices = "".join(f"VRTX {i} {i} 0 0\n" for i in range(1, rows + 1))
    path.write_text(
        f"GOCAD VSet 1\nHEADER {{\nname: wide\n}}\nPROPERTIES a b\nESIZES 999 1\n"
        f"PVRTX 0 0 0 0 {' '.join(['2'] * 1000)}\n{vertices}END\n",
        encoding="utf-8",
    )
    return path


def test_vrtx_lines_without_values_are_filled_in_up_to_the_limit(tmp_path: Path) -> None:
    """VRTX lines may carry no values in an object with properties (GOCAD mixes VRTX and PVRTX):
    no-data for them, up to an eighth of the read budget (2,097,152 values at the floor)."""
    rows = BUDGET_FLOOR // 8 // 8 // 1000
    scene = geobrep.read(_vrtx_without_values(tmp_path, rows))
    (points,) = scene.entities
    b = np.asarray(points.point_data["b"])
    assert b.shape == (rows + 1,)
    assert b[0] == 2
    assert np.isnan(b[1:]).all()


def test_vrtx_lines_without_values_past_the_limit_are_refused(tmp_path: Path) -> None:
    """Padding every value-less vertex with the header's 1000 values took 8 kB of memory per
    15-byte line (0.96 GB for a 3 MB file of 399 values: tests/reliability has that case)."""
    rows = BUDGET_FLOOR // 8 // 8 // 1000
    with pytest.raises(geobrep.FormatError, match="declares 1000 property values per ver") as c:
        geobrep.read(_vrtx_without_values(tmp_path, rows + 1))
    assert c.value.line == 7 + rows + 1  # the first VRTX past the limit
