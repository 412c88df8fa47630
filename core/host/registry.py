"""The items plugins register, and the registries that hold them.

A plugin hook receives a registry and adds items to it::

    registry.add(FormatSpec(name="xyz", extensions=(".xyz",), reader=read_xyz))

Every item is a frozen pydantic model with a ``name`` (lowercase, e.g. ``"xyz"``,
``"surface.plane"``), a ``description``, an ``options`` model validated by
:meth:`RegisteredItem.validate_options`, and the ``plugin`` that registered it (filled by
the loader). Names are unique per registry: a second plugin registering a taken name gets a
:class:`GeobrepPluginWarning` and the first registration wins; one plugin registering a
name twice is a :class:`~geobrep.errors.PluginError`.
"""

from __future__ import annotations

import os
import re
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Generic, Protocol, TypeVar, runtime_checkable

from pydantic import (
    AliasChoices,
    BaseModel,
    ConfigDict,
    ValidationError,
    field_validator,
    model_validator,
)

from geobrep.errors import GeobrepError, OptionsError, PluginError, UnknownFormatError
from geobrep.host._declared import Declared
from geobrep.host._isolation import (
    SNIFF_TIMEOUT_ENV,
    PluginTimeoutError,
    call_bounded,
    sniff_timeout,
    strict_mode,
)

if TYPE_CHECKING:
    from geobrep.geometry import Plane
    from geobrep.host.operations import OperationRegistry
    from geobrep.model.entities import Entity, LinearOctree
    from geobrep.model.scene import Scene

__all__ = [
    "PREFER_ENV",
    "SNIFF_BYTES",
    "BuildFunction",
    "BuilderRegistry",
    "BuilderSpec",
    "CheckFunction",
    "CheckRegistry",
    "CheckSpec",
    "ClipFunction",
    "ClipperRegistry",
    "ClipperSpec",
    "FitFunction",
    "FitterRegistry",
    "FitterSpec",
    "FormatCapabilities",
    "FormatRegistry",
    "FormatSpec",
    "GeobrepPluginWarning",
    "LossReporter",
    "NoOptions",
    "Pending",
    "Reader",
    "RegisteredItem",
    "Registries",
    "Registry",
    "SectionFunction",
    "Sniffer",
    "UnknownItemError",
    "VoxelizeFunction",
    "VoxelizerRegistry",
    "VoxelizerSpec",
    "Writer",
    "break_tie",
    "preferred_formats",
]

SNIFF_BYTES = 4096
"""How many leading bytes of a file a format's ``sniff`` function receives."""

PREFER_ENV = "GEOBREP_PREFER_FORMATS"
"""Comma-separated format names that win ties (same extension, or several sniffers agreeing)."""

_NAME_PATTERN = re.compile(r"[a-z0-9][a-z0-9_.-]*")
_EXTENSION_PATTERN = re.compile(r"(\.[a-z0-9_+~-]+)+")


# -- what the callables of registered items look like (positional: any parameter names) -------
@runtime_checkable
class Reader(Protocol):
    """``reader(path, options) -> Scene`` (or one entity, wrapped in a Scene by the caller)."""

    def __call__(self, path: Path, options: Any, /) -> Scene | Entity: ...


@runtime_checkable
class Writer(Protocol):
    """``writer(scene, path, options)``: writes ``path`` (through ``atomic_write``)."""

    def __call__(self, scene: Scene, path: Path, options: Any, /) -> None: ...


@runtime_checkable
class Sniffer(Protocol):
    """``sniff(head) -> bool``: whether the first :data:`SNIFF_BYTES` bytes are this format."""

    def __call__(self, head: bytes, /) -> bool: ...


@runtime_checkable
class LossReporter(Protocol):
    """``losses(scene, path) -> [sentence, ...]``: what a writer drops for this target."""

    def __call__(self, scene: Scene, path: Path, /) -> list[str]: ...


@runtime_checkable
class ClipFunction(Protocol):
    """``function(entity, plane, keep, options, context)``: the clipped entity, ``None``, or
    ``(negative, positive)`` for ``keep="both"``."""

    def __call__(
        self, entity: Any, plane: Plane, keep: Any, options: Any, context: Any, /
    ) -> Any: ...


@runtime_checkable
class SectionFunction(Protocol):
    """``section(entity, plane, options, context)``: the cut itself, or ``None``."""

    def __call__(self, entity: Any, plane: Plane, options: Any, context: Any, /) -> Any: ...


@runtime_checkable
class FitFunction(Protocol):
    """``function(entities, options)``: a ``FitResult`` (or a bare surface)."""

    def __call__(self, entities: list[Any], options: Any, /) -> Any: ...


@runtime_checkable
class BuildFunction(Protocol):
    """``function(scene, options) -> Scene`` (a new scene; scenes are never changed)."""

    def __call__(self, scene: Scene, options: Any, /) -> Scene: ...


@runtime_checkable
class VoxelizeFunction(Protocol):
    """``function(scene, options) -> LinearOctree`` of the scene's closed bodies."""

    def __call__(self, scene: Scene, options: Any, /) -> LinearOctree: ...


@runtime_checkable
class CheckFunction(Protocol):
    """``function(scene, options, context) -> [Defect, ...]``: the defects one criterion finds.

    ``context`` is a :class:`geobrep.ops.inspection.CheckContext` (the tolerance asked for, and
    a cache shared by the checks of one inspection)."""

    def __call__(self, scene: Scene, options: Any, context: Any, /) -> list[Any]: ...


class GeobrepPluginWarning(UserWarning):
    """A plugin failed to load, or its item lost a name clash; geobrep carries on without it."""


class UnknownItemError(GeobrepError, KeyError):
    """No item of that name is registered; the message lists the registered names."""

    def __str__(self) -> str:
        # KeyError would show the repr of the message, quotes and all.
        return str(self.args[0]) if self.args else ""


class NoOptions(BaseModel):
    """The options model of an item that takes no options: any option is rejected."""

    model_config = ConfigDict(extra="forbid", frozen=True, defer_build=True)


def _format_loc(loc: tuple[int | str, ...]) -> str:
    return ".".join(str(part) for part in loc)


class RegisteredItem(BaseModel):
    """What every registered item has: a name, a description, an options model, a plugin.

    Example:
        >>> class PlaneOptions(BaseModel):
        ...     model_config = ConfigDict(extra="forbid")
        ...     tolerance: float = 1e-9
        >>> item = RegisteredItem(name="plane", options=PlaneOptions)
        >>> item.validate_options(tolerance=0.5)
        PlaneOptions(tolerance=0.5)
    """

    model_config = ConfigDict(frozen=True, arbitrary_types_allowed=True, defer_build=True)

    kind: ClassVar[str] = "item"

    name: str
    description: str = ""
    options: type[BaseModel] = NoOptions
    plugin: str = ""
    builtin: bool = False
    """Registered by one of geobrep's own plugins (set by the loader; a plugin's value is
    overwritten). Built-in formats win extension ties over other plugins' formats."""

    @field_validator("name")
    @classmethod
    def _check_name(cls, value: str) -> str:
        if not _NAME_PATTERN.fullmatch(value):
            raise ValueError(
                f"{cls.kind} name {value!r} is not valid: use lowercase letters, digits "
                "and '_', '.', '-', starting with a letter or digit (e.g. 'xyz', 'surface.plane')"
            )
        return value

    @property
    def label(self) -> str:
        """``"format 'xyz'"``: how messages name this item."""
        return f"{self.kind} {self.name!r}"

    def validate_options(
        self, options: Mapping[str, Any] | BaseModel | None = None, /, **kwargs: Any
    ) -> BaseModel:
        """Validate ``options`` (a mapping or model instance) plus keywords into ``self.options``.

        Unknown options are rejected even when the options model forgot ``extra="forbid"``.

        Raises:
            OptionsError: naming this item and each bad option.

        Example:
            >>> RegisteredItem(name="noop").validate_options({"speed": 3})
            Traceback (most recent call last):
            ...
            geobrep.errors.OptionsError: item 'noop': option 'speed': unknown option (this item takes no options)
        """  # noqa: E501
        model = self.options
        if isinstance(options, model) and not kwargs:
            return options
        if isinstance(options, BaseModel):
            if not isinstance(options, model):
                raise OptionsError(
                    f"{self.label}: options must be a {model.__name__} "
                    f"(or a mapping), not a {type(options).__name__}"
                )
            data: dict[str, Any] = options.model_dump(exclude_unset=True)
        elif options is None:
            data = {}
        elif isinstance(options, Mapping):
            data = dict(options)
        else:
            raise OptionsError(
                f"{self.label}: options must be a mapping or a {model.__name__}, "
                f"not a {type(options).__name__}"
            )
        for key in kwargs:
            if key in data and not isinstance(options, BaseModel):
                raise OptionsError(f"{self.label}: option {key!r} given twice")
        data.update(kwargs)
        self._reject_unknown(data)
        try:
            return model.model_validate(data)
        except ValidationError as exc:
            raise OptionsError(f"{self.label}: {self._describe(exc)}") from exc

    def _accepted_keys(self) -> set[str]:
        keys: set[str] = set()
        for field_name, info in self.options.model_fields.items():
            keys.add(field_name)
            if info.alias:
                keys.add(info.alias)
            if isinstance(info.validation_alias, str):
                keys.add(info.validation_alias)
            elif isinstance(info.validation_alias, AliasChoices):
                keys.update(c for c in info.validation_alias.choices if isinstance(c, str))
        return keys

    def _valid_options_text(self) -> str:
        names = sorted(self.options.model_fields)
        if not names:
            return "this item takes no options"
        return "valid options: " + ", ".join(names)

    def _reject_unknown(self, data: Mapping[Any, Any]) -> None:
        extra = self.options.model_config.get("extra")
        if extra in ("forbid", "allow"):
            return  # pydantic rejects (or deliberately keeps) extras itself
        accepted = self._accepted_keys()
        unknown = [key for key in data if key not in accepted]
        if unknown:
            problems = "; ".join(
                f"option {key!r}: unknown option ({self._valid_options_text()})" for key in unknown
            )
            raise OptionsError(f"{self.label}: {problems}")

    def _describe(self, exc: ValidationError) -> str:
        problems = []
        for error in exc.errors(include_url=False):
            loc = _format_loc(error["loc"])
            message = error["msg"]
            if error["type"] == "extra_forbidden":
                message = f"unknown option ({self._valid_options_text()})"
            problems.append(f"option {loc!r}: {message}" if loc else f"options: {message}")
        return "; ".join(problems)


class FormatCapabilities(BaseModel):
    """What a format can store, so callers can warn before a lossy write.

    Example:
        >>> FormatCapabilities(entity_types=frozenset({"PointSet"}), point_data=True).point_data
        True
    """

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    entity_types: frozenset[str] = frozenset()
    point_data: bool = False
    cell_data: bool = False
    names: bool = False
    ids: bool = False
    topology: bool = False
    crs: bool = False
    multiple_entities: bool = False
    empty_entities: bool = False
    """Entities without geometry (a GOCAD header-only object) are kept, not dropped."""


class FormatSpec(RegisteredItem):
    """A file format: extensions, a reader and/or a writer, an optional content sniffer.

    ``reader(path, options) -> Scene``, ``writer(scene, path, options) -> None`` and
    ``sniff(first_bytes) -> bool`` (the first :data:`SNIFF_BYTES` bytes of the file).

    Example:
        >>> spec = FormatSpec(name="xyz", extensions=("XYZ",), reader=lambda path, options: None)
        >>> spec.extensions, spec.can_read, spec.can_write
        (('.xyz',), True, False)
    """

    kind: ClassVar[str] = "format"

    extensions: tuple[str, ...] = ()
    reader: Reader | None = None
    writer: Writer | None = None
    sniff: Sniffer | None = None
    # made without validation (it equals FormatCapabilities()): a validated default would build
    # the schema, and pydantic's plugin loader with it, when this module is imported
    capabilities: FormatCapabilities = FormatCapabilities.model_construct()
    losses: LossReporter | None = None
    """``losses(scene, path) -> [sentence, ...]``: what the writer drops for this target beyond
    what :attr:`capabilities` says (e.g. a GOCAD .ts holds surfaces only)."""
    generic_content: bool = False
    """The sniffer recognises generic content (e.g. rows of plain numbers): the format is
    chosen by content only when no other format's sniffer recognises the file."""

    @field_validator("extensions", mode="before")
    @classmethod
    def _normalise_extensions(cls, value: Any) -> Any:
        if isinstance(value, str):
            value = (value,)
        if not isinstance(value, Iterable):
            return value  # let pydantic report the type error
        normalised: list[str] = []
        for raw in value:
            if not isinstance(raw, str):
                raise ValueError(f"extension {raw!r} is not a string")
            ext = raw.strip().lower()
            if not ext.startswith("."):
                ext = "." + ext
            if not _EXTENSION_PATTERN.fullmatch(ext):
                raise ValueError(f"extension {raw!r} is not valid (expected e.g. '.ts', '.tar.gz')")
            if ext not in normalised:
                normalised.append(ext)
        return tuple(normalised)

    @model_validator(mode="after")
    def _needs_reader_or_writer(self) -> FormatSpec:
        if self.reader is None and self.writer is None:
            raise ValueError(f"format {self.name!r} needs a reader, a writer or both")
        return self

    @property
    def can_read(self) -> bool:
        """True if this format has a reader."""
        return self.reader is not None

    @property
    def can_write(self) -> bool:
        """True if this format has a writer."""
        return self.writer is not None

    def matches(self, path: Path | str) -> str | None:
        """The longest of this format's extensions that ends ``path``'s file name, if any."""
        return _longest_extension(self.extensions, Path(path).name.lower())


class ClipperSpec(RegisteredItem):
    """Cuts one entity type by a plane.

    ``function(entity, plane, keep, options, context)`` returns the clipped entity (same type) or
    ``None`` for ``keep="negative"`` / ``"positive"``, and the tuple ``(negative, positive)`` for
    ``keep="both"``; ``context`` is a :class:`geobrep.ops.clipping.ClipContext`. The optional
    ``section(entity, plane, options, context)`` returns the cut itself (a lower-dimensional
    entity on the plane) or ``None``.

    Example:
        >>> spec = ClipperSpec(name="pointset", entity_type="PointSet",
        ...                    function=lambda entity, plane, keep, options, context: entity)
        >>> spec.kind, spec.section is None
        ('clipper', True)
    """

    kind: ClassVar[str] = "clipper"

    entity_type: str
    function: ClipFunction
    section: SectionFunction | None = None


class FitterSpec(RegisteredItem):
    """Fits a surface or curve to data: ``function(entities, options) -> entity``.

    Example:
        >>> FitterSpec(name="plane", function=lambda e, o: None, input_types=("PointSet",)).kind
        'fitter'
    """

    kind: ClassVar[str] = "fitter"

    function: FitFunction
    input_types: tuple[str, ...] = ()


class BuilderSpec(RegisteredItem):
    """Builds derived structure (topology, blocks): ``function(scene, options) -> Scene``.

    Example:
        >>> BuilderSpec(name="blocks", function=lambda s, o: s, input_types=("Surface",)).kind
        'builder'
    """

    kind: ClassVar[str] = "builder"

    function: BuildFunction
    input_types: tuple[str, ...] = ()


class VoxelizerSpec(RegisteredItem):
    """Turns closed bodies into a linear octree: ``function(scene, options) -> LinearOctree``.

    ``scene`` holds the bodies to voxelize (its blocks, or closed surfaces when it has none);
    ``options`` is an instance of ``options`` (a pydantic model) with at least ``depth``.
    :func:`geobrep.voxelize` validates the options and calls it.

    Example:
        >>> VoxelizerSpec(name="octree", function=lambda scene, options: None).kind
        'voxelizer'
    """

    kind: ClassVar[str] = "voxelizer"

    function: VoxelizeFunction


class CheckSpec(RegisteredItem):
    """One inspection criterion: ``function(scene, options, context) -> [Defect, ...]``.

    ``title`` is the section heading in a report; ``default`` says whether
    :func:`geobrep.inspect` runs it when no ``checks`` are named; ``repairs`` names the
    :func:`geobrep.repair` action that mends what it finds, if any.

    Example:
        >>> CheckSpec(name="mesh.isolated_vertices", function=lambda s, o, c: []).kind
        'check'
    """

    kind: ClassVar[str] = "check"

    function: CheckFunction
    title: str = ""
    family: str = ""
    default: bool = True
    repairs: str | None = None


T = TypeVar("T", bound=RegisteredItem)


@dataclass(frozen=True, eq=False)
class Pending:
    """A declared item of a built-in plugin whose module is not imported yet.

    The registry holds it under its name until the item is used: ``load()`` imports the
    plugin and replaces each of its pending items by the item its hook registers. It answers
    what choosing a format needs without the import (:mod:`geobrep.host._declared`).
    """

    declared: Declared
    plugin: str
    load: Callable[[], None]
    builtin: bool = True

    @property
    def name(self) -> str:
        """The item's name."""
        return self.declared.name

    @property
    def extensions(self) -> tuple[str, ...]:
        """A format's extensions."""
        return self.declared.extensions

    @property
    def can_read(self) -> bool:
        """A format that reads."""
        return self.declared.reads

    @property
    def can_write(self) -> bool:
        """A format that writes."""
        return self.declared.writes

    @property
    def generic_content(self) -> bool:
        """A format whose sniffer recognises generic content."""
        return self.declared.generic_content


class Registry(Generic[T]):
    """Items of one kind by name, iterated in name order.

    ``plugin``, when given, stamps every added item as registered by that plugin, and as
    :attr:`~RegisteredItem.builtin` or not by ``builtin`` (the loader gives each plugin its
    own staging registry this way).

    Example:
        >>> registry = ClipperRegistry()
        >>> _ = registry.add(ClipperSpec(name="pointset", entity_type="PointSet", function=print))
        >>> registry.names(), "pointset" in registry
        (['pointset'], True)
    """

    item_type: ClassVar[type[RegisteredItem]] = RegisteredItem

    def __init__(
        self, items: Iterable[T] = (), *, plugin: str | None = None, builtin: bool = False
    ) -> None:
        self._items: dict[str, T] = {}
        self._pending: dict[str, Pending] = {}
        self.plugin = plugin
        self.builtin = builtin
        for item in items:
            self.add(item)

    @property
    def kind(self) -> str:
        """The kind of item held, e.g. ``"format"``."""
        return self.item_type.kind

    def add(self, item: T) -> T:
        """Register ``item``; return the item now registered under its name.

        A name taken by another plugin warns and keeps the first item; a name registered
        twice by the same plugin raises :class:`~geobrep.errors.PluginError`.
        """
        if not isinstance(item, self.item_type):
            raise PluginError(
                f"{type(self).__name__}.add() takes a {self.item_type.__name__}, "
                f"not {type(item).__name__} ({item!r:.80})"
            )
        if self.plugin is not None and (item.plugin, item.builtin) != (self.plugin, self.builtin):
            item = item.model_copy(update={"plugin": self.plugin, "builtin": self.builtin})
        pending = self._pending.get(item.name)
        if pending is not None and pending.plugin == item.plugin:
            del self._pending[item.name]  # the declared item, now imported
            self._items[item.name] = item
            return item
        if pending is not None:
            pending.load()  # the item the name is taken by, to return it
        existing = self._items.get(item.name)
        if existing is None:
            self._items[item.name] = item
            return item
        if existing.plugin == item.plugin:
            raise PluginError(
                f"{item.label} registered twice by {_plugin_label(item.plugin)}: "
                "each name may be registered once"
            )
        self._warn_taken(item.label, item.plugin, existing.plugin)
        return existing

    def declare(self, pending: Pending) -> bool:
        """Hold ``pending`` under its name until it is used; False if the name is taken (a
        warning, like :meth:`add`: the first registration wins)."""
        name = pending.name
        existing = self._items.get(name) or self._pending.get(name)
        if existing is None:
            self._pending[name] = pending
            return True
        label = f"{self.kind} {name!r}"
        if existing.plugin == pending.plugin:
            raise PluginError(
                f"{label} registered twice by {_plugin_label(pending.plugin)}: "
                "each name may be registered once"
            )
        self._warn_taken(label, pending.plugin, existing.plugin)
        return False

    def pending(self, plugin: str) -> list[str]:
        """The names ``plugin`` declared that are not imported yet."""
        pending = list(self._pending.items())  # a copy: another thread may import meanwhile
        return sorted(name for name, item in pending if item.plugin == plugin)

    def forget_pending(self, plugin: str) -> None:
        """Drop the items ``plugin`` declared and did not register (its import failed)."""
        for name in self.pending(plugin):
            self._pending.pop(name, None)

    def load_pending(self) -> None:
        """Import every plugin with an item pending here (each once)."""
        loads = {id(item.load): item.load for item in list(self._pending.values())}
        for load in loads.values():
            load()

    def entries(self) -> list[T | Pending]:
        """Every item by name, pending ones as they are (no plugin is imported)."""
        every: dict[str, T | Pending] = {**self._pending, **self._items}
        return [every[name] for name in sorted(every)]

    def loaded(self, entry: T | Pending) -> T | None:
        """The registered item ``entry`` stands for, importing its plugin if it is pending
        (None if that import failed)."""
        if isinstance(entry, Pending):
            entry.load()
            return self._items.get(entry.name)
        return entry

    def _warn_taken(self, label: str, plugin: str, holder: str) -> None:
        warnings.warn(
            f"{label} from {_plugin_label(plugin)} ignored: the name is already "
            f"registered by {_plugin_label(holder)}",
            GeobrepPluginWarning,
            stacklevel=3,
        )

    def get(self, name: str) -> T:
        """The item called ``name``; :class:`UnknownItemError` lists the names if absent."""
        pending = self._pending.get(name)
        if pending is not None:
            pending.load()
        try:
            return self._items[name]
        except KeyError:
            raise UnknownItemError(f"unknown {self.kind} {name!r}; {self._available()}") from None

    def names(self) -> list[str]:
        """Registered names, sorted (pending ones too: no plugin is imported)."""
        return sorted([*self._items, *self._pending])

    def _available(self) -> str:
        if not self._items and not self._pending:
            return f"no {self.kind}s are registered"
        return f"registered {self.kind}s: " + ", ".join(self.names())

    def __contains__(self, name: object) -> bool:
        return name in self._items or name in self._pending

    def __iter__(self) -> Iterator[T]:
        self.load_pending()
        return iter([self._items[name] for name in sorted(self._items)])

    def __len__(self) -> int:
        return len(self._items) + len(self._pending)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.names()!r})"


def _plugin_label(plugin: str) -> str:
    return f"plugin {plugin!r}" if plugin else "direct registration"


def _read_head(path: Path) -> bytes:
    """The first :data:`SNIFF_BYTES` of ``path``, or ``b""`` if it cannot be read."""
    try:
        with path.open("rb") as stream:
            return stream.read(SNIFF_BYTES)
    except (OSError, ValueError):
        return b""


def _sniffs_at_all(entry: FormatSpec | Pending) -> bool:
    """Whether the format has a sniffer (a pending one: whether it declares one)."""
    if isinstance(entry, Pending):
        return entry.declared.sniffs
    return entry.sniff is not None


def _describe_formats(formats: Iterable[FormatSpec | Pending]) -> str:
    parts = []
    for spec in formats:
        extensions = ", ".join(spec.extensions) or "no extension"
        origin = f", plugin {spec.plugin!r}" if spec.plugin else ""
        parts.append(f"{spec.name} ({extensions}{origin})")
    return "; ".join(parts) if parts else "none"


class FormatRegistry(Registry[FormatSpec]):
    """File formats, with reader/writer choice by name, extension and content.

    Example:
        >>> formats = FormatRegistry()
        >>> _ = formats.add(FormatSpec(name="xyz", extensions=(".xyz",), reader=print))
        >>> formats.choose_reader(Path("points.XYZ")).name
        'xyz'
    """

    item_type: ClassVar[type[RegisteredItem]] = FormatSpec

    def for_extension(self, ext: str) -> list[FormatSpec]:
        """Formats declaring extension ``ext`` (``"xyz"`` or ``".XYZ"`` alike), by name."""
        wanted = ext.strip().lower()
        if not wanted.startswith("."):
            wanted = "." + wanted
        return [spec for spec in self if wanted in spec.extensions]

    def readers(self) -> list[FormatSpec]:
        """Formats that can read, by name."""
        return [spec for spec in self if spec.can_read]

    def writers(self) -> list[FormatSpec]:
        """Formats that can write, by name."""
        return [spec for spec in self if spec.can_write]

    def choose_reader(self, path: Path | str, format: str | None = None) -> FormatSpec:
        """The format to read ``path`` with.

        An explicit ``format`` name wins; otherwise the longest matching extension. Of
        several formats with that extension, one named in ``GEOBREP_PREFER_FORMATS`` wins,
        else geobrep's built-in formats win over plugins' (:func:`break_tie`). Sniffing of the
        first :data:`SNIFF_BYTES` bytes decides between those left, or between all readers
        when no extension matches; of the formats whose sniffer says yes, a preferred one
        wins, then those without ``generic_content``, then the built-in ones. A plugin
        sniffer that raises or takes over ``GEOBREP_SNIFF_TIMEOUT`` seconds says no (and is
        reported: a :class:`GeobrepPluginWarning`, or a :class:`PluginError` in strict mode).

        Raises:
            UnknownFormatError: nothing matches, or several formats match equally.
        """
        path = Path(path)
        if format is not None:
            return self._named(format, path, "read")
        readers = self._able("read")
        candidates = break_tie(_longest_match(readers, path))
        head = _read_head(path) if candidates else b""
        if len(candidates) == 1:
            chosen = self._extension_or_content(candidates[0], readers, head)
            return self._chosen(chosen, lambda: self.choose_reader(path))
        head = head or _read_head(path)
        pool = candidates or readers
        sniffed = [spec for spec in pool if self._sniffs(spec, head)]
        specific = [spec for spec in sniffed if not spec.generic_content]
        if specific and len(specific) < len(sniffed) and _preferred(sniffed) is None:
            sniffed = specific  # a format that knows this content beats a generic one
        sniffed = break_tie(sniffed)
        if len(sniffed) == 1:
            return self._chosen(sniffed[0], lambda: self.choose_reader(path))
        if sniffed or candidates:
            self._ambiguous(sniffed or candidates, path, "read")
        raise UnknownFormatError(
            f"no installed format can read this file (extension "
            f"{''.join(path.suffixes).lower() or 'none'}, content not recognised); "
            f"formats that can read: {_describe_formats(readers)}",
            path=path,
        )

    def choose_writer(self, path: Path | str, format: str | None = None) -> FormatSpec:
        """The format to write ``path`` with: explicit ``format`` name, else extension.

        Of several formats with the extension, :func:`break_tie` picks a preferred or
        built-in one.

        Raises:
            UnknownFormatError: nothing matches, or several formats share the extension.
        """
        path = Path(path)
        if format is not None:
            return self._named(format, path, "write")
        writers = self._able("write")
        candidates = break_tie(_longest_match(writers, path))
        if len(candidates) == 1:
            return self._chosen(candidates[0], lambda: self.choose_writer(path))
        if candidates:
            self._ambiguous(candidates, path, "write")
        raise UnknownFormatError(
            f"no installed format writes extension "
            f"{''.join(path.suffixes).lower() or '(none)'}; "
            f"formats that can write: {_describe_formats(writers)}; pass format='<name>'",
            path=path,
        )

    def _able(self, action: str) -> list[FormatSpec | Pending]:
        """The formats (pending ones as declared) that can ``action`` ("read", "write")."""
        if action == "read":
            return [entry for entry in self.entries() if entry.can_read]
        return [entry for entry in self.entries() if entry.can_write]

    def _chosen(self, entry: FormatSpec | Pending, again: Callable[[], FormatSpec]) -> FormatSpec:
        """The format ``entry`` stands for; if its plugin failed to import, choose ``again``
        (among the formats left)."""
        spec = self.loaded(entry)
        return again() if spec is None else spec

    def _named(self, name: str, path: Path, action: str) -> FormatSpec:
        able = self._able(action)
        if name not in self:
            raise UnknownFormatError(
                f"unknown format {name!r}; formats that can {action}: {_describe_formats(able)}",
                path=path,
            )
        spec = self.get(name)
        if (action == "read" and not spec.can_read) or (action == "write" and not spec.can_write):
            raise UnknownFormatError(
                f"format {name!r} cannot {action}; formats that can {action}: "
                f"{_describe_formats(able)}",
                path=path,
            )
        return spec

    @staticmethod
    def _ambiguous(candidates: list[FormatSpec | Pending], path: Path, action: str) -> None:
        raise UnknownFormatError(
            f"several formats can {action} this file: {_describe_formats(candidates)}; "
            f"pass format='<name>' to choose one",
            path=path,
        )

    def _extension_or_content(
        self, chosen: FormatSpec | Pending, readers: list[FormatSpec | Pending], head: bytes
    ) -> FormatSpec | Pending:
        """The format an extension names, unless its sniffer refuses the content and exactly one
        other format knows it (a GeoJSON file named ``.json``, the extension of 3D Tiles).

        Without a sniffer, or with no head, or when no other specific format claims the content,
        the extension's format reads it (and its reader says what is wrong).
        """
        if not _sniffs_at_all(chosen) or not head or self._sniffs(chosen, head):
            return chosen
        others = [
            spec
            for spec in readers
            if spec is not chosen and not spec.generic_content and self._sniffs(spec, head)
        ]
        return others[0] if len(others) == 1 else chosen

    def _sniffs(self, entry: FormatSpec | Pending, head: bytes) -> bool:
        if not head or not _sniffs_at_all(entry):
            return False
        spec = self.loaded(entry)  # a pending format's sniffer: its plugin is imported
        if spec is None:
            return False
        sniff = spec.sniff
        if sniff is None or not head or id(sniff) in _HUNG_SNIFFERS:
            return False
        try:
            if spec.builtin:
                return bool(sniff(head))
            return call_bounded(
                lambda: bool(sniff(head)), sniff_timeout(), f"the sniffer of {spec.label}"
            )
        except KeyboardInterrupt:
            raise
        except PluginTimeoutError as exc:
            _HUNG_SNIFFERS[id(sniff)] = sniff
            _report_sniff(
                spec,
                f"{exc}; it is treated as no match from now on (the limit is "
                f"{SNIFF_TIMEOUT_ENV}, in seconds)",
                exc,
            )
        except BaseException as exc:  # plugin code: isolated and reported
            problem = f"sniff raised {type(exc).__name__}: {exc}; treated as no match"
            _report_sniff(spec, problem, exc)
        return False


_HUNG_SNIFFERS: dict[int, Sniffer] = {}
"""Sniffers that overran their time limit (by id; the value keeps the id from being reused)."""


def _report_sniff(spec: FormatSpec, problem: str, exc: BaseException) -> None:
    message = f"{spec.label} from {_plugin_label(spec.plugin)}: {problem}"
    if strict_mode():
        raise PluginError(message) from exc
    warnings.warn(message, GeobrepPluginWarning, stacklevel=4)


def preferred_formats() -> tuple[str, ...]:
    """The format names of ``GEOBREP_PREFER_FORMATS`` (comma separated), in order."""
    raw = os.environ.get(PREFER_ENV, "")
    return tuple(part.strip().lower() for part in raw.split(",") if part.strip())


#: A format, or a built-in one not imported yet.
F = TypeVar("F", bound=FormatSpec | Pending)


def _preferred(formats: list[F]) -> F | None:
    by_name = {spec.name: spec for spec in formats}
    for name in preferred_formats():
        if name in by_name:
            return by_name[name]
    return None


def break_tie(formats: list[F]) -> list[F]:
    """Of formats matching a file equally: the first preferred one, else the built-in ones.

    A plugin's format overrides a built-in one only when asked: by ``format=`` or by naming
    it in ``GEOBREP_PREFER_FORMATS``.

    Example:
        >>> own = FormatSpec(name="own", extensions=(".x",), reader=print, builtin=True)
        >>> other = FormatSpec(name="other", extensions=(".x",), reader=print, plugin="p")
        >>> [spec.name for spec in break_tie([other, own])]
        ['own']
    """
    if len(formats) < 2:
        return formats
    preferred = _preferred(formats)
    if preferred is not None:
        return [preferred]
    own = [spec for spec in formats if spec.builtin]
    return own or formats


def _longest_extension(extensions: Iterable[str], file_name: str) -> str | None:
    """The longest of ``extensions`` that ends the lower-case ``file_name`` (and is not all)."""
    hits = [ext for ext in extensions if file_name.endswith(ext) and file_name != ext]
    return max(hits, key=len) if hits else None


def _longest_match(formats: list[F], path: Path) -> list[F]:
    name = path.name.lower()  # once, not once per format (a Path each cost 1 ms a file)
    matched = [(spec, _longest_extension(spec.extensions, name)) for spec in formats]
    longest = max((len(ext) for _, ext in matched if ext), default=0)
    return [spec for spec, ext in matched if ext and len(ext) == longest]


class ClipperRegistry(Registry[ClipperSpec]):
    """Clippers, one per entity type or variant."""

    item_type: ClassVar[type[RegisteredItem]] = ClipperSpec

    def for_entity_type(self, entity_type: str) -> list[ClipperSpec]:
        """Clippers declared for ``entity_type`` (e.g. ``"Surface"``), by name."""
        return [spec for spec in self if spec.entity_type == entity_type]


class FitterRegistry(Registry[FitterSpec]):
    """Surface and curve fitters."""

    item_type: ClassVar[type[RegisteredItem]] = FitterSpec


class BuilderRegistry(Registry[BuilderSpec]):
    """Topology and block builders."""

    item_type: ClassVar[type[RegisteredItem]] = BuilderSpec


class VoxelizerRegistry(Registry[VoxelizerSpec]):
    """Voxelizers: closed bodies to linear octrees."""

    item_type: ClassVar[type[RegisteredItem]] = VoxelizerSpec


class CheckRegistry(Registry[CheckSpec]):
    """Inspection criteria (:func:`geobrep.inspect`, ``geobrep check``)."""

    item_type: ClassVar[type[RegisteredItem]] = CheckSpec


@dataclass(frozen=True)
class Registries:
    """The registries, one per hook kind.

    Example:
        >>> Registries().formats
        FormatRegistry([])
    """

    formats: FormatRegistry = field(default_factory=FormatRegistry)
    clippers: ClipperRegistry = field(default_factory=ClipperRegistry)
    fitters: FitterRegistry = field(default_factory=FitterRegistry)
    builders: BuilderRegistry = field(default_factory=BuilderRegistry)
    voxelizers: VoxelizerRegistry = field(default_factory=VoxelizerRegistry)
    checks: CheckRegistry = field(default_factory=CheckRegistry)
    operations: OperationRegistry = field(default_factory=lambda: _operation_registry())

    KINDS: ClassVar[tuple[str, ...]] = (
        "formats",
        "clippers",
        "fitters",
        "builders",
        "voxelizers",
        "checks",
        "operations",
    )

    @classmethod
    def staging(cls, plugin: str, *, builtin: bool = False) -> Registries:
        """Empty registries that stamp each added item with ``plugin`` and ``builtin``."""
        return cls(
            formats=FormatRegistry(plugin=plugin, builtin=builtin),
            clippers=ClipperRegistry(plugin=plugin, builtin=builtin),
            fitters=FitterRegistry(plugin=plugin, builtin=builtin),
            builders=BuilderRegistry(plugin=plugin, builtin=builtin),
            voxelizers=VoxelizerRegistry(plugin=plugin, builtin=builtin),
            checks=CheckRegistry(plugin=plugin, builtin=builtin),
            operations=_operation_registry(plugin=plugin, builtin=builtin),
        )

    def by_kind(self) -> dict[str, Registry[Any]]:
        """``{"formats": ..., "clippers": ..., ...}``."""
        return {kind: getattr(self, kind) for kind in self.KINDS}


def _operation_registry(plugin: str | None = None, builtin: bool = False) -> OperationRegistry:
    from geobrep.host.operations import OperationRegistry  # it builds on this module

    return OperationRegistry(plugin=plugin, builtin=builtin)
