"""Files with one very long line read in about the time of ordinary files of the same size.

Run: ``.venv/bin/python benchmarks/long_lines.py [--size-mb 3] [--repeat 3]``

A reader quadratic in the length of a line (issue 15: a 1 MB quoted line took 19 s, 3 MB over
120 s) is caught in the test suite by a hang guard; this script prints the times: each
long-line case of ``tests/gocad/test_gocad_reliability.py`` next to an ordinary PLine of the
same size, best and median of ``--repeat`` reads, and the ratio (long ÷ ordinary).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import ModuleType

import numpy as np

import geobrep

ROOT = Path(__file__).resolve().parent.parent
MB = 1_000_000


def _reliability_cases() -> ModuleType:
    """The long-line builders of the reliability tests (they read tests/data)."""
    sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "gocad")]
    spec = importlib.util.spec_from_file_location(
        "gocad_reliability", ROOT / "tests" / "gocad" / "test_gocad_reliability.py"
    )
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _ordinary_pline(size: int) -> str:
    """A PLine of about ``size`` bytes of plain VRTX and SEG lines."""
    n = size // 60
    x = (np.arange(n, dtype=np.float64) * 0.123456789).tolist()
    vertices = "".join(f"VRTX {i + 1} {v!r} {2 * v!r} {-v!r}\n" for i, v in enumerate(x))
    segments = "".join(f"SEG {i} {i + 1}\n" for i in range(1, n))
    return f"GOCAD PLine 1\nHEADER {{\nname:l\n}}\nILINE\n{vertices}{segments}END\n"


def _seconds(path: Path, repeat: int) -> list[float]:
    times = []
    for _ in range(repeat):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.perf_counter()
            geobrep.read(path, format="gocad")
            times.append(time.perf_counter() - start)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size-mb", type=float, default=3.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    cases = _reliability_cases()
    size = int(args.size_mb * MB)
    with tempfile.TemporaryDirectory() as folder:
        ordinary = Path(folder) / "ordinary.pl"
        ordinary.write_text(_ordinary_pline(size))
        _seconds(ordinary, 1)  # imports and caches warmed
        reference = _seconds(ordinary, args.repeat)
        print(f"ordinary {size / MB:.1f} MB PLine: best {min(reference):.3f} s")
        print(f"{'case':48s} {'best s':>8s} {'median s':>9s} {'ratio best':>10s} {'median':>7s}")
        for name in sorted(cases.LONG_LINES):
            suffix, build = cases.LONG_LINES[name]
            path = Path(folder) / f"long{suffix}"
            path.write_text(build(size))
            times = _seconds(path, args.repeat)
            best, median = min(times), statistics.median(times)
            print(
                f"{name:48s} {best:8.3f} {median:9.3f} {best / min(reference):10.2f} "
                f"{median / statistics.median(reference):7.2f}"
            )


if __name__ == "__main__":
    main()
