"""``geobrep clean FOLDER``: remove the temporaries that killed geobrep writes left behind.

Only names of geobrep temporaries (``.{stem}.tmp-{pid}-{8 hex digits}{suffix}``) whose process
is gone are removed (see :mod:`geobrep.ops.temporaries`), and those of earlier geobrep versions
(``.{stem}.tmp-{8 hex digits}{suffix}``, no pid) once a day old; a temporary of a running
process and every other file are kept. ``--dry-run`` lists what would be removed.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from geobrep.errors import FileAccessError
from geobrep.ops.temporaries import find_temporaries, remove

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "clean",
        description=(
            "Remove the temporary files that interrupted (killed) geobrep writes left in FOLDER: "
            "names like .model.tmp-4242-0a1b2c3d.vtu whose process 4242 is gone. Temporaries "
            "of running processes and all other files are kept. Temporaries of earlier geobrep "
            "versions (.model.tmp-0a1b2c3d.vtu, no pid) are removed once a day old."
        ),
    )
    parser.add_argument("folder", type=Path, help="folder to clean")
    parser.add_argument(
        "-n", "--dry-run", action="store_true", help="list what would be removed; remove nothing"
    )
    parser.add_argument("-r", "--recursive", action="store_true", help="clean subfolders too")
    parser.add_argument("--json", action="store_true", help="print JSON for machines")
    parser.set_defaults(run=run)


def _megabytes(size: int) -> str:
    return f"{size / 1e6:.1f} MB"


def run(args: argparse.Namespace) -> int:
    folder: Path = args.folder
    if not folder.is_dir():
        raise FileAccessError("not a folder", folder)
    found = find_temporaries(folder, recursive=args.recursive)
    rows: list[dict[str, Any]] = []
    for temporary in found:
        if not temporary.stale:
            action = "kept"
        elif args.dry_run:
            action = "would remove"
        else:
            action = "removed" if remove(temporary) else "could not remove"
        rows.append(
            {
                "path": str(temporary.path),
                "pid": temporary.pid,
                "bytes": temporary.size,
                "action": action,
                "reason": temporary.reason,
            }
        )
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for row in rows:
        print(f"{row['action']}  {row['path']}  ({_megabytes(row['bytes'])}, {row['reason']})")
    done = [row for row in rows if row["action"] in ("removed", "would remove")]
    failed = [row for row in rows if row["action"] == "could not remove"]
    verb = "would remove" if args.dry_run else "removed"
    kept = [row for row in rows if row["action"] == "kept"]
    recent = sum(row["pid"] is None for row in kept)
    print(
        f"{verb} {len(done)} stale temporar{'y' if len(done) == 1 else 'ies'} "
        f"({_megabytes(sum(row['bytes'] for row in done))}); "
        f"kept {len(kept) - recent} of running processes"
        + (f" and {recent} of earlier geobrep versions under a day old" if recent else "")
        + (f"; could not remove {len(failed)}" if failed else "")
    )
    return 1 if failed else 0
