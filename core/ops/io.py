"""Reading and writing files through the format registry, and atomic output.

>>> import geobrep, tempfile, pathlib
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> out = pathlib.Path(tempfile.mkdtemp()) / "model.geobrep"
>>> _ = geobrep.write(scene, out)
>>> geobrep.read(out) == scene
True
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from os import PathLike
from pathlib import Path
from typing import Any

from geobrep.errors import FileAccessError, FormatError, GeobrepError, UnknownFormatError
from geobrep.model.entities import Entity
from geobrep.model.scene import Scene
from geobrep.ops.temporaries import remove_stale_temporaries, replace_file, temporary_path

__all__ = ["as_scene", "atomic_write", "read", "write"]

PathArg = str | PathLike[str]


@contextmanager
def atomic_write(path: PathArg) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` only on success.

    The temporary is ``.{stem}.tmp-{pid}-{random}{suffix}``: it keeps the final suffix, so
    writers that look at it still work, and names the writing process, so that temporaries
    left by a killed process are found later: each call first removes the stale temporaries of
    ``path`` (:mod:`geobrep.ops.temporaries`; also ``geobrep clean FOLDER``). On an exception
    the temporary file is removed and ``path`` is left as it was.

    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_write(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text()
    'done'
    """
    final = Path(path)
    if not final.parent.is_dir():
        raise FileAccessError("the output folder does not exist", final.parent)
    remove_stale_temporaries(final)
    temporary = temporary_path(final)
    try:
        yield temporary
        if not temporary.exists():
            raise FormatError("the writer produced no file", final)
        replace_file(temporary, final)
    finally:
        if temporary.exists():
            temporary.unlink()


def as_scene(data: Scene | Entity | Iterable[Entity]) -> Scene:
    """A scene from a scene, one entity, or several entities."""
    if isinstance(data, Scene):
        return data
    if isinstance(data, Entity):
        return Scene(entities=[data])
    return Scene(entities=list(data))


def _check_readable(path: Path) -> None:
    if not path.exists():
        raise FileAccessError("no such file", path)
    if path.is_dir():
        raise FileAccessError("is a directory, not a file", path)
    try:
        with path.open("rb") as handle:
            handle.read(1)
    except OSError as exc:
        raise FileAccessError(f"cannot be read ({exc.strerror or exc})", path) from exc


def read(path: PathArg, format: str | None = None, *, repair: bool = True, **options: Any) -> Scene:
    """Read a file into a :class:`Scene`, choosing the format by extension and content.

    ``format`` names a registered format explicitly; other keywords are that format's options
    (validated by its options model). ``repair`` (default ``True``) lets a reader mend what a
    file gets wrong, with a warning for each repair (GOCAD: triangles flipped against their
    TFACE's key triangle, REGION sides contradicting the geometry); ``repair=False`` keeps the
    model exactly as the file holds it, defects included, for inspection. Errors:
    :class:`FileAccessError` for a missing or unreadable file, :class:`UnknownFormatError` when
    no format matches, :class:`FormatError` (with path and line) when the content is wrong.
    """
    from geobrep.host import registries

    source = Path(path)
    _check_readable(source)
    spec = registries().formats.choose_reader(source, format)
    if not spec.can_read or spec.reader is None:
        raise UnknownFormatError(f"format {spec.name!r} cannot read files", source)
    if "repair" in spec.options.model_fields:
        options = {"repair": repair, **options}
    validated = spec.validate_options(options)
    try:
        result = spec.reader(source, validated)
    except GeobrepError:
        raise
    except (Exception, SystemExit) as exc:  # a library failing deep inside: say where
        raise FormatError(
            f"{spec.name} reader failed: {type(exc).__name__}: {exc}", source
        ) from exc
    if isinstance(result, Scene):
        return result
    if isinstance(result, Entity):
        return Scene(entities=[result])
    raise FormatError(f"{spec.name} reader returned {type(result).__name__}, not a Scene", source)


def write(
    data: Scene | Entity | Iterable[Entity],
    path: PathArg,
    format: str | None = None,
    **options: Any,
) -> Path:
    """Write a scene (or entities) to ``path`` atomically; returns the path written.

    The format comes from ``format`` or the extension. The file appears only when the writer
    succeeded: a failure leaves no partial output behind.
    """
    from geobrep.host import registries

    target = Path(path)
    scene = as_scene(data)
    spec = registries().formats.choose_writer(target, format)
    if not spec.can_write or spec.writer is None:
        raise UnknownFormatError(f"format {spec.name!r} cannot write files", target)
    validated = spec.validate_options(options)
    try:
        with atomic_write(target) as temporary:
            try:
                spec.writer(scene, temporary, validated)
            except GeobrepError:
                raise
            except (Exception, SystemExit) as exc:
                raise FormatError(
                    f"{spec.name} writer failed: {type(exc).__name__}: {exc}", target
                ) from exc
    except GeobrepError as exc:
        _point_to_target(exc, target)
        raise
    return target


def _point_to_target(error: GeobrepError, target: Path) -> None:
    """Make an error raised while writing a temporary file name ``target`` instead.

    The writer only sees :func:`atomic_write`'s temporary path (``.out.tmp-4242-1530bb30.vtu``,
    or ``..out.tmp-….tmp-….vtu`` when the writer writes atomically too), so its messages and
    ``path`` attributes name it: the user asked for ``out.vtu``.
    """
    suffix = "".join(target.suffixes[-1:])
    temporary = re.compile(
        r"\.+" + re.escape(target.stem) + r"(?:\.tmp-[0-9]+-[0-9a-f]{8})+" + re.escape(suffix)
    )

    def fixed(value: object) -> object:
        if isinstance(value, str):
            return temporary.sub(lambda _: target.name, value)
        if isinstance(value, Path) and temporary.fullmatch(value.name):
            return value.with_name(target.name)
        return value

    error.args = tuple(fixed(arg) for arg in error.args)
    for name, value in vars(error).items():
        setattr(error, name, fixed(value))
