"""Discover, isolate and load geobrep plugins into the registries.

Plugins come from the ``geobrep.plugins`` entry-point group (built-ins too), loaded in a
deterministic order: built-ins (module ``geobrep.*``) first, then the rest by entry-point
name. Each plugin is imported, registered with pluggy and has its hooks called on its own,
into staging registries; only a plugin that succeeds entirely is committed. A failure (any
exception, :class:`BaseException` subclasses included, but :class:`KeyboardInterrupt`) is a
:class:`~geobrep.host.registry.GeobrepPluginWarning` and the plugin is marked ``"failed"``.

The import and the hooks of a plugin from another distribution run in a daemon thread
(:func:`geobrep.host._isolation.call_bounded`): one that does not finish within
``GEOBREP_PLUGIN_TIMEOUT`` seconds (default 10) is reported, skipped and abandoned. geobrep's
own plugins are imported directly and their items are marked ``builtin``.

geobrep's own plugins are not imported at discovery: their items are declared as plain data
(:mod:`geobrep.host._declared`), held in the registries as
:class:`~geobrep.host.registry.Pending` entries, and a plugin's module is imported (and its
hooks called) when one of its items is first used (:meth:`PluginHost.materialize`). Such a
plugin is listed ``"loaded"`` with its declared items from the start.

Environment:
    ``GEOBREP_STRICT_PLUGINS=1`` (also ``true``/``yes``/``on``): a failure raises
    :class:`~geobrep.errors.PluginError` instead of warning.
    ``GEOBREP_DISABLE_PLUGINS=a,b``: entry-point names never imported (status ``"disabled"``).
    ``GEOBREP_PLUGIN_TIMEOUT=seconds``: the time limit above.

Example:
    >>> host = get_host()
    >>> [info.name for info in host.plugins if info.status == "loaded"]  # doctest: +SKIP
    ['native', 'example']
"""

from __future__ import annotations

import os
import threading
import types
import warnings
from collections.abc import Iterable
from functools import cached_property, partial
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from geobrep.errors import PluginError
from geobrep.host._declared import BUILTIN_PLUGINS
from geobrep.host._entry_points import ENTRY_POINT_GROUP, PROJECT_NAME, entry_points
from geobrep.host._entry_points import EntryPointLike as EntryPoint
from geobrep.host._entry_points import distribution as _distribution
from geobrep.host._entry_points import is_builtin as _is_builtin
from geobrep.host._entry_points import is_own as _is_own
from geobrep.host._isolation import (
    STRICT_ENV,
    TIMEOUT_ENV,
    PluginTimeoutError,
    call_bounded,
    in_plugin_thread,
    plugin_timeout,
    strict_mode,
)
from geobrep.host.registry import (
    GeobrepPluginWarning,
    Pending,
    RegisteredItem,
    Registries,
    Registry,
)

if TYPE_CHECKING:
    import pluggy

__all__ = [
    "DISABLE_ENV",
    "ENTRY_POINT_GROUP",
    "HOOK_KINDS",
    "STRICT_ENV",
    "TIMEOUT_ENV",
    "PluginHost",
    "PluginInfo",
    "disabled_plugins",
    "discover_entry_points",
    "get_host",
    "register_plugin",
    "reset",
    "set_host",
    "strict_mode",
]

DISABLE_ENV = "GEOBREP_DISABLE_PLUGINS"

HOOK_KINDS: dict[str, str] = {
    "geobrep_register_formats": "formats",
    "geobrep_register_clippers": "clippers",
    "geobrep_register_fitters": "fitters",
    "geobrep_register_builders": "builders",
    "geobrep_register_voxelizers": "voxelizers",
    "geobrep_register_checks": "checks",
    "geobrep_register_operations": "operations",
}
"""Each hook and the :class:`~geobrep.host.registry.Registries` field it fills."""

Status = Literal["loaded", "failed", "disabled"]


def _nothing_registered() -> dict[str, tuple[str, ...]]:
    return {kind: () for kind in Registries.KINDS}


class PluginInfo(BaseModel):
    """One plugin: where it came from, whether it loaded, what it registered.

    ``registered`` maps each kind (``"formats"``, ``"clippers"``, ``"fitters"``,
    ``"builders"``) to the names this plugin holds in the registries; empty tuples for a
    plugin that failed or is disabled. A built-in plugin is ``"loaded"`` with its declared
    items from discovery on (:mod:`geobrep.host._declared`), though its module is imported only
    when one of them is first used; should that import fail, it becomes ``"failed"``.

    Example:
        >>> info = PluginInfo(name="example", module="geobrep_example_plugin", status="disabled")
        >>> info.status, info.registered["formats"]
        ('disabled', ())
    """

    model_config = ConfigDict(frozen=True)

    name: str
    module: str
    distribution: str | None = None
    version: str | None = None
    status: Status
    builtin: bool = False
    """A plugin of geobrep itself (its formats win extension ties over other plugins')."""
    error: str | None = None
    registered: dict[str, tuple[str, ...]] = Field(default_factory=_nothing_registered)


def disabled_plugins() -> frozenset[str]:
    """Entry-point names listed in ``GEOBREP_DISABLE_PLUGINS`` (comma separated)."""
    raw = os.environ.get(DISABLE_ENV, "")
    return frozenset(part.strip() for part in raw.split(",") if part.strip())


def discover_entry_points() -> list[EntryPoint]:
    """The ``geobrep.plugins`` entry points in load order: built-ins, then by name."""

    def order(entry_point: EntryPoint) -> tuple[bool, str, str]:
        return (not _is_builtin(entry_point), entry_point.name, _distribution(entry_point)[0] or "")

    return sorted(entry_points(group=ENTRY_POINT_GROUP), key=order)


def _listed(registered: dict[str, tuple[str, ...]]) -> str:
    parts = [f"{kind} {', '.join(names)}" for kind, names in registered.items() if names]
    return "; ".join(parts) or "nothing"


def _origin(name: str, module: str, distribution: str | None, version: str | None) -> str:
    if distribution is None:
        return f"plugin {name!r} (module {module!r}, no distribution)"
    return f"plugin {name!r} (module {module!r}, distribution {distribution} {version or ''})"


class PluginHost:
    """The pluggy manager, the registries and what each plugin did.

    Example:
        >>> from geobrep.hookspecs import hookimpl
        >>> from geobrep.host.registry import FormatSpec
        >>> class Plugin:
        ...     @hookimpl
        ...     def geobrep_register_formats(self, registry):
        ...         registry.add(FormatSpec(name="demo", reader=print))
        >>> host = PluginHost()
        >>> host.register(Plugin(), "demo").registered["formats"]
        ('demo',)
    """

    def __init__(self) -> None:
        self.registries = Registries()
        self._plugins: list[PluginInfo] = []
        self._deferred: dict[str, EntryPoint] = {}
        self._lock = threading.RLock()

    @cached_property
    def manager(self) -> pluggy.PluginManager:
        """The pluggy manager (made when the first plugin is imported)."""
        import pluggy

        from geobrep.hookspecs import GeobrepSpecs

        manager = pluggy.PluginManager(PROJECT_NAME)
        manager.add_hookspecs(GeobrepSpecs)
        return manager

    @property
    def plugins(self) -> list[PluginInfo]:
        """Every plugin seen, in load order."""
        return list(self._plugins)

    def info(self, name: str) -> PluginInfo:
        """The :class:`PluginInfo` of the plugin called ``name``."""
        for info in self._plugins:
            if info.name == name:
                return info
        raise PluginError(
            f"no plugin named {name!r}; plugins: {', '.join(i.name for i in self._plugins)}"
        )

    def load_entry_points(self, entry_points: Iterable[EntryPoint] | None = None) -> None:
        """Load ``entry_points`` (default: :func:`discover_entry_points`), honouring the env."""
        disabled = disabled_plugins()
        eps = discover_entry_points() if entry_points is None else list(entry_points)
        with self._lock:
            for entry_point in eps:
                self._load_entry_point(entry_point, disabled)

    def register(
        self,
        plugin: object,
        name: str,
        *,
        module: str | None = None,
        distribution: str | None = None,
        version: str | None = None,
    ) -> PluginInfo:
        """Register an in-process plugin (module, class instance, ...) and call its hooks.

        Failures are isolated like those of entry-point plugins: a warning and status
        ``"failed"`` (or :class:`~geobrep.errors.PluginError` in strict mode).
        """
        if module is None:
            if isinstance(plugin, types.ModuleType):
                module = plugin.__name__
            else:
                module = getattr(plugin, "__module__", None) or type(plugin).__module__
        with self._lock:
            return self._register(plugin, name, module, distribution, version)

    def _load_entry_point(self, entry_point: EntryPoint, disabled: frozenset[str]) -> None:
        name, module = entry_point.name, entry_point.module
        distribution, version = _distribution(entry_point)
        builtin = _is_own(entry_point)
        if name in disabled:
            self._plugins.append(
                PluginInfo(
                    name=name,
                    module=module,
                    distribution=distribution,
                    version=version,
                    status="disabled",
                    builtin=builtin,
                )
            )
            return
        if self._taken(name, module, distribution, version):
            return
        declared = BUILTIN_PLUGINS.get(name)
        if builtin and declared is not None and declared[0] == module:
            self._declare(entry_point, declared[1], distribution, version)
            return
        limit = None if builtin else plugin_timeout()
        try:
            if limit is None:
                plugin = entry_point.load()
            else:
                plugin = call_bounded(entry_point.load, limit, f"the import of {module!r}")
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # plugin code: isolated and reported
            self._fail(name, module, distribution, version, exc)
            return
        self._register(plugin, name, module, distribution, version, builtin=builtin, limit=limit)

    def _declare(
        self,
        entry_point: EntryPoint,
        items: Iterable[Any],
        distribution: str | None,
        version: str | None,
    ) -> None:
        """List a built-in plugin with its declared items, pending in the registries; its
        module is imported when one of them is used (:meth:`materialize`)."""
        name = entry_point.name
        load = partial(self.materialize, name)
        targets = self.registries.by_kind()
        registered: dict[str, list[str]] = {kind: [] for kind in Registries.KINDS}
        for item in items:
            if targets[item.kind].declare(Pending(item, name, load)):
                registered[item.kind].append(item.name)
        self._deferred[name] = entry_point
        self._plugins.append(
            PluginInfo(
                name=name,
                module=entry_point.module,
                distribution=distribution,
                version=version,
                status="loaded",
                builtin=True,
                registered={kind: tuple(sorted(names)) for kind, names in registered.items()},
            )
        )

    def materialize(self, name: str) -> None:
        """Import the built-in plugin ``name`` if it is still pending, call its hooks and put
        its items in the place of their declarations (nothing if it was imported already).

        A failure is reported like a failing plugin's (a warning, or
        :class:`~geobrep.errors.PluginError` in strict mode); its declared items are dropped.
        An item its hooks register that was not declared, or one declared and not registered,
        is a :class:`~geobrep.errors.PluginError` (the declarations are out of date).
        """
        with self._lock:
            entry_point = self._deferred.pop(name, None)
            if entry_point is None:
                return
            index = next(i for i, info in enumerate(self._plugins) if info.name == name)
            declared = self._plugins[index]
            try:
                plugin = entry_point.load()
                staging = Registries.staging(name, builtin=True)
                if self.manager.register(plugin, name=name) is None:
                    raise PluginError(f"pluggy blocked the plugin name {name!r}")
                self.manager.check_pending()
                self._call_hooks(name, staging)
            except KeyboardInterrupt:
                raise
            except BaseException as exc:  # isolated and reported like any plugin's failure
                for registry in self.registries.by_kind().values():
                    registry.forget_pending(name)
                del self._plugins[index]
                failed = self._fail(
                    name, declared.module, declared.distribution, declared.version, exc
                )
                self._plugins.remove(failed)
                self._plugins.insert(index, failed)
                return
            registered = self._commit(staging)
            left = {
                kind: registry.pending(name)
                for kind, registry in self.registries.by_kind().items()
                if registry.pending(name)
            }
            if registered != declared.registered or left:
                for registry in self.registries.by_kind().values():
                    registry.forget_pending(name)
                raise PluginError(
                    f"the built-in plugin {name!r} registered {_listed(registered)}, but "
                    f"geobrep.host._declared declares {_listed(declared.registered)}"
                )

    def _taken(self, name: str, module: str, distribution: str | None, version: str | None) -> bool:
        for info in self._plugins:
            if info.name == name:
                other = info.distribution or f"module {info.module!r}"
                error = PluginError(f"the plugin name {name!r} is already used by {other}")
                self._fail(name, module, distribution, version, error)
                return True
        return False

    def _register(
        self,
        plugin: object,
        name: str,
        module: str,
        distribution: str | None,
        version: str | None,
        *,
        builtin: bool = False,
        limit: float | None = None,
    ) -> PluginInfo:
        """Register ``plugin`` and call its hooks (within ``limit`` seconds, if given)."""
        if self._taken(name, module, distribution, version):
            return self._plugins[-1]
        staging = Registries.staging(name, builtin=builtin)
        registered_with_pluggy = False
        try:
            if self.manager.register(plugin, name=name) is None:
                raise PluginError(f"pluggy blocked the plugin name {name!r}")
            registered_with_pluggy = True
            self.manager.check_pending()
            if limit is None:
                self._call_hooks(name, staging)
            else:
                call_bounded(
                    lambda: self._call_hooks(name, staging), limit, f"the hooks of {name!r}"
                )
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # plugin code: isolated and reported
            if registered_with_pluggy:
                self.manager.unregister(name=name)
            return self._fail(name, module, distribution, version, exc)
        info = PluginInfo(
            name=name,
            module=module,
            distribution=distribution,
            version=version,
            status="loaded",
            builtin=builtin,
            registered=self._commit(staging),
        )
        self._plugins.append(info)
        return info

    def _call_hooks(self, name: str, staging: Registries) -> None:
        registries = staging.by_kind()
        for hook_name, kind in HOOK_KINDS.items():
            caller: pluggy.HookCaller = getattr(self.manager.hook, hook_name)
            arguments: dict[str, object] = {"registry": registries[kind]}
            for impl in caller.get_hookimpls():
                if impl.plugin_name != name:
                    continue
                if impl.wrapper or impl.hookwrapper:
                    raise PluginError(f"{hook_name}: registry hooks cannot be wrappers")
                impl.function(*[arguments[arg] for arg in impl.argnames])

    def _commit(self, staging: Registries) -> dict[str, tuple[str, ...]]:
        registered = _nothing_registered()
        targets = self.registries.by_kind()
        for kind, scratch in staging.by_kind().items():
            target: Registry[Any] = targets[kind]
            kept: list[str] = []
            item: RegisteredItem
            for item in scratch:
                if target.add(item) is item:
                    kept.append(item.name)
            registered[kind] = tuple(kept)
        return registered

    def _fail(
        self,
        name: str,
        module: str,
        distribution: str | None,
        version: str | None,
        exc: BaseException,
    ) -> PluginInfo:
        error = f"{type(exc).__name__}: {exc}"
        info = PluginInfo(
            name=name,
            module=module,
            distribution=distribution,
            version=version,
            status="failed",
            error=error,
        )
        self._plugins.append(info)
        message = f"{_origin(name, module, distribution, version)} failed: {error}"
        if isinstance(exc, PluginTimeoutError):
            message += f" (the limit is {TIMEOUT_ENV}, in seconds)"
        if strict_mode():
            raise PluginError(message) from exc
        warnings.warn(
            f"{message}; it was skipped (set {STRICT_ENV}=1 to make this an error, "
            f"or {DISABLE_ENV}={name} to silence it)",
            GeobrepPluginWarning,
            stacklevel=2,
        )
        return info


_lock = threading.RLock()
_host: PluginHost | None = None
_loading = False


def get_host() -> PluginHost:
    """The process-wide :class:`PluginHost`, discovering entry points on first use.

    Thread-safe; loading happens once. If strict mode makes loading raise, nothing is cached
    and the next call tries again.
    """
    global _host, _loading
    host = _host
    if host is not None:
        return host
    if _loading and in_plugin_thread():
        # the loader holds the lock while it waits for this thread: refuse, do not deadlock
        raise PluginError("geobrep plugins were used by a plugin hook while loading")
    with _lock:
        if _host is not None:
            return _host
        if _loading:
            raise PluginError("geobrep plugins were used by a plugin hook while loading")
        _loading = True
        try:
            host = PluginHost()
            host.load_entry_points()
        finally:
            _loading = False
        _host = host
        return host


def reset() -> None:
    """Forget the loaded plugins; the next :func:`get_host` rediscovers them."""
    set_host(None)


def set_host(host: PluginHost | None) -> PluginHost | None:
    """Install ``host`` as the process-wide host (``None``: rediscover); return the old one.

    Tests use it to save and restore the global state::

        previous = set_host(None)
        ...
        set_host(previous)
    """
    global _host
    with _lock:
        previous, _host = _host, host
        return previous


def register_plugin(plugin: object, name: str) -> PluginInfo:
    """Register an in-process ``plugin`` under ``name`` with the global host.

    Example:
        >>> import my_geobrep_plugin  # doctest: +SKIP
        >>> register_plugin(my_geobrep_plugin, "mine").status  # doctest: +SKIP
        'loaded'
    """
    with _lock:
        return get_host().register(plugin, name)
