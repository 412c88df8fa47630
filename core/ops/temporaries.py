"""Temporary files of interrupted writes: their names, whose they are, and removing stale ones.

:func:`geobrep.ops.io.atomic_write` writes ``model.vtu`` through ``.model.tmp-{pid}-{random}.vtu``
beside it (``{pid}`` is the writing process, ``{random}`` 8 hex digits) and renames it into
place. A process that is killed leaves its temporary behind; the next :func:`atomic_write` of
the same target, or ``geobrep clean FOLDER``, removes it once its process is gone.

A temporary is **stale** when no process with its pid runs, or when the process that has that
pid started after the file was last modified (the pid was reused). Only processes of this
machine (and PID namespace) can be seen: do not clean a folder that a writer on another machine
is writing into. On Windows nothing is considered stale.

geobrep before issue 15 named temporaries ``.{stem}.tmp-{random}{suffix}``, without a pid
(:data:`LEGACY_TEMPORARY_PATTERN`). No process can be checked for those: one is stale when it
was last modified more than :data:`LEGACY_STALE_AGE` ago (a day), far longer than any write.

Example:
    >>> parse_temporary(".model.tmp-4242-0a1b2c3d.vtu")
    (4242, 'model')
    >>> parse_temporary("model.vtu") is None
    True
    >>> parse_legacy_temporary(".model.tmp-0a1b2c3d.vtu")
    'model'
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
import stat
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "LEGACY_STALE_AGE",
    "LEGACY_TEMPORARY_PATTERN",
    "TEMPORARY_PATTERN",
    "Temporary",
    "find_temporaries",
    "finish_freeing",
    "parse_legacy_temporary",
    "parse_temporary",
    "remove_stale_temporaries",
    "replace_file",
    "temporary_path",
]

TEMPORARY_PATTERN = re.compile(
    r"^\.(?P<stem>.+)\.tmp-(?P<pid>[1-9][0-9]{0,9})-(?P<token>[0-9a-f]{8})(?P<suffix>\.[^.]+)?$"
)
"""The name of a geobrep temporary: ``.{stem}.tmp-{pid}-{8 hex digits}{suffix}``."""

LEGACY_TEMPORARY_PATTERN = re.compile(
    r"^\.(?P<stem>.+)\.tmp-(?P<token>[0-9a-f]{8})(?P<suffix>\.[^.]+)?$"
)
"""The name earlier geobrep versions gave a temporary: ``.{stem}.tmp-{8 hex digits}{suffix}``."""

LEGACY_STALE_AGE = 24 * 3600.0
"""Seconds after its last change when a temporary without a pid (:data:`LEGACY_TEMPORARY_PATTERN`)
is stale: a day."""

_SLACK = 2.0
"""Seconds of doubt between a file's time and a process's start (boot time has 1 s steps)."""


def temporary_path(final: Path, suffix: str | None = None) -> Path:
    """A fresh temporary name beside ``final`` for this process (``suffix``: final's by default).

    >>> temporary_path(Path("out/model.vtu")).name.startswith(".model.tmp-")
    True
    """
    ending = "".join(final.suffixes[-1:]) if suffix is None else suffix
    token = secrets.token_hex(4)
    return final.with_name(f".{final.stem}.tmp-{os.getpid()}-{token}{ending}")


BACKGROUND_FREE_BYTES = 8 << 20
"""A replaced file at least this large (8 MiB) is unlinked by a background thread."""

_freeing: list[Any] = []
"""The one thread that unlinks replaced files (made on first use; joined at exit)."""


def _free_later(path: Path) -> None:
    if not _freeing:
        from concurrent.futures import ThreadPoolExecutor

        _freeing.append(ThreadPoolExecutor(max_workers=1, thread_name_prefix="geobrep-free"))
    _freeing[0].submit(_unlink_quietly, path)


def finish_freeing() -> None:
    """Wait until every file :func:`replace_file` replaced is unlinked."""
    if _freeing:
        _freeing[0].submit(lambda: None).result()


def _unlink_quietly(path: Path) -> None:
    # on an error it is left as a stale temporary: the next write or ``geobrep clean`` finds it
    with contextlib.suppress(OSError):
        path.unlink(missing_ok=True)


def replace_file(source: Path, target: Path) -> None:
    """``os.replace(source, target)``, as atomic, without waiting for the replaced file's
    blocks to be freed.

    Freeing a large file (tens of milliseconds for tens of MB on ext4, the cost of a whole
    write of a small model) is the slow part of a rename onto an existing file. A regular file
    of at least :data:`BACKGROUND_FREE_BYTES` that ``target`` names keeps a second name, a
    temporary of this process beside ``target``; ``source`` is renamed onto ``target`` (readers
    see the old file or the new one, never neither), and a background thread unlinks the
    temporary (the interpreter waits for it at exit; :func:`finish_freeing` waits now). Should
    the process die first, the temporary is stale and removed by the next write of ``target``
    or ``geobrep clean``. Without hard links, a plain :func:`os.replace`.
    """
    try:
        old = os.lstat(target)
    except OSError:
        old = None
    large = (
        old is not None
        and stat.S_ISREG(old.st_mode)
        and old.st_nlink == 1
        and old.st_size >= BACKGROUND_FREE_BYTES
    )
    keep = temporary_path(target) if large else None
    if keep is not None:
        try:
            os.link(target, keep)
        except OSError:  # a file system without hard links, or the target just went
            keep = None
    try:
        os.replace(source, target)
    except BaseException:
        if keep is not None:
            _unlink_quietly(keep)
        raise
    if keep is not None:
        _free_later(keep)


def parse_temporary(name: str) -> tuple[int, str] | None:
    """``(pid, stem)`` of a temporary's file name, or ``None`` if it is not one."""
    match = TEMPORARY_PATTERN.match(name)
    if match is None:
        return None
    return int(match["pid"]), match["stem"].lstrip(".").split(".tmp-")[0]


def parse_legacy_temporary(name: str) -> str | None:
    """The target's stem of an earlier geobrep's temporary name (no pid), or ``None``."""
    if TEMPORARY_PATTERN.match(name):
        return None
    match = LEGACY_TEMPORARY_PATTERN.match(name)
    if match is None:
        return None
    return match["stem"].lstrip(".").split(".tmp-")[0]


def _process_start(pid: int) -> float | None:
    """When process ``pid`` started (seconds since the epoch), where the system says (Linux)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        boot = next(
            line for line in Path("/proc/stat").read_text().splitlines() if line.startswith("btime")
        )
        ticks = int(stat.rsplit(")", 1)[1].split()[19])
        return int(boot.split()[1]) + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, StopIteration):
        return None


def _owner_running(pid: int, modified: float) -> bool:
    """Whether the process that wrote a temporary last modified at ``modified`` still runs."""
    if os.name == "nt":
        return True  # os.kill would end the process; assume it runs
    if pid != os.getpid():
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except (PermissionError, OverflowError):
            return pid > 0  # another user's process (or a pid out of range: none)
        except OSError:
            return True
    start = _process_start(pid)
    return start is None or modified >= start - _SLACK


@dataclass(frozen=True)
class Temporary:
    """A geobrep temporary found in a folder."""

    path: Path
    pid: int | None
    """The writing process; ``None`` for a temporary of an earlier geobrep (no pid in its name)."""
    stale: bool
    size: int
    age: float = 0.0
    """Seconds since it was last modified (when it was found)."""

    @property
    def reason(self) -> str:
        """Why it is stale or kept, in words."""
        if self.pid is None:
            hours = f"last modified {self.age / 3600:.1f} h ago"
            if self.stale:
                return f"an earlier geobrep's (no pid), {hours}"
            return (
                f"an earlier geobrep's (no pid), {hours}: kept until "
                f"{LEGACY_STALE_AGE / 3600:.0f} h old"
            )
        if self.stale:
            return f"process {self.pid} is gone"
        return f"process {self.pid} is running"


def _size(path: Path) -> int:
    try:
        if path.is_dir() and not path.is_symlink():
            return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
        return path.lstat().st_size
    except OSError:
        return 0


def _examine(path: Path) -> Temporary | None:
    parsed = parse_temporary(path.name)
    if parsed is None and parse_legacy_temporary(path.name) is None:
        return None
    try:
        modified = path.lstat().st_mtime
    except OSError:
        return None  # gone meanwhile
    age = time.time() - modified
    if parsed is None:  # an earlier geobrep's: no process to ask, only its age
        stale = os.name != "nt" and age > LEGACY_STALE_AGE
        return Temporary(path=path, pid=None, stale=stale, size=_size(path), age=age)
    stale = not _owner_running(parsed[0], modified)
    return Temporary(path=path, pid=parsed[0], stale=stale, size=_size(path), age=age)


def _entries(folder: Path, recursive: bool) -> Iterator[Path]:
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith(".") and ".tmp-" in entry.name:
            yield Path(entry.path)
        elif recursive and entry.is_dir(follow_symlinks=False):
            yield from _entries(Path(entry.path), recursive)


def find_temporaries(folder: Path | str, *, recursive: bool = False) -> list[Temporary]:
    """The geobrep temporaries in ``folder`` (and below, if ``recursive``), by path."""
    found = (_examine(path) for path in _entries(Path(folder), recursive))
    return sorted((t for t in found if t is not None), key=lambda t: str(t.path))


def remove(temporary: Temporary) -> bool:
    """Delete a temporary (a file, or a folder of a shapefile set); False if that failed."""
    try:
        if temporary.path.is_dir() and not temporary.path.is_symlink():
            shutil.rmtree(temporary.path)
        else:
            temporary.path.unlink()
    except FileNotFoundError:
        return True
    except OSError:
        return False
    return True


def remove_stale_temporaries(final: Path) -> list[Path]:
    """Remove the stale temporaries of target ``final`` (any suffix); the paths removed.

    Best effort: a temporary that cannot be removed is left for ``geobrep clean``.
    """
    prefix = f"{final.stem}.tmp-"
    try:  # names only, filtered in one pass: a batch writes thousands of files to one folder
        names = os.listdir(final.parent)
    except OSError:
        return []
    removed: list[Path] = []
    for name in names:
        if not (name.startswith(".") and ".tmp-" in name and name.lstrip(".").startswith(prefix)):
            continue
        path = final.parent / name
        temporary = _examine(path)
        if temporary is not None and temporary.stale and remove(temporary):
            removed.append(path)
    return removed
