"""Plugin discovery and isolation through fake entry points and in-process plugins."""

from __future__ import annotations

import importlib
import subprocess
import sys
import threading
from collections.abc import Callable
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

import geobrep.plugins
from geobrep.errors import PluginError
from geobrep.hookspecs import GeobrepSpecs
from geobrep.host import loader as plugin_loader
from geobrep.host.loader import (
    DISABLE_ENV,
    ENTRY_POINT_GROUP,
    HOOK_KINDS,
    STRICT_ENV,
    PluginHost,
    PluginInfo,
    discover_entry_points,
    get_host,
)
from geobrep.host.registry import FitterRegistry, FormatRegistry, GeobrepPluginWarning, Registries
from geobrep.plugins import FitterSpec, FormatSpec, hookimpl

SetEntryPoints = Callable[..., list[EntryPoint]]  # the fake_entry_points fixture


def by_name(plugins: list[PluginInfo]) -> dict[str, PluginInfo]:
    return {info.name: info for info in plugins}


# --- discovery order ---------------------------------------------------------------------


def test_builtins_load_first_then_by_name(fake_entry_points: SetEntryPoints) -> None:
    fake_entry_points(
        zeta="geobrep_fake_good",
        alpha="geobrep_fake_no_args",
        zz_builtin="geobrep.adapters.native",
        aa_builtin="geobrep.hookspecs",
    )
    assert [ep.name for ep in discover_entry_points()] == [
        "aa_builtin",
        "zz_builtin",
        "alpha",
        "zeta",
    ]


def test_real_discovery_finds_the_native_builtin() -> None:
    eps = discover_entry_points()
    assert any(ep.name == "native" and ep.module == "geobrep.adapters.native" for ep in eps)
    info = by_name(geobrep.plugins.list_plugins())["native"]
    assert info.distribution == "geobrep"
    assert info.status == "loaded"


# --- isolation ---------------------------------------------------------------------------


def test_good_plugins_load_and_bad_ones_fail_alone(fake_entry_points: SetEntryPoints) -> None:
    fake_entry_points(
        broken="geobrep_fake_broken_import",
        good="geobrep_fake_good",
        raises="geobrep_fake_hook_raises",
        invalid="geobrep_fake_invalid_item",
        wrongtype="geobrep_fake_wrong_type",
        selfdup="geobrep_fake_self_duplicate",
        unknownhook="geobrep_fake_unknown_hook",
    )
    with pytest.warns(GeobrepPluginWarning) as caught:
        host = get_host()
    plugins = by_name(host.plugins)
    assert [info.name for info in host.plugins] == [
        "broken",
        "good",
        "invalid",
        "raises",
        "selfdup",
        "unknownhook",
        "wrongtype",
    ]
    assert plugins["good"].status == "loaded"
    assert plugins["good"].registered == {
        "formats": ("fakegood",),
        "clippers": ("fakegood.points",),
        "fitters": (),
        "builders": (),
        "voxelizers": (),
        "checks": (),
        "operations": (),
    }
    failed = {name for name, info in plugins.items() if info.status == "failed"}
    assert failed == set(plugins) - {"good"}
    for name in failed:
        assert plugins[name].registered == dict.fromkeys(Registries.KINDS, ())
        assert plugins[name].error
    assert "ModuleNotFoundError" in str(plugins["broken"].error)
    assert "RuntimeError: boom from geobrep_fake_hook_raises" in str(plugins["raises"].error)
    assert "fitter name 'Not A Valid Name' is not valid" in str(plugins["invalid"].error)
    assert "FormatRegistry.add() takes a FormatSpec" in str(plugins["wrongtype"].error)
    assert "builder 'twice' registered twice by plugin 'selfdup'" in str(plugins["selfdup"].error)
    assert "geobrep_register_widgets" in str(plugins["unknownhook"].error)

    # Nothing of a failed plugin is kept, not even what it registered before failing.
    registries = host.registries
    assert registries.formats.names() == ["fakegood"]
    assert registries.clippers.names() == ["fakegood.points"]
    assert registries.fitters.names() == []  # 'partial' came from the failing plugin
    assert registries.builders.names() == []
    assert registries.formats.get("fakegood").plugin == "good"

    messages = [str(w.message) for w in caught]
    assert len(messages) == len(failed)
    assert any(
        "plugin 'broken' (module 'geobrep_fake_broken_import', no distribution) failed: "
        "ModuleNotFoundError" in m
        for m in messages
    )
    # A failed plugin is not left behind in pluggy either.
    for name in failed:
        assert host.manager.get_plugin(name) is None
    assert host.manager.get_plugin("good") is not None


def test_duplicate_name_across_plugins_warns_first_wins(fake_entry_points: SetEntryPoints) -> None:
    fake_entry_points(b_dup="geobrep_fake_duplicate", a_good="geobrep_fake_good")
    with pytest.warns(GeobrepPluginWarning, match="format 'fakegood' from plugin 'b_dup' ignored"):
        host = get_host()
    plugins = by_name(host.plugins)
    assert plugins["b_dup"].status == "loaded"
    assert plugins["b_dup"].registered["formats"] == ("dupextra",)
    assert host.registries.formats.get("fakegood").plugin == "a_good"
    assert host.registries.formats.get("fakegood").extensions == (".fgood",)
    assert host.registries.formats.get("dupextra").plugin == "b_dup"


def test_hook_with_fewer_arguments_is_still_called(fake_entry_points: SetEntryPoints) -> None:
    fake_entry_points(noargs="geobrep_fake_no_args")
    get_host()
    assert importlib.import_module("geobrep_fake_no_args").calls == ["called"]


def test_same_entry_point_name_twice(
    fake_entry_points: SetEntryPoints, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake_entry_points(good="geobrep_fake_good")
    twins = [
        EntryPoint(name="good", value="geobrep_fake_good", group=ENTRY_POINT_GROUP),
        EntryPoint(name="good", value="geobrep_fake_duplicate", group=ENTRY_POINT_GROUP),
    ]
    host = PluginHost()
    with pytest.warns(GeobrepPluginWarning, match="plugin name 'good' is already used"):
        host.load_entry_points(twins)
    assert [info.status for info in host.plugins] == ["loaded", "failed"]
    assert "geobrep_fake_duplicate" not in sys.modules  # not even imported


# --- strict and disabled -----------------------------------------------------------------


def test_strict_mode_raises_plugin_error(
    fake_entry_points: SetEntryPoints, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake_entry_points(good="geobrep_fake_good", raises="geobrep_fake_hook_raises")
    monkeypatch.setenv(STRICT_ENV, "1")
    with pytest.raises(
        PluginError, match=r"plugin 'raises' .* failed: RuntimeError: boom"
    ) as caught:
        get_host()
    assert isinstance(caught.value.__cause__, RuntimeError)
    assert plugin_loader._host is None  # nothing half-loaded is cached
    with pytest.raises(PluginError):
        get_host()
    monkeypatch.setenv(STRICT_ENV, "0")
    with pytest.warns(GeobrepPluginWarning):
        assert by_name(get_host().plugins)["good"].status == "loaded"


def test_strict_mode_chains_the_import_error(
    fake_entry_points: SetEntryPoints, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake_entry_points(broken="geobrep_fake_broken_import")
    monkeypatch.setenv(STRICT_ENV, "true")
    with pytest.raises(PluginError, match="plugin 'broken'") as caught:
        get_host()
    assert isinstance(caught.value.__cause__, ImportError)


def test_disabled_plugins_are_never_imported(
    fake_entry_points: SetEntryPoints, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake_entry_points(
        good="geobrep_fake_good", off="geobrep_fake_disabled", raises="geobrep_fake_hook_raises"
    )
    monkeypatch.setenv(DISABLE_ENV, " off ,raises,, ")
    monkeypatch.setenv(STRICT_ENV, "1")  # a disabled plugin is no failure, even in strict mode
    host = get_host()
    plugins = by_name(host.plugins)
    assert plugins["off"].status == "disabled"
    assert plugins["off"].module == "geobrep_fake_disabled"
    assert plugins["raises"].status == "disabled"
    assert plugins["good"].status == "loaded"
    assert "geobrep_fake_disabled" not in sys.modules
    assert "geobrep_fake_hook_raises" not in sys.modules
    assert host.registries.formats.names() == ["fakegood"]


def test_env_helpers(monkeypatch: pytest.MonkeyPatch) -> None:
    assert not plugin_loader.strict_mode()
    for value in ("1", "TRUE", " yes ", "on"):
        monkeypatch.setenv(STRICT_ENV, value)
        assert plugin_loader.strict_mode()
    for value in ("0", "", "no", "off"):
        monkeypatch.setenv(STRICT_ENV, value)
        assert not plugin_loader.strict_mode()
    monkeypatch.setenv(DISABLE_ENV, "a, b ,,c")
    assert plugin_loader.disabled_plugins() == {"a", "b", "c"}


# --- in-process plugins ------------------------------------------------------------------


class FitterPlugin:
    @hookimpl
    def geobrep_register_fitters(self, registry: FitterRegistry) -> None:
        registry.add(FitterSpec(name="inprocess", function=print))


class FailingPlugin:
    @hookimpl
    def geobrep_register_formats(self, registry: FormatRegistry) -> None:
        registry.add(FormatSpec(name="halfway", reader=print))
        raise ValueError("no luck")


def test_register_in_process_plugin() -> None:
    info = geobrep.plugins.register(FitterPlugin(), "fitters-in-process")
    assert info.status == "loaded"
    assert info.module == __name__
    assert info.distribution is None
    assert info.registered["fitters"] == ("inprocess",)
    assert geobrep.plugins.registries().fitters.get("inprocess").plugin == "fitters-in-process"
    assert info in geobrep.plugins.list_plugins()


def test_register_failing_in_process_plugin(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.warns(GeobrepPluginWarning, match="plugin 'failing' .* failed: ValueError"):
        info = geobrep.plugins.register(FailingPlugin(), "failing")
    assert info.status == "failed"
    assert "halfway" not in geobrep.plugins.registries().formats
    monkeypatch.setenv(STRICT_ENV, "1")
    with pytest.raises(PluginError, match="plugin 'failing-strict'"):
        geobrep.plugins.register(FailingPlugin(), "failing-strict")


def test_register_the_same_name_twice_fails() -> None:
    geobrep.plugins.register(FitterPlugin(), "twice")
    with pytest.warns(GeobrepPluginWarning, match="plugin name 'twice' is already used"):
        info = geobrep.plugins.register(FitterPlugin(), "twice")
    assert info.status == "failed"


def test_wrapper_hooks_are_rejected() -> None:
    class Wrapper:
        @hookimpl(wrapper=True)
        def geobrep_register_formats(self, registry: FormatRegistry) -> object:
            return (yield)

    with pytest.warns(GeobrepPluginWarning, match="registry hooks cannot be wrappers"):
        assert PluginHost().register(Wrapper(), "wrapper").status == "failed"


def test_a_hook_using_the_registries_while_loading_fails_cleanly(
    fake_entry_points: SetEntryPoints,
) -> None:
    class Reentrant:
        @hookimpl
        def geobrep_register_formats(self, registry: FormatRegistry) -> None:
            geobrep.plugins.registries()

    def load_reentrant(self: PluginHost, entry_points: object = None) -> None:
        self.register(Reentrant(), "reentrant")

    fake_entry_points()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(PluginHost, "load_entry_points", load_reentrant)
        with pytest.warns(GeobrepPluginWarning, match="used by a plugin hook while loading"):
            host = get_host()
    assert host.plugins[0].status == "failed"


# --- the global host and the facade -------------------------------------------------------


def test_get_host_loads_once_across_threads(
    fake_entry_points: SetEntryPoints, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake_entry_points(good="geobrep_fake_good")
    calls: list[int] = []
    original = plugin_loader.discover_entry_points

    def counting() -> list[EntryPoint]:
        calls.append(1)
        return original()

    monkeypatch.setattr(plugin_loader, "discover_entry_points", counting)
    hosts: list[PluginHost] = []
    barrier = threading.Barrier(8)

    def worker() -> None:
        barrier.wait()
        hosts.append(get_host())

    threads = [threading.Thread(target=worker) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(calls) == 1
    assert len({id(host) for host in hosts}) == 1


def test_reload_rediscovers_and_forgets_in_process_plugins(
    fake_entry_points: SetEntryPoints,
) -> None:
    fake_entry_points(good="geobrep_fake_good")
    first = get_host()
    geobrep.plugins.register(FitterPlugin(), "temporary")
    assert "inprocess" in geobrep.plugins.registries().fitters
    geobrep.plugins.reload()
    assert get_host() is not first
    assert "inprocess" not in geobrep.plugins.registries().fitters
    assert [p.name for p in geobrep.plugins.list_plugins()] == ["good"]


def test_reset_and_set_host() -> None:
    host = PluginHost()
    previous = plugin_loader.set_host(host)
    assert get_host() is host
    plugin_loader.reset()
    assert get_host() is not host
    plugin_loader.set_host(previous)


def test_host_info_lookup() -> None:
    host = PluginHost()
    host.register(FitterPlugin(), "mine")
    assert host.info("mine").registered["fitters"] == ("inprocess",)
    with pytest.raises(PluginError, match="no plugin named 'other'; plugins: mine"):
        host.info("other")


def test_hook_kinds_cover_every_hook() -> None:
    hooks = {name for name in vars(GeobrepSpecs) if name.startswith("geobrep_")}
    assert set(HOOK_KINDS) == hooks
    assert set(HOOK_KINDS.values()) == set(Registries.KINDS)


def test_facade_exports() -> None:
    for name in geobrep.plugins.__all__:
        assert getattr(geobrep.plugins, name) is not None
    assert geobrep.plugins.FormatSpec is FormatSpec
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        geobrep.plugins.Nope  # noqa: B018


def test_importing_the_markers_is_cheap() -> None:
    code = (
        "import sys, geobrep; before = set(sys.modules); "
        "import geobrep.plugins, geobrep.hookspecs; "
        "from geobrep.plugins import hookimpl; "
        "new = {m.split('.')[0] for m in set(sys.modules) - before}; "
        "heavy = new & {'numpy', 'scipy', 'pydantic', 'rtree', 'meshio'}; "
        "assert not heavy, heavy"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=Path(__file__).parent)
