"""What the file-format adapters share: a :class:`FormatSpec` from a plain reader and writer, and
the capabilities of a format that keeps everything of its entity types.

A format is a reader, a writer and a registration line. The reader of a file format without read
options is ``read(path) -> Scene``; its writer ``write(scene, path, options)`` only ever meets
what the format holds (the scene restricted to the format's capabilities), so no adapter repeats
either wrapper.

>>> from pathlib import Path
>>> from geobrep.host.registry import NoOptions
>>> from geobrep.model.scene import Scene
>>> spec = file_format(
...     "empty", "a format that reads nothing", (".empty",),
...     capabilities=full_capabilities({"PointSet"}), options=NoOptions,
...     read=lambda path: Scene(name=path.stem),
... )
>>> spec.reader(Path("a.empty"), NoOptions()).name, spec.can_write
('a', False)
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel

from geobrep.host.capabilities import restrict_scene
from geobrep.host.registry import FormatCapabilities, FormatSpec
from geobrep.model.scene import Scene

__all__ = ["file_format", "full_capabilities"]

OptionsT = TypeVar("OptionsT", bound=BaseModel)


def full_capabilities(entity_types: Iterable[str]) -> FormatCapabilities:
    """A format holding many entities of ``entity_types`` in one file with their point and cell
    properties, names (and groups), ids and CRS; no topology."""
    return FormatCapabilities(
        entity_types=frozenset(entity_types),
        point_data=True,
        cell_data=True,
        names=True,
        ids=True,
        crs=True,
        multiple_entities=True,
    )


def file_format(
    name: str,
    description: str,
    extensions: tuple[str, ...],
    *,
    capabilities: FormatCapabilities,
    options: type[OptionsT],
    read: Callable[[Path], Scene] | None = None,
    write: Callable[[Scene, Path, OptionsT], None] | None = None,
    sniff: Callable[[bytes], bool] | None = None,
    **spec: Any,
) -> FormatSpec:
    """The :class:`FormatSpec` of a file format read by ``read(path)`` (no read options) and
    written by ``write(scene, path, options)`` with ``scene`` restricted to ``capabilities``
    (:func:`~geobrep.host.capabilities.restrict_scene`). ``spec`` passes further FormatSpec
    fields (``losses``, ``generic_content``)."""
    return FormatSpec(
        name=name,
        description=description,
        extensions=extensions,
        reader=None if read is None else _reader(read),
        writer=None if write is None else _restricted_writer(write, capabilities),
        sniff=sniff,
        options=options,
        capabilities=capabilities,
        **spec,
    )


def _reader(read: Callable[[Path], Scene]) -> Callable[[Path, BaseModel], Scene]:
    """``read`` as a format reader: it takes no options."""

    def reader(path: Path, options: BaseModel) -> Scene:
        return read(path)

    return reader


def _restricted_writer(
    write: Callable[[Scene, Path, OptionsT], None], capabilities: FormatCapabilities
) -> Callable[[Scene, Path, OptionsT], None]:
    """``write`` as a format writer: it gets only what ``capabilities`` hold."""

    def writer(scene: Scene, path: Path, options: OptionsT) -> None:
        write(restrict_scene(scene, capabilities), path, options)

    return writer
