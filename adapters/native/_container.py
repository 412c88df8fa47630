"""The native ``.geobrep`` container: a zip holding ``scene.json`` and one ``.npy`` per array.

``scene.json`` is a :class:`NativeDocument` (its JSON Schema is ``schemas/scene.schema.json``);
arrays appear in it as ``{"dtype", "shape", "file"}`` records naming ``arrays/NNNNNN.npy`` members.
The JSON is the first member, so a reader can recognise the file from its first bytes. Arrays are
stored uncompressed by default (bit-identical and fast); ``compress=True`` deflates them.
"""

from __future__ import annotations

import json
import math
import zipfile
import zlib
from pathlib import Path
from tokenize import TokenError
from typing import IO, Any, Final, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

import geobrep
from geobrep.adapters import _strict_json as strict_json
from geobrep.adapters.limits import check_declared
from geobrep.errors import FormatError, GeobrepError
from geobrep.model.arrays import ARRAY_WRITER, array_reader
from geobrep.model.scene import Scene
from geobrep.ops.io import atomic_write

__all__ = ["FORMAT_ID", "FORMAT_VERSION", "NativeDocument", "load", "looks_native", "save"]

FORMAT_ID: Final = "geobrep-scene"
FORMAT_VERSION: Final = 1
SCENE_MEMBER = "scene.json"
_ZIP_MAGIC = b"PK\x03\x04"
SCENE_JSON_LIMIT: Final = 64 * 2**20
"""The largest ``scene.json`` read from a container smaller than this (64 MiB)."""
_NPY_HEADER: Final = 10_000


class NativeDocument(BaseModel):
    """The content of ``scene.json``."""

    model_config = ConfigDict(
        frozen=True, extra="forbid", title="geobrep scene document", defer_build=True
    )

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
        archive.writestr(SCENE_MEMBER, _document_text(document, path))
        for name, array in arrays:
            with archive.open(name, "w", force_zip64=array.nbytes > 2**30) as member:
                np.lib.format.write_array(member, np.ascontiguousarray(array), allow_pickle=False)


def _non_finite_at(data: Any) -> str | None:
    """The JSON path of the first NaN or infinity in ``data`` (None when there is none)."""

    def non_finite(value: Any, _: tuple[str, ...]) -> bool:
        return isinstance(value, float) and not math.isfinite(value)

    found = strict_json.find_leaf(data, non_finite)
    return None if found is None else ".".join(found) or "(the document)"


def _document_text(document: dict[str, Any], path: Path) -> str:
    """``scene.json``'s text; a NaN or infinity (metadata from Python code) is refused by name."""
    try:
        return json.dumps(document, indent=1, allow_nan=False)
    except ValueError:
        where = _non_finite_at(document)
        raise FormatError(
            f"{where} is NaN or infinite, not JSON compliant: metadata cannot hold it "
            "(store it as a string, or as a property's no_data_value)",
            path,
        ) from None


def load(path: str | Path) -> Scene:
    """Read a ``.geobrep`` file; every problem is a :class:`FormatError` naming the file.

    Declared sizes are checked before anything is inflated or allocated: every member's size
    against the archive and the read budget (:mod:`geobrep.adapters.limits`), every ``.npy``
    header's shape against its member's size; members are inflated in bounded steps.
    """
    source = Path(path)
    try:
        with zipfile.ZipFile(source) as archive:
            _check_members(archive, source)
            return _read_container(archive, source)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError) as exc:
        raise FormatError(f"not a readable .geobrep container ({exc})", source) from exc
    except OSError as exc:  # zipfile seeks to offsets a corrupt directory gives
        reason = exc.strerror or exc
        raise FormatError(f"not a readable .geobrep container ({reason})", source) from exc
    except RecursionError:
        raise FormatError(f"{SCENE_MEMBER} nests too deeply to be a scene", source) from None


def _check_members(archive: zipfile.ZipFile, source: Path) -> None:
    """Refuse members whose declared sizes the archive cannot hold or the budget forbids."""
    size = source.stat().st_size
    total = 0
    for info in archive.infolist():
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise FormatError(
                f"member {info.filename!r} uses zip compression method {info.compress_type}; "
                ".geobrep members are stored or deflated",
                source,
            )
        if info.header_offset + info.compress_size > size:
            raise FormatError(
                f"member {info.filename!r} declares {info.compress_size} bytes of data past "
                f"the end of the {size}-byte file",
                source,
            )
        if info.compress_type == zipfile.ZIP_STORED and info.file_size != info.compress_size:
            raise FormatError(
                f"stored member {info.filename!r} declares {info.file_size} bytes but holds "
                f"{info.compress_size}",
                source,
            )
        total += info.file_size
    check_declared(total, size, "the container's members", source)


def _member_bytes(archive: zipfile.ZipFile, name: str, limit: int, source: Path) -> bytes:
    """The inflated bytes of member ``name``, read in bounded steps and at most ``limit``."""
    chunks: list[bytes] = []
    total = 0
    try:
        with archive.open(name) as member:
            while chunk := member.read(1 << 20):
                total += len(chunk)
                if total > limit:
                    raise FormatError(
                        f"member {name!r} inflates to more than {limit} bytes", source
                    )
                chunks.append(chunk)
    except (zlib.error, zipfile.BadZipFile, EOFError) as exc:
        raise FormatError(f"member {name!r} is corrupt ({exc})", source) from None
    return b"".join(chunks)


def _scene_json(archive: zipfile.ZipFile, source: Path) -> dict[str, Any]:
    """The parsed ``scene.json``: UTF-8 JSON of at most :data:`SCENE_JSON_LIMIT` (or the
    archive's size, if larger)."""
    try:
        info = archive.getinfo(SCENE_MEMBER)
    except KeyError:
        raise FormatError(f"the container has no {SCENE_MEMBER}", source) from None
    limit = max(SCENE_JSON_LIMIT, source.stat().st_size)
    if info.file_size > limit:
        raise FormatError(
            f"{SCENE_MEMBER} declares {info.file_size} bytes; a scene document is at most "
            f"{limit} bytes (arrays live in .npy members)",
            source,
        )
    raw = _member_bytes(archive, SCENE_MEMBER, limit, source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise FormatError(
            f"{SCENE_MEMBER} is not UTF-8 text (byte 0x{raw[exc.start]:02x})", source, line
        ) from None
    try:
        data = strict_json.loads(text)
    except json.JSONDecodeError as exc:
        raise FormatError(
            f"{SCENE_MEMBER}: invalid JSON: {exc.msg}", source, line=exc.lineno
        ) from exc
    except ValueError as exc:
        raise FormatError(f"{SCENE_MEMBER}: {exc}", source) from None
    if not isinstance(data, dict) or data.get("format") != FORMAT_ID:
        raise FormatError(f"{SCENE_MEMBER} is not a {FORMAT_ID} document", source)
    return data


def _npy_layout(member: IO[bytes], name: str) -> tuple[np.dtype[Any], tuple[int, ...], int]:
    """dtype, shape and header length of a ``.npy`` member, from its header alone."""
    try:
        version = np.lib.format.read_magic(member)
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(
                member, max_header_size=_NPY_HEADER
            )
        elif version in ((2, 0), (3, 0)):
            shape, _, dtype = np.lib.format.read_array_header_2_0(
                member, max_header_size=_NPY_HEADER
            )
        else:
            raise ValueError(f"npy format version {version} is not supported")
    except (ValueError, SyntaxError, TypeError, OverflowError, EOFError, TokenError) as exc:
        raise ValueError(f"array member {name!r} is corrupt: its .npy header: {exc}") from None
    if dtype.hasobject or dtype.kind not in "biuf" or dtype.subdtype is not None:
        raise ValueError(f"array member {name!r} holds {dtype} values, not numbers")
    return dtype, shape, member.tell()


def _read_container(archive: zipfile.ZipFile, source: Path) -> Scene:
    data = _scene_json(archive, source)
    if data.get("version") != FORMAT_VERSION:
        raise FormatError(
            f"container version {data.get('version')!r} is not supported "
            f"(this geobrep reads version {FORMAT_VERSION})",
            source,
        )
    members = {info.filename: info for info in archive.infolist()}

    def fetch(name: object) -> NDArray[Any]:
        if not isinstance(name, str):
            raise ValueError(f"an array record's 'file' must be a member name, not {name!r}")
        info = members.get(name)
        if info is None:
            raise ValueError(f"array member {name!r} is missing from the container")
        try:
            with archive.open(info) as member:
                dtype, shape, offset = _npy_layout(member, name)
            if math.prod(shape) * dtype.itemsize != info.file_size - offset:
                raise ValueError(
                    f"array member {name!r}: its header declares {dtype} values of shape "
                    f"{shape}, {math.prod(shape) * dtype.itemsize} bytes, but it holds "
                    f"{info.file_size - offset}"
                )
            with archive.open(info) as member:
                return np.lib.format.read_array(member, allow_pickle=False)
        except (OSError, EOFError, zlib.error, zipfile.BadZipFile) as exc:
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
