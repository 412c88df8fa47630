"""The native ``.geobrep`` container: a zip holding ``scene.json`` and one ``.npy`` per array.

``scene.json`` is a :class:`NativeDocument` (its JSON Schema is ``schemas/scene.schema.json``);
arrays appear in it as ``{"dtype", "shape", "file"}`` records naming ``arrays/NNNNNN.npy`` members.
The JSON is the first member, so a reader can recognise the file from its first bytes. Arrays are
stored uncompressed by default (bit-identical and fast); ``compress=True`` deflates them.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

import geobrep
from geobrep.errors import FormatError, GeobrepError
from geobrep.model.arrays import ARRAY_WRITER, array_reader
from geobrep.model.scene import Scene
from geobrep.ops.io import atomic_write

__all__ = ["FORMAT_ID", "FORMAT_VERSION", "NativeDocument", "load", "looks_native", "save"]

FORMAT_ID: Final = "geobrep-scene"
FORMAT_VERSION: Final = 1
SCENE_MEMBER = "scene.json"
_ZIP_MAGIC = b"PK\x03\x04"


class NativeDocument(BaseModel):
    """The content of ``scene.json``."""

    model_config = ConfigDict(frozen=True, extra="forbid", title="geobrep scene document")

    format: Literal["geobrep-scene"] = FORMAT_ID
    version: Literal[1] = FORMAT_VERSION
    writer: str = Field(default_factory=lambda: f"geobrep {geobrep.__version__}")
    scene: Scene


def looks_native(head: bytes) -> bool:
    """True when the first bytes are a zip whose first member is ``scene.json``."""
    name_length = int.from_bytes(head[26:28], "little") if len(head) >= 30 else 0
    return head.startswith(_ZIP_MAGIC) and head[30 : 30 + name_length] == SCENE_MEMBER.encode()


def save(scene: Scene, path: str | Path, compress: bool = False) -> Path:
    """Write ``scene`` to ``path`` atomically (a temporary file renamed on success)."""
    target = Path(path)
    with atomic_write(target) as temporary:
        _write_container(scene, temporary, compress)
    return target


def _write_container(scene: Scene, path: Path, compress: bool) -> None:
    arrays: list[tuple[str, NDArray[Any]]] = []
    stored: dict[int, str] = {}

    def store(array: NDArray[Any]) -> str:
        # pydantic may serialise a union member more than once while it picks the matching
        # type; store each array object once (the scene keeps them alive during the save).
        name = stored.get(id(array))
        if name is None:
            name = stored[id(array)] = f"arrays/{len(arrays):06d}.npy"
            arrays.append((name, array))
        return name

    document = NativeDocument(scene=scene).model_dump(mode="json", context={ARRAY_WRITER: store})
    method = zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED
    with zipfile.ZipFile(path, "w", compression=method, allowZip64=True) as archive:
        archive.writestr(SCENE_MEMBER, json.dumps(document, indent=1, allow_nan=False))
        for name, array in arrays:
            with archive.open(name, "w", force_zip64=array.nbytes > 2**30) as member:
                np.lib.format.write_array(member, np.ascontiguousarray(array), allow_pickle=False)


def load(path: str | Path) -> Scene:
    """Read a ``.geobrep`` file; every problem is a :class:`FormatError` naming the file."""
    source = Path(path)
    try:
        with zipfile.ZipFile(source) as archive:
            return _read_container(archive, source)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError) as exc:
        raise FormatError(f"not a readable .geobrep container ({exc})", source) from exc


def _read_container(archive: zipfile.ZipFile, source: Path) -> Scene:
    try:
        text = archive.read(SCENE_MEMBER).decode("utf-8")
    except KeyError:
        raise FormatError(f"the container has no {SCENE_MEMBER}", source) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FormatError(
            f"{SCENE_MEMBER}: invalid JSON: {exc.msg}", source, line=exc.lineno
        ) from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT_ID:
        raise FormatError(f"{SCENE_MEMBER} is not a {FORMAT_ID} document", source)
    if data.get("version") != FORMAT_VERSION:
        raise FormatError(
            f"container version {data.get('version')!r} is not supported "
            f"(this geobrep reads version {FORMAT_VERSION})",
            source,
        )
    members = set(archive.namelist())

    def fetch(name: str) -> NDArray[Any]:
        if name not in members:
            raise ValueError(f"array member {name!r} is missing from the container")
        with archive.open(name) as member:
            try:
                return np.lib.format.read_array(member, allow_pickle=False)
            except (ValueError, OSError, EOFError) as exc:
                raise ValueError(f"array member {name!r} is corrupt: {exc}") from None

    try:
        with array_reader(fetch):
            document = NativeDocument.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        original = (first.get("ctx") or {}).get("error")
        where = ".".join(str(p) for p in first["loc"])
        reason = str(original) if isinstance(original, GeobrepError) else first["msg"]
        raise FormatError(f"{SCENE_MEMBER}: {where}: {reason}", source) from exc
    except GeobrepError as exc:
        raise FormatError(f"{SCENE_MEMBER}: {exc}", source) from exc
    return document.scene
