"""Bounds on plugin code: time limits, strictness, and the threads plugin code runs in.

Third-party plugin code (the import of an entry point, its registration hooks, a format's
sniffer) runs in a daemon thread that geobrep stops waiting for after a time limit; whatever it
raises (any :class:`BaseException` but :class:`KeyboardInterrupt`) comes back to the caller, who
reports it. A thread that does not finish in time is abandoned, not killed: Python cannot stop
a thread, so a plugin stuck in a loop keeps a CPU busy until the process exits.

Environment:
    ``GEOBREP_PLUGIN_TIMEOUT`` (seconds, default 10): how long the import of one plugin, and
    then its registration hooks, may take.
    ``GEOBREP_SNIFF_TIMEOUT`` (seconds, default 2): how long one plugin sniffer may take.
    ``GEOBREP_STRICT_PLUGINS=1`` (also ``true``/``yes``/``on``): failures raise
    :class:`~geobrep.errors.PluginError` instead of warning.

Example:
    >>> call_bounded(lambda: 6 * 7, 1.0, "the answer")
    42
"""

from __future__ import annotations

import os
import threading
import warnings
from collections.abc import Callable
from typing import TypeVar, cast

from geobrep.errors import PluginError

__all__ = [
    "DEFAULT_PLUGIN_TIMEOUT",
    "DEFAULT_SNIFF_TIMEOUT",
    "SNIFF_TIMEOUT_ENV",
    "STRICT_ENV",
    "TIMEOUT_ENV",
    "PluginTimeoutError",
    "call_bounded",
    "in_plugin_thread",
    "plugin_timeout",
    "sniff_timeout",
    "strict_mode",
]

STRICT_ENV = "GEOBREP_STRICT_PLUGINS"
TIMEOUT_ENV = "GEOBREP_PLUGIN_TIMEOUT"
SNIFF_TIMEOUT_ENV = "GEOBREP_SNIFF_TIMEOUT"
DEFAULT_PLUGIN_TIMEOUT = 10.0
DEFAULT_SNIFF_TIMEOUT = 2.0

T = TypeVar("T")

_plugin_threads: set[int] = set()
"""Identifiers of the threads running plugin code right now."""


class PluginTimeoutError(PluginError):
    """Plugin code did not finish within its time limit; geobrep stopped waiting for it."""


def strict_mode() -> bool:
    """True if ``GEOBREP_STRICT_PLUGINS`` asks for plugin failures to raise."""
    return os.environ.get(STRICT_ENV, "").strip().lower() in {"1", "true", "yes", "on"}


def _seconds(variable: str, default: float) -> float:
    raw = os.environ.get(variable, "").strip()
    if not raw:
        return default
    try:
        value = float(raw)
    except ValueError:
        value = -1.0
    if not 0 < value < float("inf"):
        from geobrep.host.registry import GeobrepPluginWarning

        warnings.warn(
            f"{variable}={raw!r} is not a positive number of seconds; using {default:g}",
            GeobrepPluginWarning,
            stacklevel=3,
        )
        return default
    return value


def plugin_timeout() -> float:
    """Seconds the import, then the hooks, of one plugin may take: ``GEOBREP_PLUGIN_TIMEOUT``."""
    return _seconds(TIMEOUT_ENV, DEFAULT_PLUGIN_TIMEOUT)


def sniff_timeout() -> float:
    """Seconds one plugin sniffer may take: ``GEOBREP_SNIFF_TIMEOUT``."""
    return _seconds(SNIFF_TIMEOUT_ENV, DEFAULT_SNIFF_TIMEOUT)


def in_plugin_thread() -> bool:
    """True when called from plugin code that :func:`call_bounded` runs."""
    return threading.get_ident() in _plugin_threads


def call_bounded(function: Callable[[], T], seconds: float, what: str) -> T:
    """``function()`` run in a daemon thread: its result, or what it raised, raised here.

    Raises:
        PluginTimeoutError: ``function`` did not return within ``seconds`` (it is abandoned).
        BaseException: whatever ``function`` raised, re-raised in the calling thread.
    """
    outcome: list[tuple[bool, object]] = []

    def run() -> None:
        ident = threading.get_ident()
        _plugin_threads.add(ident)
        try:
            outcome.append((True, function()))
        except BaseException as exc:  # handed to the caller
            outcome.append((False, exc))
        finally:
            _plugin_threads.discard(ident)

    thread = threading.Thread(target=run, name=f"geobrep: {what}", daemon=True)
    thread.start()
    thread.join(seconds)
    if not outcome:
        raise PluginTimeoutError(f"{what} did not finish within {seconds:g} s")
    done, value = outcome[0]
    if done:
        return cast(T, value)
    assert isinstance(value, BaseException)
    raise value
