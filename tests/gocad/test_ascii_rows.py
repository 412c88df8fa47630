"""The vectorised ASCII table parser: exact floats, integer columns, errors naming the line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

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
