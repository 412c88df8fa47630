"""Output names and where they may go: the one place batch writers form output paths.

Every file :func:`geobrep.convert` writes into a folder and every file a pipeline's write step
writes is named here. A name pattern may only substitute the bare fields of
:data:`NAME_FIELDS` (no attribute access, indexing, conversion or format spec: ``str.format``
would let ``{index.__class__...}`` spell a ``/`` and ``{index:>900000000}`` allocate gigabytes),
and every output path is resolved (symlinks included) and must lie inside its output folder.
The check is made when the path is formed (:meth:`OutputFolder.target`) and again right before
the file is written (:func:`contained`).

>>> import pathlib, tempfile
>>> folder = OutputFolder(pathlib.Path(tempfile.mkdtemp()))
>>> name = format_name("{stem}_{index}.vtu", name_fields(pathlib.Path("a/cake.ts"), 3))
>>> folder.target(name).name
'cake_3.vtu'
>>> check_name_pattern("{index.__class__}.vtu")
Traceback (most recent call last):
...
geobrep.errors.OptionsError: name pattern '{index.__class__}.vtu': {index.__class__} is not a plain field (no attribute access, indexing, conversion or format spec); fields: {stem}, {name}, {ext}, {index}, {half}
"""  # noqa: E501

from __future__ import annotations

import os
import string
from collections.abc import Mapping
from pathlib import Path

from geobrep.errors import FileAccessError, OptionsError

__all__ = [
    "NAME_FIELDS",
    "OutputFolder",
    "check_file_name",
    "check_name_pattern",
    "contained",
    "format_name",
    "half_name",
    "name_fields",
    "uses_half",
]

#: Fields a name pattern may use: the input's name up to its first dot, its file name, the
#: rest of its file name after the stem (its extensions, with the dot), its position, and the
#: half of a ``clip`` step with ``keep: both`` the scene written is (``negative`` or
#: ``positive``; ``negative-positive`` after two such steps; empty when no step split it).
NAME_FIELDS = ("stem", "name", "ext", "index", "half")

_PATTERN_SEPARATORS = ("/", "\\")  # refused in a pattern on every system
_NAME_SEPARATORS = tuple(s for s in (os.sep, os.altsep, "\0") if s)


def _fields_text() -> str:
    return ", ".join("{" + field + "}" for field in NAME_FIELDS)


def check_name_pattern(pattern: str) -> None:
    """Raise :class:`OptionsError` unless ``pattern`` substitutes only bare known fields.

    Literal text may not hold a path separator; ``{{`` and ``}}`` stand for braces.
    """
    try:
        pieces = list(string.Formatter().parse(pattern))
    except ValueError as exc:
        raise OptionsError(f"name pattern {pattern!r}: {exc}") from exc
    for literal, field, spec, conversion in pieces:
        if any(separator in literal for separator in _PATTERN_SEPARATORS):
            raise OptionsError(f"name pattern {pattern!r}: a file name, not a path")
        if field is None:
            continue
        if field not in NAME_FIELDS or spec or conversion is not None:
            shown = "{" + field + (f"!{conversion}" if conversion else "")
            shown += (f":{spec}" if spec else "") + "}"
            if field.split(".")[0].split("[")[0] not in NAME_FIELDS:
                raise OptionsError(
                    f"name pattern {pattern!r}: unknown field {shown}; fields: {_fields_text()}"
                )
            raise OptionsError(
                f"name pattern {pattern!r}: {shown} is not a plain field (no attribute access, "
                f"indexing, conversion or format spec); fields: {_fields_text()}"
            )


def format_name(pattern: str, fields: Mapping[str, str | int]) -> str:
    """``pattern`` with its fields replaced by ``fields`` (checked by :func:`check_name_pattern`).

    The substitution is plain text replacement, never ``str.format``.
    """
    check_name_pattern(pattern)
    parts: list[str] = []
    for literal, field, _, _ in string.Formatter().parse(pattern):
        parts.append(literal)
        if field is not None:
            parts.append(str(fields[field]))
    return "".join(parts)


def name_fields(source: Path, index: int, half: str = "") -> dict[str, str | int]:
    """The values of :data:`NAME_FIELDS` for the input ``source`` at position ``index``."""
    stem = source.name.split(".")[0]
    return {
        "stem": stem,
        "name": source.name,
        "ext": source.name[len(stem) :],
        "index": index,
        "half": half,
    }


def uses_half(pattern: str) -> bool:
    """True when the name pattern substitutes ``{half}``."""
    return any(field == "half" for _, field, _, _ in string.Formatter().parse(pattern))


def half_name(pattern: str, fields: Mapping[str, str | int]) -> str:
    """The name ``pattern`` gives, told apart by its half as ``geobrep clip --keep both`` does.

    A pattern that does not say ``{half}`` gets ``-HALF`` before its last extension:

    >>> fields = name_fields(Path("cake.ts"), 0, "negative")
    >>> half_name("{stem}.vtu", fields), half_name("{half}_{stem}.vtu", fields)
    ('cake-negative.vtu', 'negative_cake.vtu')
    """
    name = format_name(pattern, fields)
    half = str(fields.get("half", ""))
    if not half or uses_half(pattern):
        return name
    suffix = Path(name).suffix
    stem = name[: len(name) - len(suffix)] if suffix else name
    return f"{stem}-{half}{suffix}"


def check_file_name(name: str) -> None:
    """Raise :class:`OptionsError` unless ``name`` is one plain file name (no folder part)."""
    if name in ("", ".", "..") or any(separator in name for separator in _NAME_SEPARATORS):
        raise OptionsError(f"output name {name!r} is not a plain file name")


def contained(target: Path, folder: Path) -> Path:
    """``target``, once checked to resolve (symlinks included) to a file inside ``folder``.

    Raises:
        FileAccessError: ``target`` resolves outside ``folder`` (or to the folder itself).
    """
    inside = folder.resolve()
    if target.parent == folder and target.name not in ("", ".", "..") and not target.is_symlink():
        resolved = inside / target.name  # what resolve() gives, without a look at each part
    else:
        resolved = target.resolve()
    if resolved == inside or not resolved.is_relative_to(inside):
        raise FileAccessError(
            f"resolves to {resolved}, outside the output folder {folder}; not written", target
        )
    return target


class OutputFolder:
    """An output folder that hands out only paths inside itself."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def target(self, name: str) -> Path:
        """``path / name``: ``name`` must be a plain file name and resolve inside the folder.

        Raises:
            OptionsError: ``name`` has a folder part, or is empty, ``.`` or ``..``.
            FileAccessError: the path resolves outside the folder (e.g. through a symlink).
        """
        check_file_name(name)
        return contained(self.path / name, self.path)
