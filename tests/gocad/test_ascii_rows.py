"""The vectorised ASCII table parser: exact floats, integer columns, errors naming the line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geobrep.adapters.gocad import _ascii_rows as ascii_rows
from geobrep.adapters.gocad._ascii_rows import iter_rows
from geobrep.errors import FormatError


def _rows(path: Path, columns: int = 4) -> tuple[np.ndarray, np.ndarray, list[int]]:
    chunks = list(iter_rows(path, columns, (0, 1, 2), 1 << 30))
    ints = np.concatenate([c.ints for c in chunks])
    floats = np.concatenate([c.floats for c in chunks])
    lines = [c.line(r) for c in chunks for r in range(c.ints.shape[0])]
    return ints, floats, lines


def test_random_float64_round_trip_bit_for_bit(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    bits = rng.integers(0, 2**64 - 1, 60_000, dtype=np.uint64, endpoint=True)
    values = bits.view(np.float64)
    values = values[np.isfinite(values)]
    extra = np.concatenate(
        [
            rng.normal(size=20_000),
            rng.normal(size=20_000).astype(np.float32).astype(np.float64),
            rng.uniform(-1e-3, 1e-3, 5_000),
            rng.integers(-(10**6), 10**6, 5_000).astype(np.float64),
            [0.0, -0.0, 5e-324, 1.7976931348623157e308, 0.1, 0.5, 1e22, 1e23, 9007199254740993.0],
        ]
    )
    values = np.concatenate([values, extra])
    text = "".join(f"{i % 7} {i % 3} {i % 5} {v!r}\n" for i, v in enumerate(values.tolist()))
    path = tmp_path / "t"
    path.write_text("*\n* I J K v\n*\n" + text.replace("e+", "E+"))
    ints, floats, lines = _rows(path)
    assert np.array_equal(floats[:, 0].view(np.uint64), values.view(np.uint64))
    n = np.arange(values.size)
    assert np.array_equal(ints, np.stack([n % 7, n % 3, n % 5], axis=1))
    assert lines[0] == 4
    assert lines[-1] == 3 + values.size


def test_more_than_19_digits_are_exact(tmp_path: Path) -> None:
    # 20 digits and more can exceed 2**64: those tokens are parsed one by one.
    tokens = [
        "123456789012345678901.5",
        "99999999999999999999",
        "-18446744073709551617.0",
        "18446744073709551615",
        "0.12345678901234567890123",
        "1234567890.1234567890123",
        "0.000000000000000000000012345",
        "9999999999999999999",
    ]
    path = tmp_path / "t"
    path.write_text("".join(f"{i} 0 0 {t}\n" for i, t in enumerate(tokens)))
    _, floats, _ = _rows(path)
    assert floats[:, 0].tolist() == [float(t) for t in tokens]


def test_gocad_padded_columns_and_crlf(tmp_path: Path) -> None:
    path = tmp_path / "t"
    path.write_bytes(
        b"       0        0        0      6.48414 \r\n       1        0        0 -99999\r\n"
    )
    ints, floats, _ = _rows(path)
    assert ints.tolist() == [[0, 0, 0], [1, 0, 0]]
    assert floats[:, 0].tolist() == [6.48414, -99999.0]


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("3 0 0 1.2.3", r":3: ASCII data file: '1.2.3' is not a number"),
        ("3 0 0 0x10", r":3: ASCII data file: '0x10' is not a number"),
        ("3 0 0 1_0", r":3: ASCII data file: '1_0' is not a number"),
        ("3 0 0", r":3: ASCII data file: 3 numbers on a row of 4"),
        ("3 0 0 1 2", r":3: ASCII data file: 5 numbers on a row of 4"),
        ("3.5 0 0 1", r":3: ASCII data file: '3.5' is not an integer index"),
        ("3 0 0 1e", r":3: ASCII data file: '1e' is not a number"),
        ("3 0 0 \x011", r":3: ASCII data file: .* is not a number"),
    ],
)
def test_malformed_row_names_its_line(tmp_path: Path, row: str, message: str) -> None:
    path = tmp_path / "t"
    path.write_text("1 0 0 0.5\n2 0 0 0.25\n" + row + "\n4 0 0 1\n")
    with pytest.raises(FormatError, match=message):
        _rows(path)


def test_specials_blank_lines_and_integral_indices(tmp_path: Path) -> None:
    path = tmp_path / "t"
    path.write_text("0 0 0 nan\n\n1 0 0 -1.#INF\n2.0 0 0 inf\n# c\n3 0 0 1e-400\n\n\n")
    ints, floats, lines = _rows(path)
    assert ints[:, 0].tolist() == [0, 1, 2, 3]
    assert np.isnan(floats[0, 0])
    assert floats[1, 0] == -np.inf
    assert floats[2, 0] == np.inf
    assert floats[3, 0] == 0.0
    assert lines == [1, 3, 4, 6]


def test_voxet_rows_in_any_order_missing_ones_no_data_and_outside(tmp_path: Path) -> None:
    import geobrep
    from geobrep import Property, RegularGrid

    values = np.arange(24, dtype=np.float64) / 7
    grid = RegularGrid(
        name="g", origin=[0.0, 0, 0], u=[1.0, 0, 0], v=[0, 1.0, 0], w=[0, 0, 1.0],
        counts=(1, 2, 3),
        point_data={"p": Property(values=values, no_data_value=-99.0)},
    )  # fmt: skip
    path = geobrep.write(grid, tmp_path / "a.vo", voxet_ascii=True)
    table = tmp_path / "a__ascii@@"
    head, *rows = table.read_text().splitlines()[2:]
    table.write_text("\n".join([head, *rows[::-1][:-1]]) + "\n")  # reversed, node 0 missing
    back = geobrep.read(path).entities[0].point_data["p"].values
    assert back[0] == -99.0
    assert np.array_equal(back[1:], values[1:])
    table.write_text("\n".join([head, *rows, "2 0 0 1.0"]) + "\n")
    with pytest.raises(FormatError, match=r":26: ASCII data file: I J K \(2, 0, 0\) is not a node"):
        geobrep.read(path)


def _no_line_by_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make the line-by-line parser fail the test: a regular table must not need it."""

    def refuse(*_: object) -> None:
        raise AssertionError("a regular table was parsed line by line")

    monkeypatch.setattr(ascii_rows._Table, "_slow", refuse)


def test_regular_tables_take_the_vectorised_path_across_blocks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Blocks of 256 bytes: rows cut at every place by the block ends, carried over, a line
    # longer than a block, signs, exponents, leading zeros and two float columns.
    _no_line_by_line(monkeypatch)
    monkeypatch.setattr(ascii_rows, "_CHUNK", 256)
    rng = np.random.default_rng(11)
    values = np.concatenate([rng.normal(size=3000) * 10.0 ** rng.integers(-12, 12, 3000)])
    texts = [repr(v) for v in values.tolist()]
    texts[7] = "+" + repr(abs(float(values[7])))
    texts[8] = "0000.5"
    texts[9] = "-0.0"
    texts[10] = "1" + "0" * 300 + "e-300"  # longer than a block: the buffer grows
    expected = values.copy()
    expected[7:11] = [float(t) for t in texts[7:11]]
    n = np.arange(values.size)
    rows = [f"{i % 9} {i // 9 % 7} {i // 63} {t} {-i}.25" for i, t in enumerate(texts)]
    path = tmp_path / "t"
    path.write_text("* I J K v w\n" + "\n".join(rows))  # no line break at the end
    chunks = list(iter_rows(path, 5, (0, 1, 2), 1 << 30))
    ints = np.concatenate([c.ints for c in chunks])
    floats = np.concatenate([c.floats for c in chunks])
    assert len(chunks) > 100
    assert np.array_equal(floats[:, 0].view(np.uint64), expected.view(np.uint64))
    assert np.array_equal(floats[:, 1], np.where(n == 0, 0.25, -n - 0.25))  # "0.25", "-1.25"
    assert np.array_equal(ints, np.stack([n % 9, n // 9 % 7, n // 63], axis=1))
    assert [c.line(r) for c in chunks for r in range(c.ints.shape[0])] == list(n + 2)


def test_without_the_x87_long_double_numpy_parses_the_floats_bit_for_bit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # ARM, PowerPC and Windows have no 80-bit long double: forced here on x86 too.
    monkeypatch.setattr(ascii_rows, "_EXTENDED", False)
    rng = np.random.default_rng(5)
    bits = rng.integers(0, 2**64 - 1, 20_000, dtype=np.uint64, endpoint=True)
    values = bits.view(np.float64)
    values = np.concatenate([values[np.isfinite(values)], rng.normal(size=10_000)])
    path = tmp_path / "t"
    path.write_text("".join(f"{i % 4} 0 {i // 4} {v!r}\n" for i, v in enumerate(values.tolist())))
    values_read = np.concatenate([c.floats[:, 0] for c in iter_rows(path, 4, (0, 1, 2), 1 << 30)])
    assert np.array_equal(values_read.view(np.uint64), values.view(np.uint64))
    assert ascii_rows.exact_floats(*_words_of(b" 1.5"), None, None)[1].all()


def _words_of(text: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    buffer, data, words = ascii_rows._buffer(64)
    buffer[32 : 32 + len(text)] = text
    return words, data, np.array([33]), np.array([32 + len(text)])


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("3 0 0 1.2.3", r":3: ASCII data file: '1.2.3' is not a number"),
        ("3 0 0 0x10", r":3: ASCII data file: '0x10' is not a number"),
        ("3 0 0 1_0", r":3: ASCII data file: '1_0' is not a number"),
        ("3 0 0 1e", r":3: ASCII data file: '1e' is not a number"),
        ("3.5 0 0 1", r":3: ASCII data file: '3.5' is not an integer index"),
    ],
)
def test_malformed_rows_without_the_long_double(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, row: str, message: str
) -> None:
    monkeypatch.setattr(ascii_rows, "_EXTENDED", False)
    path = tmp_path / "t"
    path.write_text("1 0 0 0.5\n2 0 0 0.25\n" + row + "\n4 0 0 1\n")
    with pytest.raises(FormatError, match=message):
        _rows(path)


def _voxet_table(tmp_path: Path) -> tuple[Path, Path, list[str]]:
    import geobrep
    from geobrep import Property, RegularGrid

    grid = RegularGrid(
        name="g", origin=[0.0, 0, 0], u=[1.0, 0, 0], v=[0, 1.0, 0], w=[0, 0, 1.0],
        counts=(3, 4, 5),
        point_data={"p": Property(values=np.arange(120) / 7, no_data_value=-99.0)},
    )  # fmt: skip
    path = geobrep.write(grid, tmp_path / "a.vo", voxet_ascii=True)
    table = tmp_path / "a__ascii@@"
    return path, table, table.read_text().splitlines()


@pytest.mark.parametrize(
    ("order", "second", "back"),
    [
        ("in order, repeated at once", 9, 1),
        ("in order, repeated in a later block", 110, 90),
        ("reversed, repeated", 60, 3),
    ],
)
def test_a_node_listed_twice_is_a_format_error_naming_the_second_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, order: str, second: int, back: int
) -> None:
    # OpenGeode-GeosciencesIO takes the last row of a node listed twice; a table that lists
    # a node twice is inconsistent, so geobrep refuses it.
    import geobrep

    monkeypatch.setattr(ascii_rows, "_CHUNK", 512)  # several blocks
    path, table, lines = _voxet_table(tmp_path)
    head, rows = lines[:3], lines[3:]
    if order.startswith("reversed"):
        rows = rows[::-1]
    node = rows[second - 4 - back]  # a row above: the node listed again on line `second`
    rows = [*rows[: second - 4], node, *rows[second - 4 :]]
    table.write_text("\n".join([*head, *rows]) + "\n")
    ijk = tuple(int(t) for t in node.split()[:3])
    with pytest.raises(
        FormatError, match=rf":{second}: .* I J K \({ijk[0]}, {ijk[1]}, {ijk[2]}\) is listed twice"
    ):
        geobrep.read(path)


def test_an_sgrid_ascii_table_takes_the_vectorised_path_and_refuses_doubles_and_gaps(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import geobrep

    header = (
        "GOCAD SGrid 1\nHEADER {\nname:s\nascii:on\n}\nAXIS_N 5 4 3\nPROP_ALIGNMENT POINTS\n"
        "ASCII_DATA_FILE s__ascii@@\nPROPERTY 1 a\nPROPERTY 2 b\nEND\n"
    )
    (tmp_path / "s.sg").write_text(header)
    rng = np.random.default_rng(2)
    xyz = rng.normal(size=(60, 3)) * 1000.0
    a, b = rng.normal(size=60), rng.uniform(size=60)
    n = np.arange(60)
    rows = [
        f"{x!r} {y!r} {z!r} {u!r} {v!r} {i % 5} {i // 5 % 4} {i // 20}"
        for i, ((x, y, z), u, v) in enumerate(
            zip(xyz.tolist(), a.tolist(), b.tolist(), strict=True)
        )
    ]
    table = tmp_path / "s__ascii@@"
    table.write_text("*\n* X Y Z a b I J K\n*\n" + "\n".join(rows) + "\n")
    with monkeypatch.context() as patched:
        _no_line_by_line(patched)
        (grid,) = geobrep.read(tmp_path / "s.sg").structured_grids
    assert np.array_equal(grid.points, xyz)
    assert np.array_equal(grid.point_data["a"].values, a)
    assert np.array_equal(grid.point_data["b"].values, b)
    table.write_text("\n".join(rows[::-1]) + "\n")  # any order
    (grid,) = geobrep.read(tmp_path / "s.sg").structured_grids
    assert np.array_equal(grid.points[n], xyz)
    table.write_text("\n".join([*rows[:30], rows[12], *rows[30:]]) + "\n")
    with pytest.raises(FormatError, match=r":31: .* I J K \(2, 2, 0\) is listed twice"):
        geobrep.read(tmp_path / "s.sg")
    table.write_text("\n".join(rows[:17] + rows[18:]) + "\n")
    with pytest.raises(FormatError, match=r"no row for node I J K \(2, 3, 0\) \(59 rows"):
        geobrep.read(tmp_path / "s.sg")


def test_crlf_and_tab_separated_tables_take_the_vectorised_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _no_line_by_line(monkeypatch)
    values = np.random.default_rng(4).normal(size=2000)
    path = tmp_path / "t"
    rows = [
        f"{i % 10}\t{i // 10 % 10}\t{i // 100}\t{v!r}\r\n" for i, v in enumerate(values.tolist())
    ]
    path.write_bytes("".join(rows).encode())
    ints, floats, lines = _rows(path)
    assert np.array_equal(floats[:, 0], values)
    assert ints[-1].tolist() == [9, 9, 19]
    assert lines[-1] == 2000
    path.write_bytes("".join(rows[:5]).encode() + b"5 0 0 \x0b1\r\n")  # a vertical tab
    with pytest.raises(AssertionError, match="line by line"):
        _rows(path)
