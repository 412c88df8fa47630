"""Check that a change leaves every Model3d read exactly as it was (issue 17, part 2).

Run ``.venv/bin/python tools/model3d_identity.py save DIR`` on the code before a change and
``.venv/bin/python tools/model3d_identity.py check DIR`` after it: every ``.ml`` file of
tests/data, its TSurf files with BSTONEs and the generated Model3d files of
benchmarks/_inputs.py are read (with and without repair), and each scene (corners, arcs with
their patch order, patches, blocks and their sides, surfaces, groups, metadata) and the warnings
of its read must be identical, bit for bit, to the saved ones.
"""

from __future__ import annotations

import argparse
import pickle
import struct
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import geobrep

ROOT = Path(__file__).resolve().parent.parent
sys.path.append(str(ROOT / "benchmarks"))


def _files(folder: Path) -> list[Path]:
    from _inputs import model3d_files

    folder.mkdir(parents=True, exist_ok=True)
    data = ROOT / "tests" / "data"
    with_borders = [p for p in sorted(data.rglob("*.ts")) if b"BSTONE" in p.read_bytes()]
    return sorted(data.rglob("*.ml")) + with_borders + model3d_files(folder)


def plain(value: Any) -> Any:
    """``value`` as plain Python data that pickles and compares bit for bit: models as their
    type name and fields, arrays as dtype, shape and bytes, floats as their bits."""
    fields = getattr(type(value), "model_fields", None)
    if fields is not None:
        return (type(value).__name__, {name: plain(getattr(value, name)) for name in fields})
    if isinstance(value, np.ndarray):
        return ("ndarray", str(value.dtype), value.shape, np.ascontiguousarray(value).tobytes())
    if isinstance(value, dict):
        return {key: plain(item) for key, item in value.items()}
    if isinstance(value, tuple | list):
        return [plain(item) for item in value]
    if isinstance(value, float):
        return ("float", struct.pack("<d", value))
    if isinstance(value, np.generic):
        return plain(value.item())
    return value


def _read(path: Path, repair: bool) -> tuple[Any, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            scene: Any = plain(geobrep.read(path, repair=repair))
        except geobrep.errors.GeobrepError as exc:
            scene = f"{type(exc).__name__}: {exc}"
    return scene, [str(w.message) for w in caught]


def _first_difference(a: Any, b: Any, where: str = "scene") -> str:
    """Where two structures first differ (a path such as ``scene.topology.arcs[3].patches``)."""
    if type(a) is not type(b):
        return f"{where}: {type(a).__name__} != {type(b).__name__}"
    if isinstance(a, tuple | list) and len(a) == len(b):
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            if x != y:
                return _first_difference(x, y, f"{where}[{k}]")
    if isinstance(a, dict) and a.keys() == b.keys():
        for key in a:
            if a[key] != b[key]:
                return _first_difference(a[key], b[key], f"{where}[{key!r}]")
    return f"{where}: {a!r:.200} != {b!r:.200}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("action", choices=("save", "check"))
    parser.add_argument("folder", type=Path, help="where the reads are saved / compared")
    args = parser.parse_args()
    args.folder.mkdir(parents=True, exist_ok=True)
    failures = 0
    for path in _files(args.folder / "inputs"):
        for repair in (True, False):
            saved = args.folder / f"{path.parent.name}_{path.name}.repair_{repair}.pickle"
            read = _read(path, repair)
            if args.action == "save":
                saved.write_bytes(pickle.dumps(read))
                print(f"saved {path.name} (repair={repair})")
                continue
            before = pickle.loads(saved.read_bytes())
            if before == read:
                print(f"same  {path.name} (repair={repair})")
                continue
            failures += 1
            what = (
                _first_difference(before[0], read[0])
                if before[0] != read[0]
                else f"warnings: {before[1]} != {read[1]}"
            )
            print(f"DIFF  {path.name} (repair={repair}): {what}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
