"""The readers' large fuzz run (``make fuzz``): many mutated files, each read in a worker process
with its memory and time measured.

Every case is a seed file (``tests/data`` and files geobrep writes, see
``tests/reliability/fuzzing.py``) with one to three mutations, read by ``geobrep.read``. A case
fails when the read raises anything but a result or an apt geobrep error (a FormatError that is
``geobrep.read``'s catch-all rewrap counts as a failure), when it takes longer than
``--timeout`` seconds (the worker is killed), or when its peak resident memory over the
worker's memory before the read exceeds max(256 MB, 20 x the file's size). Cases are
reproducible: case ``i`` of ``--seed s`` is always the same file.

    .venv/bin/python benchmarks/fuzz.py [--cases 25000] [--workers N] [--timeout 10]
                                        [--seed 0] [--keep-failures DIR]

Prints, per format, the cases, results, FormatErrors, other accepted errors and failures; the
slowest case; the largest peak memory; and each failure (with its case number).
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing
import os
import random
import sys
import tempfile
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "reliability"))

import fuzzing

MIB = 2**20


def _status(key: str) -> int:
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith(key):
                return int(line.split()[1]) * 1024
    return 0


def _reset_peak() -> None:
    """Reset the process's peak RSS (Linux). Where that is refused the peak keeps earlier
    reads, so a case's measure can only be too high: the memory bound never passes wrongly."""
    with contextlib.suppress(OSError), open("/proc/self/clear_refs", "w") as handle:
        handle.write("5")


def case_of(number: int, base: int, seeds: dict[str, list[fuzzing.Seed]]) -> tuple[Any, ...]:
    """The format, seed, other seed and mutation steps of case ``number`` (formats in turn)."""
    rng = random.Random(f"{base}:{number}")
    formats = sorted(seeds)
    name = formats[number % len(formats)]
    seed = rng.choice(seeds[name])
    other = rng.choice(seeds[name])
    return name, seed, other, fuzzing.random_steps(rng)


@dataclass
class Outcome:
    number: int
    format: str
    kind: str
    message: str
    seconds: float
    peak_over: int
    size: int
    origin: str
    steps: list[tuple[str, int]]


def _worker(
    connection: Connection, folder: str, base: int, seeds: dict[str, list[fuzzing.Seed]]
) -> None:
    import resource
    import warnings

    import geobrep.host

    warnings.simplefilter("ignore")
    quiet = os.open(os.devnull, os.O_WRONLY)  # VTK and GDAL print every error they meet
    os.dup2(quiet, 1)
    os.dup2(quiet, 2)
    geobrep.host.registries()
    for module in ("plyfile", "meshio", "pyogrio", "pyvista", "vtk"):
        with contextlib.suppress(ImportError):
            __import__(module)
    # a guard on the whole machine: a runaway case gets a MemoryError, not the OOM killer
    limit = _status("VmSize:") + 6 * 1024 * MIB
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    work = Path(folder) / f"worker-{os.getpid()}"
    connection.send("ready")
    while True:
        number = connection.recv()
        if number is None:
            return
        name, seed, other, steps = case_of(number, base, seeds)
        data = fuzzing.mutate(seed, other, steps)
        path = fuzzing.write_case(work, seed, data)
        _reset_peak()
        before = _status("VmRSS:")
        start = time.perf_counter()
        judged = fuzzing.verdict(path)
        seconds = time.perf_counter() - start
        peak = max(0, _status("VmHWM:") - before)
        message = judged.message[:400]
        outcome = Outcome(
            number, name, judged.kind, message, seconds, peak, len(data), seed.origin, steps
        )
        connection.send(outcome)


class Pool:
    """Worker processes fed one case at a time; a worker past the time limit is killed."""

    def __init__(
        self, workers: int, folder: str, base: int, seeds: dict[str, list[fuzzing.Seed]]
    ) -> None:
        self.folder, self.base, self.seeds = folder, base, seeds
        self.context = multiprocessing.get_context("spawn")
        self.slots: list[list[Any]] = [self._start() for _ in range(workers)]

    def _start(self) -> list[Any]:
        parent, child = self.context.Pipe()
        process = self.context.Process(
            target=_worker, args=(child, self.folder, self.base, self.seeds), daemon=True
        )
        process.start()
        if not parent.poll(300) or parent.recv() != "ready":
            raise RuntimeError("a fuzz worker did not start")
        return [process, parent, None, 0.0]  # process, pipe, case, started

    def run(self, cases: range, timeout: float, done: Any) -> None:
        pending = iter(cases)
        for slot in self.slots:
            self._feed(slot, pending)
        while any(slot[2] is not None for slot in self.slots):
            ready = wait([s[1] for s in self.slots if s[2] is not None], timeout=0.5)
            now = time.perf_counter()
            for slot in self.slots:
                if slot[2] is None:
                    continue
                if slot[1] in ready:
                    try:
                        done(slot[1].recv())
                    except EOFError:  # the worker died (a crash in a library)
                        done(self._lost(slot, "worker died"))
                        self._restart(slot)
                    self._feed(slot, pending)
                elif now - slot[3] > timeout + 2 or not slot[0].is_alive():
                    reason = "worker died" if not slot[0].is_alive() else f"over {timeout} s"
                    done(self._lost(slot, reason))
                    self._restart(slot)
                    self._feed(slot, pending)

    def _lost(self, slot: list[Any], reason: str) -> Outcome:
        name, seed, _, steps = case_of(slot[2], self.base, self.seeds)
        spent = time.perf_counter() - slot[3]
        return Outcome(slot[2], name, "failure", reason, spent, 0, 0, seed.origin, steps)

    def _restart(self, slot: list[Any]) -> None:
        slot[0].kill()
        slot[0].join()
        slot[:] = self._start()

    def _feed(self, slot: list[Any], pending: Any) -> None:
        number = next(pending, None)
        slot[2] = number
        slot[3] = time.perf_counter()
        if number is not None:
            slot[1].send(number)

    def close(self) -> None:
        for process, pipe, *_ in self.slots:
            with contextlib.suppress(OSError):
                pipe.send(None)
            process.join(timeout=5)
            if process.is_alive():
                process.kill()


def memory_bound(size: int) -> int:
    """The issue's bound on a read's peak memory: max(256 MB, 20 x the file's size)."""
    return max(256 * MIB, 20 * size)


def judge(outcome: Outcome, timeout: float) -> Outcome:
    """Add the time and memory verdicts to a worker's outcome."""
    if outcome.kind != "failure":
        if outcome.seconds > timeout:
            outcome.kind, outcome.message = "failure", f"took {outcome.seconds:.1f} s"
        elif outcome.peak_over > memory_bound(outcome.size):
            outcome.kind = "failure"
            outcome.message = f"peak memory {outcome.peak_over / MIB:.0f} MB: {outcome.message}"
    return outcome


def report(outcomes: list[Outcome], seconds: float, timeout: float) -> int:
    """Print the figures; the number of failures."""
    table: dict[str, Counter[str]] = defaultdict(Counter)
    for outcome in outcomes:
        kind = outcome.kind if outcome.kind in ("result", "FormatError", "failure") else "other"
        table[outcome.format][kind] += 1
        table[outcome.format]["cases"] += 1
    columns = ("cases", "result", "FormatError", "other", "failure")
    print(f"{'format':<11}" + "".join(f"{c:>13}" for c in columns))
    for name in sorted(table):
        print(f"{name:<11}" + "".join(f"{table[name][c]:>13}" for c in columns))
    total = Counter[str]()
    for counts in table.values():
        total.update(counts)
    print(f"{'all':<11}" + "".join(f"{total[c]:>13}" for c in columns))
    print("(other: UnknownFormatError, FileAccessError or MissingDependencyError)")
    measured = [o for o in outcomes if o.size]
    if measured:
        slow = max(measured, key=lambda o: o.seconds)
        big = max(measured, key=lambda o: o.peak_over)
        print(f"slowest case: #{slow.number} {slow.format} {slow.seconds:.2f} s ({slow.kind}: "
              f"{slow.message[:120]})")  # fmt: skip
        print(f"peak memory: #{big.number} {big.format} {big.peak_over / MIB:.1f} MB over the "
              f"worker's memory before the read (file of {big.size} bytes; bound "
              f"{memory_bound(big.size) / MIB:.0f} MB)")  # fmt: skip
    print(f"{len(outcomes)} cases in {seconds:.0f} s ({len(outcomes) / max(seconds, 1e-9):.0f} "
          f"cases/s), time limit {timeout} s per case")  # fmt: skip
    failures = [o for o in outcomes if o.kind == "failure"]
    for outcome in failures[:50]:
        print(f"FAIL #{outcome.number} {outcome.format} [{outcome.origin} {outcome.steps}]: "
              f"{outcome.message[:300]}")  # fmt: skip
    return len(failures)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=25_000)
    parser.add_argument("--workers", type=int, default=max(1, min(4, os.cpu_count() or 1)))
    parser.add_argument("--timeout", type=float, default=10.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--first", type=int, default=0, help="number of the first case")
    parser.add_argument("--keep-failures", type=Path, default=None)
    args = parser.parse_args(argv)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with tempfile.TemporaryDirectory(prefix="geobrep-fuzz-") as folder:
        seeds = fuzzing.all_seeds(Path(folder) / "seeds")
        print(f"seeds: {sum(map(len, seeds.values()))} files of {len(seeds)} formats "
              f"({', '.join(f'{k} {len(v)}' for k, v in sorted(seeds.items()))})")  # fmt: skip
        missing = sorted(set(fuzzing.reading_formats()) - set(seeds))
        if missing:
            print(f"formats without seeds: {', '.join(missing)}")
        outcomes: list[Outcome] = []
        start = time.perf_counter()
        pool = Pool(args.workers, folder, args.seed, seeds)

        def done(outcome: Outcome) -> None:
            outcomes.append(judge(outcome, args.timeout))
            if len(outcomes) % 1000 == 0:
                print(f"... {len(outcomes)} cases, {sum(o.kind == 'failure' for o in outcomes)} "
                      "failures", flush=True)  # fmt: skip

        try:
            pool.run(range(args.first, args.first + args.cases), args.timeout, done)
        finally:
            pool.close()
        failures = report(sorted(outcomes, key=lambda o: o.number), time.perf_counter() - start,
                          args.timeout)  # fmt: skip
        if args.keep_failures is not None and failures:
            _keep(args.keep_failures, outcomes, seeds, args.seed)
    return 1 if failures else 0


def _keep(folder: Path, outcomes: list[Outcome], seeds: dict[str, list[fuzzing.Seed]],
          base: int) -> None:  # fmt: skip
    """Write each failing case's file into ``folder`` (``<case>-<name>``)."""
    folder.mkdir(parents=True, exist_ok=True)
    for outcome in outcomes:
        if outcome.kind == "failure":
            _, seed, other, steps = case_of(outcome.number, base, seeds)
            (folder / f"{outcome.number}-{seed.name}").write_bytes(
                fuzzing.mutate(seed, other, steps)
            )
    print(f"failing inputs written to {folder}")


if __name__ == "__main__":
    sys.exit(main())
