"""The readers' fuzz harness: seeds, mutations and the verdict on one mutated file (issue 15).

Shared by ``tests/reliability/test_fuzz_readers.py`` (a small fixed budget in ``make test``) and
``benchmarks/fuzz.py`` (``make fuzz``: 25,000 cases, memory and time measured per case).

- **Seeds**: every file under ``tests/data`` (all subfolders) that a registered reader claims,
  plus a few files geobrep writes in every format that can both write and read, so each reader
  has seeds. Files over :data:`SEED_BYTES` contribute their first :data:`SEED_BYTES`.
- **Mutations** (:data:`MUTATIONS`): byte flips, truncation, duplicated and dropped chunks or
  lines, huge (and negative, NaN, infinite) numbers in place of numbers, junk inserted, a splice
  with another seed of the format. A case applies one to three of them.
- **Verdict** (:func:`verdict`): a read may give a scene, a :class:`FormatError`, or, where apt,
  :class:`FileAccessError`, :class:`UnknownFormatError` or :class:`MissingDependencyError`;
  anything else fails, and so does a FormatError that is the catch-all rewrap of
  ``geobrep.read`` (its message starts with ``"<format> reader failed:"``).
"""

from __future__ import annotations

import random
import re
import shutil
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import geobrep
from geobrep.errors import (
    FileAccessError,
    FormatError,
    MissingDependencyError,
    UnknownFormatError,
)

DATA = Path(__file__).resolve().parents[1] / "data"
SEED_BYTES = 64 * 1024
_SKIPPED_NAMES = frozenset({"SOURCES.md", "README.txt", "README.md"})


@dataclass(frozen=True)
class Seed:
    """A file to mutate: its bytes, the name the mutated copy gets, its sidecar files (a
    shapefile's ``.shx``/``.dbf``...) and the format that reads it."""

    format: str
    name: str
    data: bytes
    sidecars: tuple[tuple[str, bytes], ...] = ()
    origin: str = ""


# -- seeds --------------------------------------------------------------------------------------


def _seed_scenes() -> list[geobrep.Scene]:
    """Small scenes that every writer can hold at least one of."""
    rng = np.random.default_rng(7)
    points = geobrep.PointSet(
        vertices=rng.normal(size=(6, 3)) * 100 + [450000, 6700000, -50],
        point_data={
            "age": rng.normal(size=6),
            "code": geobrep.Property(values=np.arange(6, dtype=np.int32), no_data_value=-1),
        },
        name="wells",
    )
    grid = np.array([[x, y, 0.1 * x * y] for y in range(3) for x in range(3)], dtype=float)
    faces = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6]])
    surface = geobrep.Surface(
        vertices=grid,
        faces=faces,
        name="top",
        point_data={"depth": grid[:, 2]},
        cell_data={"facies": np.arange(6, dtype=np.int64)},
        patch_labels=np.array([0, 0, 1, 1, 0, 1]),
        patch_names=("a", "b"),
    )
    line = geobrep.PolyLine(
        vertices=grid[:4],
        indices=np.arange(4),
        part_offsets=np.array([0, 4]),
        closed=np.array([False]),
        name="trace",
    )
    return [
        geobrep.Scene(entities=[points, surface, line], name="mixed"),
        geobrep.Scene(entities=[surface]),
        geobrep.Scene(entities=[points]),
        geobrep.Scene(entities=[line]),
    ]


def reading_formats() -> list[str]:
    """Names of every registered format that can read."""
    from geobrep.host import registries

    return sorted(spec.name for spec in registries().formats if spec.can_read)


#: Write options giving other encodings of a format (compressed, ASCII, binary).
WRITE_VARIANTS: dict[str, list[dict[str, object]]] = {
    "native": [{"compress": True}],
    "vtu": [{"compression": "zlib"}, {"compression": "lzma"}],
    "vtk": [{"binary": False}],
    "ply": [{"binary": False}],
    "stl": [{"binary": True}],
    "csv": [{"delimiter": " "}],
    "3dtiles": [{"longitude": 5.7, "latitude": 45.2, "height": 200.0}],  # a local CRS needs one
}


def _written_seeds(folder: Path) -> list[Seed]:
    from geobrep.host import registries

    seeds: list[Seed] = []
    for spec in registries().formats:
        if not (spec.can_read and spec.can_write and spec.extensions):
            continue
        for variant, options in enumerate([{}, *WRITE_VARIANTS.get(spec.name, [])]):
            for index, scene in enumerate(_seed_scenes()):
                target = folder / spec.name / f"seed{index}_{variant}{spec.extensions[0]}"
                target.parent.mkdir(parents=True, exist_ok=True)
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        geobrep.write(scene, target, format=spec.name, **options)
                except Exception:  # this writer holds none of this scene: try the next one
                    continue
                origin = f"written by geobrep ({spec.name} {options or ''})".replace(" )", ")")
                seeds.append(_seed_of(target, spec.name, origin))
    return seeds


def _seed_of(path: Path, format_name: str, origin: str) -> Seed:
    sidecars = tuple(
        (other.name, other.read_bytes()[:SEED_BYTES])
        for other in sorted(path.parent.glob(f"{path.stem}.*"))
        if other != path and other.is_file()
    )
    return Seed(format_name, path.name, path.read_bytes()[:SEED_BYTES], sidecars, origin)


def data_seeds(root: Path = DATA) -> list[Seed]:
    """A seed for every file under ``root`` that a registered reader claims."""
    from geobrep.host import registries

    formats = registries().formats
    seeds = []
    for path in sorted(root.rglob("*")):
        if not path.is_file() or path.name in _SKIPPED_NAMES or "__pycache__" in path.parts:
            continue
        try:
            spec = formats.choose_reader(path)
        except Exception:  # no reader claims it (plugin code, pipeline files, ...)
            continue
        seeds.append(_seed_of(path, spec.name, str(path.relative_to(root))))
    return seeds


def all_seeds(folder: Path) -> dict[str, list[Seed]]:
    """Seeds by format name: files of ``tests/data`` and files written into ``folder``."""
    by_format: dict[str, list[Seed]] = {}
    for seed in data_seeds() + _written_seeds(folder):
        by_format.setdefault(seed.format, []).append(seed)
    return by_format


# -- mutations ----------------------------------------------------------------------------------

_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_HUGE = (
    b"4294967296",
    b"18446744073709551616",
    b"99999999999999999999999999",
    b"400000000",
    b"-1",
    b"-2147483649",
    b"1e308",
    b"1e999",
    b"nan",
    b"inf",
    b"-inf",
    b"0",
)

Mutation = Callable[[random.Random, bytes, bytes], bytes]


def _span(rng: random.Random, size: int) -> tuple[int, int]:
    start = rng.randrange(size + 1)
    return start, min(size, start + rng.choice((1, 2, 8, 64, 512, 4096)))


def flip_bytes(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Set one to eight bytes to random values."""
    if not data:
        return bytes([rng.randrange(256)])
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        out[rng.randrange(len(out))] = rng.randrange(256)
    return bytes(out)


def truncate(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Cut the file short."""
    return data[: rng.randrange(len(data) + 1)]


def duplicate_chunk(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Copy a chunk elsewhere."""
    start, stop = _span(rng, len(data))
    where = rng.randrange(len(data) + 1)
    return data[:where] + data[start:stop] * rng.choice((1, 2, 16)) + data[where:]


def drop_chunk(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Remove a chunk."""
    start, stop = _span(rng, len(data))
    return data[:start] + data[stop:]


def _lines_edit(rng: random.Random, data: bytes, duplicate: bool) -> bytes:
    lines = data.split(b"\n")
    index = rng.randrange(len(lines))
    if duplicate:
        lines.insert(rng.randrange(len(lines) + 1), lines[index])
    else:
        del lines[index]
    return b"\n".join(lines)


def duplicate_line(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Repeat one line somewhere."""
    return _lines_edit(rng, data, duplicate=True)


def drop_line(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Remove one line."""
    return _lines_edit(rng, data, duplicate=False)


def huge_number(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Put a huge, negative, NaN or infinite number in place of a number (a count in a header,
    most often: the numbers near the start are picked more often)."""
    numbers = [m.span() for m in _NUMBER.finditer(data[:SEED_BYTES], 0)]
    if not numbers:
        return data + b" " + rng.choice(_HUGE)
    pick = min(int(rng.expovariate(1 / 8)), len(numbers) - 1) if rng.random() < 0.7 else None
    start, stop = numbers[pick if pick is not None else rng.randrange(len(numbers))]
    return data[:start] + rng.choice(_HUGE) + data[stop:]


def insert_junk(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """Insert random bytes."""
    where = rng.randrange(len(data) + 1)
    junk = bytes(rng.randrange(256) for _ in range(rng.choice((1, 4, 32))))
    return data[:where] + junk + data[where:]


def splice(rng: random.Random, data: bytes, other: bytes) -> bytes:
    """The start of this file and the end of another of the same format."""
    return data[: rng.randrange(len(data) + 1)] + other[rng.randrange(len(other) + 1) :]


MUTATIONS: dict[str, Mutation] = {
    "flip_bytes": flip_bytes,
    "truncate": truncate,
    "duplicate_chunk": duplicate_chunk,
    "drop_chunk": drop_chunk,
    "duplicate_line": duplicate_line,
    "drop_line": drop_line,
    "huge_number": huge_number,
    "insert_junk": insert_junk,
    "splice": splice,
}


def mutate(seed: Seed, other: Seed, steps: list[tuple[str, int]]) -> bytes:
    """``seed``'s bytes after each ``(mutation name, random seed)`` step in turn."""
    data = seed.data
    for name, number in steps:
        data = MUTATIONS[name](random.Random(number), data, other.data)
    return data


def random_steps(rng: random.Random) -> list[tuple[str, int]]:
    """One to three mutation steps."""
    names = sorted(MUTATIONS)
    return [(rng.choice(names), rng.randrange(2**32)) for _ in range(rng.choice((1, 1, 2, 3)))]


def write_case(folder: Path, seed: Seed, data: bytes) -> Path:
    """Write a mutated file (with the seed's sidecars) into an empty ``folder``."""
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    for name, content in seed.sidecars:
        (folder / name).write_bytes(content)
    path = folder / seed.name
    path.write_bytes(data)
    return path


# -- verdict ------------------------------------------------------------------------------------

ACCEPTED_ERRORS = (FormatError, FileAccessError, MissingDependencyError)


@dataclass(frozen=True)
class Verdict:
    """What one read gave: ``kind`` is ``result``, ``FormatError`` (or another accepted error's
    class name) or ``failure``; ``message`` says what."""

    kind: str
    message: str

    @property
    def failed(self) -> bool:
        return self.kind == "failure"


def catch_all_rewrap(error: FormatError) -> bool:
    """True for ``geobrep.read``'s catch-all rewrap (``"ply reader failed: KeyError: ..."``)."""
    return re.match(r"[\w.-]+ reader failed:", error.message) is not None


def verdict(path: Path) -> Verdict:
    """Read ``path`` (format chosen as ``geobrep.read`` chooses it) and judge the outcome."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = geobrep.read(path)
    except UnknownFormatError as exc:
        return Verdict("UnknownFormatError", str(exc))
    except FormatError as exc:
        if catch_all_rewrap(exc):
            return Verdict("failure", f"catch-all rewrap: {exc}")
        return Verdict("FormatError", str(exc))
    except ACCEPTED_ERRORS as exc:
        return Verdict(type(exc).__name__, str(exc))
    except Exception as exc:  # the defect this harness hunts
        return Verdict("failure", f"{type(exc).__name__}: {exc}")
    if not isinstance(scene, geobrep.Scene):
        return Verdict("failure", f"read returned {type(scene).__name__}")
    return Verdict("result", f"{len(scene.entities)} entities")
