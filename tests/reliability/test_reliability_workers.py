"""Issue 15 item 2: under ``--jobs N`` a worker's death costs only its own input.

The reproducer's plugin (``jobs_broken_pool/plugin``, a ``PYTHONPATH`` entry) registers a reader
for ``.kill`` files that calls ``os._exit(9)``: before, every pending file failed with
``BrokenProcessPool`` (0 of 20 converted). Now the killer is reported with its exit status and
the pool is rebuilt for the rest.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import geobrep
from geobrep.batch.conversion import WorkerDiedError, run_each, worker_failure

BROKEN_POOL = Path(__file__).resolve().parents[1] / "data" / "reliability" / "jobs_broken_pool"
TRI = Path(__file__).resolve().parents[1] / "data" / "reliability" / "pipeline_traversal" / "in"
GOOD = 8


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    """``in/``: the worker-killing input and GOOD copies of a two-triangle TSurf."""
    folder = tmp_path / "in"
    folder.mkdir()
    shutil.copy(BROKEN_POOL / "in" / "a_worker_killer.kill", folder)
    for number in range(1, GOOD + 1):
        shutil.copy(TRI / "tri.ts", folder / f"good{number:02d}.ts")
    return folder


def _geobrep(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(BROKEN_POOL / "plugin")}
    env.pop("GEOBREP_DISABLE_PLUGINS", None)
    return subprocess.run(
        [sys.executable, "-m", "geobrep.cli", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def _check_good_outputs(out: Path, extension: str) -> None:
    source = geobrep.read(TRI / "tri.ts").surfaces[0]
    written = sorted(out.glob(f"*{extension}"))
    assert [p.name for p in written] == [f"good{n:02d}{extension}" for n in range(1, GOOD + 1)]
    for path in written:
        surface = geobrep.read(path).surfaces[0]
        assert (surface.n_points, surface.n_cells) == (source.n_points, source.n_cells)


def test_convert_jobs_reports_only_the_killer(tmp_path: Path, inputs: Path) -> None:
    result = _geobrep(
        "convert", "in/*", "--to", "vtu", "-o", "out", "--jobs", "2", "--no-progress", cwd=tmp_path
    )
    assert result.returncode == 1, result.stderr
    _check_good_outputs(tmp_path / "out", ".vtu")
    failures = [line for line in result.stderr.splitlines() if "failed:" in line]
    assert failures == ["geobrep: failed: in/a_worker_killer.kill: worker died (exit code 9)"]
    assert "BrokenProcessPool" not in result.stdout + result.stderr
    assert f"{GOOD} converted, 1 failed" in result.stdout


@pytest.mark.parametrize(
    ("args", "converted"),
    [((), 0), (("--jobs", "1"), 0), (("--jobs", "2"), None)],
    ids=["default", "jobs 1", "jobs 2, one input"],
)
def test_in_process_the_killer_ends_the_run(
    tmp_path: Path, inputs: Path, args: tuple[str, ...], converted: int | None
) -> None:
    """As docs/security.md says: without ``--jobs`` (or with one input) inputs are converted in
    geobrep's process, so one whose reader kills it ends the run (no summary, the inputs after
    it not converted); ``--jobs 2`` or more is the remedy."""
    sources = ["in/*"] if converted is not None else ["in/a_worker_killer.kill"]
    result = _geobrep(
        "convert", *sources, "--to", "vtu", "-o", "out", "--no-progress", *args, cwd=tmp_path
    )
    assert result.returncode == 9, result.stderr  # the killer's own exit status
    assert "converted," not in result.stdout  # no summary: the run ended there
    assert not list((tmp_path / "out").glob("*.vtu"))  # the killer sorts first


def test_pipeline_jobs_reports_only_the_killer(tmp_path: Path, inputs: Path) -> None:
    (tmp_path / "p.yaml").write_text(
        "inputs: ['in/*']\noutput: out\nsteps:\n  - write: {format: native}\n", encoding="utf-8"
    )
    result = _geobrep("run", "p.yaml", "--jobs", "3", "--no-progress", cwd=tmp_path)
    assert result.returncode == 1, result.stderr
    _check_good_outputs(tmp_path / "out", ".geobrep")
    failures = [line for line in result.stderr.splitlines() if "failed:" in line]
    assert len(failures) == 1
    assert "a_worker_killer.kill" in failures[0]
    assert "worker died (exit code 9)" in failures[0]
    assert f"{GOOD} done, 1 failed" in result.stdout


def _square_or_die(number: int, deaths: tuple[int, ...]) -> int:
    """``number`` squared; the worker is SIGKILLed (as by the OOM killer) for ``deaths``."""
    if number in deaths:
        os.kill(os.getpid(), signal.SIGKILL)
    if number < 0:
        raise ValueError(f"negative: {number}")
    return number * number


@pytest.mark.parametrize("jobs", [2, 4])
@pytest.mark.parametrize("deaths", [(3,), (0, 7), (2, 3, 4, 5)])
def test_run_each_survives_sigkill(jobs: int, deaths: tuple[int, ...]) -> None:
    numbers = [*range(10), -1]
    outcomes: dict[int, tuple[int | None, BaseException | None]] = {}

    def done(position: int, result: int | None, error: BaseException | None) -> None:
        assert position not in outcomes  # each call is reported once
        outcomes[position] = (result, error)

    run_each(_square_or_die, [(n, deaths) for n in numbers], done, jobs=jobs)
    assert sorted(outcomes) == list(range(len(numbers)))
    for position, number in enumerate(numbers):
        result, error = outcomes[position]
        if number in deaths:
            assert result is None
            assert isinstance(error, WorkerDiedError)
            assert error.exitcode == -signal.SIGKILL
            assert worker_failure(error) == "worker died (signal 9, SIGKILL)"
        elif number < 0:  # an exception is the call's own, not a death
            assert result is None
            assert isinstance(error, ValueError)
            assert worker_failure(error) == "worker failed: ValueError: negative: -1"
        else:
            assert (result, error) == (number * number, None)
