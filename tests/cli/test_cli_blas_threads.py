"""Commands that solve no large dense system start numpy with one BLAS thread (issue 17).

See :mod:`geobrep.cli._blas_threads`. Each command-line probe runs in a fresh interpreter,
where numpy is not loaded yet, and prints what ``OPENBLAS_NUM_THREADS`` was when it ended.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from geobrep.cli._blas_threads import BLAS_THREADS_ENV, one_blas_thread
from geobrep.cli.main import _one_blas_thread_suffices

TSURF = Path(__file__).parents[1] / "data" / "gocad" / "2triangles.ts"

PROBE = """
import contextlib, io, os, sys
from geobrep.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    main(sys.argv[1:])
print(repr(os.environ.get("OPENBLAS_NUM_THREADS")), "numpy" in sys.modules)
"""


def _probe(*args: str, **env: str) -> str:
    environ = {k: v for k, v in os.environ.items() if k not in BLAS_THREADS_ENV}
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *args],
        capture_output=True,
        text=True,
        env={**environ, **env},
        check=False,
        timeout=120,
    )
    return done.stdout.strip().splitlines()[-1]


def test_reading_a_file_starts_numpy_with_one_blas_thread() -> None:
    assert _probe("info", str(TSURF)) == "'1' True"


def test_a_count_the_user_chose_is_kept() -> None:
    assert _probe("info", str(TSURF), OPENBLAS_NUM_THREADS="3") == "'3' True"
    assert _probe("info", str(TSURF), OMP_NUM_THREADS="2") == "None True"


def test_fitting_keeps_openblas_threads() -> None:
    assert _probe("fit", "--help") == "None True"


@pytest.mark.parametrize(
    ("argv", "one"),
    [
        ([], True),
        (["--help"], True),
        (["info", "x.ts"], True),
        (["-v", "convert", "a.ts", "--to", "vtu"], True),
        (["blocks", "in.ts", "out.geobrep"], True),
        (["fit", "points.csv", "out.ts"], False),
        (["run", "pipeline.yaml"], False),
        (["map", "x"], False),
        (["demo"], False),
        (["a-plugin-command", "x"], False),
    ],
)
def test_which_commands_take_one_thread(argv: list[str], one: bool) -> None:
    assert _one_blas_thread_suffices(argv) is one


def test_too_late_once_numpy_is_loaded() -> None:
    assert "numpy" in sys.modules  # the suite imports it
    environ: dict[str, str] = {}
    assert one_blas_thread(environ) is False
    assert environ == {}
