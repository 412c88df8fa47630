"""The readers' own fuzz test (issue 15, "Done when"): mutated files of every format that can read
give a scene or a clean geobrep error, never an internal exception or the catch-all rewrap.

Seeds are the files of ``tests/data`` (all subfolders) and files geobrep writes in every format
(see ``fuzzing.py``); mutations are byte flips, truncation, duplicated and dropped chunks or
lines, huge numbers in place of numbers, junk and splices. The budget is small and fixed
(:data:`EXAMPLES` per format, derandomised) so that this runs in seconds in ``make test``;
``make fuzz`` runs 25,000 cases with memory and time measured. Each read has a 30 s hang
guard: a guard, not a timing assertion.
"""

from __future__ import annotations

import functools
import tempfile
import threading
from pathlib import Path

import fuzzing
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EXAMPLES = 50
HANG_GUARD = 30.0


@functools.cache
def _seeds() -> dict[str, list[fuzzing.Seed]]:
    return fuzzing.all_seeds(Path(tempfile.mkdtemp(prefix="geobrep-fuzz-seeds-")))


def _guarded(path: Path) -> fuzzing.Verdict:
    """The verdict on reading ``path``, or a failure if the read is still running after the
    hang guard (the thread is left behind: the test fails anyway)."""
    result: list[fuzzing.Verdict] = []
    reader = threading.Thread(target=lambda: result.append(fuzzing.verdict(path)), daemon=True)
    reader.start()
    reader.join(HANG_GUARD)
    if not result:
        return fuzzing.Verdict("failure", f"no answer after {HANG_GUARD} s (hang guard)")
    return result[0]


def test_every_reading_format_has_seeds() -> None:
    assert sorted(_seeds()) == fuzzing.reading_formats()


def test_catch_all_rewrap_is_recognised() -> None:
    """The test would miss the defect it hunts if this did not hold."""
    from geobrep.errors import FormatError

    assert fuzzing.catch_all_rewrap(FormatError("ply reader failed: KeyError: 'id'", "a.ply"))
    assert not fuzzing.catch_all_rewrap(FormatError("element 'vertex' declares 9 rows", "a.ply"))


STEPS = st.lists(
    st.tuples(st.sampled_from(sorted(fuzzing.MUTATIONS)), st.integers(0, 2**32 - 1)),
    min_size=1,
    max_size=3,
)


@pytest.mark.parametrize("format_name", fuzzing.reading_formats())
@settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(data=st.data())
def test_mutated_file_reads_or_fails_cleanly(
    format_name: str, data: st.DataObject, tmp_path_factory: pytest.TempPathFactory
) -> None:
    seeds = _seeds()[format_name]
    seed = data.draw(st.sampled_from(seeds), label="seed")
    other = data.draw(st.sampled_from(seeds), label="other seed")
    steps = data.draw(STEPS, label="mutations")
    folder = tmp_path_factory.mktemp(format_name)
    path = fuzzing.write_case(folder, seed, fuzzing.mutate(seed, other, steps))
    judged = _guarded(path)
    assert not judged.failed, f"{seed.origin} {steps}: {judged.message}"
