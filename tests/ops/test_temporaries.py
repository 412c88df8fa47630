"""Temporaries of killed writes are found and removed; live ones and other files are kept."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.cli.main import main
from geobrep.ops.io import atomic_write
from geobrep.ops.temporaries import find_temporaries, parse_temporary, remove_stale_temporaries

GUARD = 120  # seconds: a hang guard, not a timing assertion
CHUNK = 1 << 20

#: A child that writes ``big.ply`` through geobrep.write with a writer that writes 64 MB, says
#: so, and then waits to be killed.
SLOW_WRITER = """
import sys, time
import geobrep
from geobrep.plugins import FormatSpec, hookimpl, register

def write(scene, path, options):
    with open(path, "wb") as stream:
        for _ in range(64):
            stream.write(b"x" * CHUNK)
        stream.flush()
        print(path.name, flush=True)
        time.sleep(600)

class Slow:
    @hookimpl
    def geobrep_register_formats(self, registry):
        registry.add(FormatSpec(name="slow", extensions=(".ply",), writer=write))

register(Slow(), "slow")
geobrep.write(geobrep.PointSet(name="p", vertices=[[0.0, 0.0, 0.0]]), sys.argv[1], format="slow")
""".replace("CHUNK", str(CHUNK))


def killed_write(target: Path) -> Path:
    """Start a write of ``target`` in a child, SIGKILL it mid-way; the temporary it left."""
    child = subprocess.Popen(
        [sys.executable, "-c", SLOW_WRITER, str(target)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout is not None
        name = child.stdout.readline().strip()
        assert name, child.stderr.read() if child.stderr else ""
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=GUARD)
    assert child.returncode == -signal.SIGKILL
    leftover = target.with_name(name)
    assert leftover.stat().st_size == 64 * CHUNK
    assert parse_temporary(name) == (child.pid, target.stem)
    return leftover


@pytest.fixture
def sleeper() -> Iterator[subprocess.Popen[bytes]]:
    """A running process (to own 'live' temporaries), ended afterwards."""
    process = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    yield process
    process.kill()
    process.wait(timeout=GUARD)


def points(n: int = 10) -> geobrep.PointSet:
    return geobrep.PointSet(name="p", vertices=np.arange(3.0 * n).reshape(n, 3))


def test_a_killed_write_leaves_a_temporary_that_the_next_write_removes(tmp_path: Path) -> None:
    target = tmp_path / "big.ply"
    geobrep.write(points(), target)
    before = target.read_bytes()
    leftover = killed_write(target)
    assert target.read_bytes() == before  # the kill did not touch the target
    other = tmp_path / "other.ply"
    geobrep.write(points(), other)
    assert leftover.exists()  # a write of another target leaves it alone
    geobrep.write(points(20), target)
    assert not leftover.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.ply", "other.ply"]
    assert len(geobrep.read(target).entities[0].vertices) == 20


def test_a_temporary_of_a_running_process_is_kept(
    tmp_path: Path, sleeper: subprocess.Popen[bytes]
) -> None:
    target = tmp_path / "model.ply"
    live = tmp_path / f".model.tmp-{sleeper.pid}-0a1b2c3d.ply"
    live.write_bytes(b"being written")
    geobrep.write(points(), target)
    assert live.read_bytes() == b"being written"
    mine = tmp_path / f".model.tmp-{os.getpid()}-0a1b2c3d.ply"  # another thread of this process
    mine.write_bytes(b"mine")
    assert remove_stale_temporaries(target) == []


def test_a_reused_pid_does_not_keep_a_temporary(
    tmp_path: Path, sleeper: subprocess.Popen[bytes]
) -> None:
    if not Path(f"/proc/{sleeper.pid}/stat").exists():
        pytest.skip("process start times come from /proc")
    old = tmp_path / f".model.tmp-{sleeper.pid}-0a1b2c3d.ply"
    old.write_bytes(b"from a process that had this pid before")
    an_hour_ago = time.time() - 3600
    os.utime(old, (an_hour_ago, an_hour_ago))
    assert remove_stale_temporaries(tmp_path / "model.ply") == [old]


def test_nested_temporaries_are_found_for_their_target(tmp_path: Path) -> None:
    dead = dead_pid()
    nested = tmp_path / f"..model.tmp-{dead}-0a1b2c3d.tmp-{dead}-1a2b3c4d.geobrep"
    nested.write_bytes(b"inner temporary of an atomic writer inside atomic_write")
    staging = tmp_path / f".model.tmp-{dead}-2b3c4d5e.set"
    staging.mkdir()
    (staging / "model.dbf").write_bytes(b"a shapefile set being staged")
    with atomic_write(tmp_path / "model.geobrep") as temporary:
        temporary.write_text("new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.geobrep"]


def dead_pid() -> int:
    """The pid of a process that has ended."""
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait(timeout=GUARD)
    return process.pid


def test_geobrep_clean_removes_stale_and_keeps_live_and_other_files(
    tmp_path: Path, sleeper: subprocess.Popen[bytes], capsys: pytest.CaptureFixture[str]
) -> None:
    stale = killed_write(tmp_path / "big.ply")
    sub = tmp_path / "sub"
    sub.mkdir()
    deeper = sub / f".deep.tmp-{dead_pid()}-0a1b2c3d.vtu"
    deeper.write_bytes(b"stale too")
    live = tmp_path / f".run.tmp-{sleeper.pid}-0a1b2c3d.vtu"
    live.write_bytes(b"live")
    others = [
        tmp_path / "big.ply.tmp",
        tmp_path / ".hidden",
        tmp_path / f".x.tmp-{dead_pid()}-notahex1.vtu",  # not 8 hex digits
        tmp_path / f"x.tmp-{dead_pid()}-0a1b2c3d.vtu",  # not hidden
        tmp_path / "model.vtu",
    ]
    for path in others:
        path.write_text("keep me")
    everything = {p for p in tmp_path.rglob("*")}

    assert main(["clean", str(tmp_path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert f"would remove  {stale}  (67.1 MB, process" in out
    assert f"kept  {live}" in out
    assert out.rstrip().endswith(
        "would remove 1 stale temporary (67.1 MB); kept 1 of running processes"
    )
    assert {p for p in tmp_path.rglob("*")} == everything

    assert main(["clean", str(tmp_path), "--recursive", "--json"]) == 0
    rows = {Path(row["path"]).name: row for row in json.loads(capsys.readouterr().out)}
    assert {name: row["action"] for name, row in rows.items()} == {
        stale.name: "removed",
        deeper.name: "removed",
        live.name: "kept",
    }
    assert rows[stale.name]["bytes"] == 64 * CHUNK
    assert {p for p in tmp_path.rglob("*")} == everything - {stale, deeper}
    assert [t.path for t in find_temporaries(tmp_path, recursive=True)] == [live]


def test_geobrep_clean_needs_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["clean", str(tmp_path / "missing")]) == 1
    assert "not a folder" in capsys.readouterr().err


def _legacy(folder: Path, name: str, hours: float) -> Path:
    """A temporary named as geobrep wrote them before issue 15 (``.tmp-{8 hex}``, no pid)."""
    path = folder / name
    path.write_bytes(b"x" * 1000)
    when = time.time() - hours * 3600
    os.utime(path, (when, when))
    return path


def test_temporaries_of_earlier_versions_are_stale_after_a_day(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Earlier geobrep named temporaries .{stem}.tmp-{token_hex(4)}{suffix}: no pid to check."""
    old = _legacy(tmp_path, ".model.tmp-1530bb30.vtu", hours=30)
    nested = _legacy(tmp_path, "..model.tmp-1530bb30.tmp-0a1b2c3d.vtu", hours=25)
    recent = _legacy(tmp_path, ".model.tmp-2b3c4d5e.vtu", hours=2)
    others = [
        _legacy(tmp_path, ".model.tmp-1530bb3.vtu", hours=30),  # 7 hex digits
        _legacy(tmp_path, ".model.tmp-1530BB30.vtu", hours=30),  # not lower-case hex
        _legacy(tmp_path, "model.tmp-1530bb30.vtu", hours=30),  # not hidden
    ]
    found = {t.path: t for t in find_temporaries(tmp_path)}
    assert set(found) == {old, nested, recent}
    assert [found[p].stale for p in (old, nested, recent)] == [True, True, False]
    assert found[old].pid is None

    assert main(["clean", str(tmp_path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert f"would remove  {old}  (0.0 MB, an earlier geobrep's (no pid), last modified 30" in out
    assert f"kept  {recent}  (0.0 MB, an earlier geobrep's (no pid), last modified 2.0 h" in out
    assert out.rstrip().endswith(
        "would remove 2 stale temporaries (0.0 MB); kept 0 of running processes and 1 of "
        "earlier geobrep versions under a day old"
    )
    assert all(p.exists() for p in (old, nested, recent, *others))

    assert main(["clean", str(tmp_path), "--json"]) == 0
    rows = {Path(row["path"]).name: row for row in json.loads(capsys.readouterr().out)}
    assert {name: (row["action"], row["pid"]) for name, row in rows.items()} == {
        old.name: ("removed", None),
        nested.name: ("removed", None),
        recent.name: ("kept", None),
    }
    assert all(p.exists() for p in (recent, *others))


def test_a_write_removes_the_targets_day_old_temporaries_of_earlier_versions(
    tmp_path: Path,
) -> None:
    old = _legacy(tmp_path, ".model.tmp-1530bb30.ply", hours=48)
    recent = _legacy(tmp_path, ".model.tmp-2b3c4d5e.ply", hours=1)
    other_target = _legacy(tmp_path, ".other.tmp-1530bb30.ply", hours=48)
    geobrep.write(geobrep.PointSet(name="p", vertices=np.zeros((1, 3))), tmp_path / "model.ply")
    assert not old.exists()
    assert recent.exists()
    assert other_target.exists()


# -- replacing a large file without waiting for its blocks to be freed ---------------------------


def _big(path: Path, byte: bytes) -> Path:
    from geobrep.ops.temporaries import BACKGROUND_FREE_BYTES

    path.write_bytes(byte * BACKGROUND_FREE_BYTES)
    return path


def test_replace_file_swaps_a_large_file_and_frees_the_old_one_later(tmp_path: Path) -> None:
    from geobrep.ops.temporaries import finish_freeing, replace_file

    target, source = _big(tmp_path / "m.h5", b"o"), _big(tmp_path / "new.h5", b"n")
    old_inode = target.stat().st_ino
    with target.open("rb") as reader:  # a reader of the old file keeps reading it whole
        replace_file(source, target)
        assert reader.read(4) == b"oooo"
    assert target.read_bytes()[:4] == b"nnnn"
    assert target.stat().st_ino != old_inode
    finish_freeing()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.h5"]


def test_replace_file_of_small_files_and_without_hard_links_is_a_rename(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from geobrep.ops.temporaries import finish_freeing, replace_file

    def no_links(*_: object) -> None:
        raise OSError("no hard links on this file system")

    monkeypatch.setattr(os, "link", no_links)
    small, source = tmp_path / "s.txt", tmp_path / "t.txt"
    small.write_text("old")
    source.write_text("new")
    replace_file(source, small)  # small: os.link is not even tried
    assert small.read_text() == "new"
    target, source = _big(tmp_path / "m.h5", b"o"), _big(tmp_path / "n.h5", b"n")
    replace_file(source, target)  # large, but os.link fails: a plain rename
    finish_freeing()
    assert target.read_bytes()[:1] == b"n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.h5", "s.txt"]


def test_a_failed_replace_leaves_the_target_and_no_second_name(tmp_path: Path) -> None:
    from geobrep.ops.temporaries import replace_file

    target = _big(tmp_path / "m.h5", b"o")
    with pytest.raises(FileNotFoundError):
        replace_file(tmp_path / "missing.h5", target)
    assert target.read_bytes()[:1] == b"o"
    assert [p.name for p in tmp_path.iterdir()] == ["m.h5"]


def test_a_write_over_a_large_file_leaves_only_the_file(tmp_path: Path) -> None:
    from geobrep.ops.temporaries import BACKGROUND_FREE_BYTES, finish_freeing

    side = 800
    x, y = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    points = geobrep.PointSet(vertices=np.column_stack([x.ravel(), y.ravel(), x.ravel() * 0]))
    path = geobrep.write(points, tmp_path / "p.geobrep")
    first = path.read_bytes()
    assert len(first) >= BACKGROUND_FREE_BYTES  # freed in the background
    moved = points.replace(vertices=points.vertices + 1.0)
    geobrep.write(moved, path)
    finish_freeing()
    assert path.read_bytes() != first
    assert [p.name for p in tmp_path.iterdir()] == ["p.geobrep"]
    assert geobrep.read(path).entities[0].vertices.tobytes() == moved.vertices.tobytes()
