"""geobrep's own plugins are declared as data (geobrep.host._declared) and imported on first use.

The declarations must say exactly what each plugin's hooks register (checked against the
plugins imported and registered the ordinary way); discovery imports no plugin module; using
an item imports its plugin alone; a built-in plugin that fails at that import is reported like
any failing plugin; third-party plugins are imported at discovery, as before, next to them.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path

import pytest

import geobrep
from geobrep.errors import PluginError, UnknownFormatError
from geobrep.host import loader as plugin_loader
from geobrep.host._declared import BUILTIN_PLUGINS, Declared
from geobrep.host.loader import ENTRY_POINT_GROUP, PluginHost, discover_entry_points
from geobrep.host.registry import FormatSpec, GeobrepPluginWarning, Pending

TSURF = Path(__file__).parents[1] / "data" / "gocad" / "2triangles.ts"

#: Every module of a built-in plugin (the package each entry point names, and what is in it).
PLUGIN_MODULES = tuple(module for module, _ in BUILTIN_PLUGINS.values())


def _registered(name: str) -> list[Declared]:
    """What plugin ``name``'s hooks register, imported and registered the ordinary way."""
    module = importlib.import_module(BUILTIN_PLUGINS[name][0])
    host = PluginHost()
    info = host.register(module, name)
    assert info.status == "loaded", info.error
    found: list[Declared] = []
    for kind, registry in host.registries.by_kind().items():
        for item in registry:
            if isinstance(item, FormatSpec):
                found.append(
                    Declared(
                        kind,
                        item.name,
                        item.extensions,
                        reads=item.can_read,
                        writes=item.can_write,
                        sniffs=item.sniff is not None,
                        generic_content=item.generic_content,
                    )
                )
            else:
                found.append(Declared(kind, item.name))
    return sorted(found, key=lambda d: (d.kind, d.name))


def test_every_builtin_entry_point_is_declared() -> None:
    ours = {
        ep.name: ep.value
        for ep in entry_points(group=ENTRY_POINT_GROUP)
        if ep.value.startswith("geobrep.")
    }
    assert ours == {name: module for name, (module, _) in BUILTIN_PLUGINS.items()}


@pytest.mark.parametrize("name", sorted(BUILTIN_PLUGINS))
def test_declarations_are_what_the_hooks_register(name: str) -> None:
    declared = sorted(BUILTIN_PLUGINS[name][1], key=lambda d: (d.kind, d.name))
    assert _registered(name) == declared


def test_discovery_lists_the_builtins_without_importing_them() -> None:
    host = PluginHost()
    host.load_entry_points()
    gocad = host.info("gocad")
    assert (gocad.status, gocad.builtin) == ("loaded", True)
    assert gocad.registered["formats"] == ("gocad", "skua")
    entries = {entry.name: entry for entry in host.registries.formats.entries()}
    assert isinstance(entries["vtu"], Pending)
    assert "vtu" in host.registries.formats
    assert "vtu" in host.registries.formats.names()
    assert host.manager.get_plugin("meshio") is None  # not imported, so not in pluggy yet
    # choosing a .ts reader imports gocad only
    assert host.registries.formats.choose_reader(TSURF).name == "gocad"
    assert host.manager.get_plugin("gocad") is not None
    entries = {entry.name: entry for entry in host.registries.formats.entries()}
    assert isinstance(entries["gocad"], FormatSpec)
    assert isinstance(entries["skua"], FormatSpec)  # the same plugin: imported together
    assert isinstance(entries["vtu"], Pending)
    # iterating (listing every format) imports them all
    assert all(isinstance(spec, FormatSpec) for spec in host.registries.formats)
    assert not [e for e in host.registries.formats.entries() if isinstance(e, Pending)]
    assert host.registries.clippers.get("surface").plugin == "clip"


PROBE = """
import json, sys, warnings
warnings.simplefilter("error")
step = sys.argv[1]
import geobrep
if step in ("read", "clip"):
    scene = geobrep.read(sys.argv[2])
if step == "clip":
    from geobrep.host import registries
    registries().clippers.get("surface")
if step == "plugins":
    from geobrep.host import list_plugins
    print(json.dumps([(p.name, p.status) for p in list_plugins()]))
print(json.dumps(sorted(sys.modules)))
"""


def _modules(*args: str, path: str | None = None) -> list[str]:
    env = dict(os.environ)
    if path is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [path, env.get("PYTHONPATH")]))
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    modules: list[str] = json.loads(done.stdout.splitlines()[-1])
    return modules


def _plugins_loaded(modules: list[str]) -> set[str]:
    return {m for m in PLUGIN_MODULES if m in modules}


def test_listing_the_plugins_imports_none() -> None:
    modules = _modules("plugins")
    assert not _plugins_loaded(modules)
    assert "pluggy" not in modules


def test_reading_a_tsurf_imports_the_gocad_plugin_alone() -> None:
    modules = _modules("read", str(TSURF))
    assert _plugins_loaded(modules) == {"geobrep.adapters.gocad"}
    # the GOCAD grid and well readers and writers are imported for files of their type only
    for grid in ("_voxet", "_sgrid", "_well", "_voxet_writer", "_sgrid_writer", "_writer"):
        assert f"geobrep.adapters.gocad.{grid}" not in modules


def test_using_a_clipper_imports_the_clip_plugin() -> None:
    modules = _modules("clip", str(TSURF))
    assert _plugins_loaded(modules) == {"geobrep.adapters.gocad", "geobrep.plugins.clip"}


def test_a_third_party_plugin_is_discovered_and_used_next_to_them(
    example_plugin: Path, tmp_path: Path
) -> None:
    points = tmp_path / "points.xyz"
    points.write_text("1 2 3\n4 5 6\n")
    modules = _modules("read", str(points), path=str(example_plugin))
    assert "geobrep_example_plugin" in modules  # imported at discovery, as before
    assert not _plugins_loaded(modules)  # .xyz is the example's: no built-in was imported
    geobrep.plugins.reload()
    assert geobrep.read(points).entities[0].vertices.shape == (2, 3)
    assert geobrep.plugins.registries().formats.get("xyz").plugin == "example"
    assert geobrep.read(TSURF).surfaces[0].faces.shape == (2, 3)


def _with_builtin(
    monkeypatch: pytest.MonkeyPatch, name: str, module: str, items: tuple[Declared, ...]
) -> list[EntryPoint]:
    """The real entry points and a built-in one called ``name`` declared with ``items``."""
    monkeypatch.setitem(BUILTIN_PLUGINS, name, (module, items))
    extra = EntryPoint(name=name, value=module, group=ENTRY_POINT_GROUP)
    return [*discover_entry_points(), extra]


def test_a_builtin_failing_at_its_import_is_reported_and_dropped(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    declared = (Declared("formats", "brk", (".brk",), reads=True),)
    eps = _with_builtin(monkeypatch, "broken", "geobrep.adapters.no_such_module", declared)
    host = PluginHost()
    host.load_entry_points(eps)
    assert host.info("broken").status == "loaded"
    assert "brk" in host.registries.formats
    with (
        pytest.warns(GeobrepPluginWarning, match=r"plugin 'broken'.*failed: ModuleNotFoundError"),
        pytest.raises(UnknownFormatError, match="no installed format can read"),
    ):
        host.registries.formats.choose_reader(tmp_path / "a.brk")
    info = host.info("broken")
    assert info.status == "failed"
    assert "ModuleNotFoundError" in str(info.error)
    assert "brk" not in host.registries.formats
    assert [p.name for p in host.plugins].count("broken") == 1


def test_declarations_out_of_date_are_an_error(monkeypatch: pytest.MonkeyPatch) -> None:
    module, items = BUILTIN_PLUGINS["blocks"]
    monkeypatch.delitem(BUILTIN_PLUGINS, "blocks")
    stale = (*items, Declared("builders", "gone"))
    eps = [ep for ep in discover_entry_points() if ep.name != "blocks"]
    eps += _with_builtin(monkeypatch, "blocks2", module, stale)[-1:]
    host = PluginHost()
    host.load_entry_points(eps)
    assert host.registries.builders.names() == ["blocks", "gone"]
    with pytest.raises(PluginError, match=r"'blocks2' registered builders blocks, but"):
        host.registries.builders.get("gone")
    assert host.registries.builders.names() == ["blocks"]


def test_the_global_host_defers_too() -> None:
    plugin_loader.set_host(None)
    formats = geobrep.plugins.registries().formats
    assert any(isinstance(entry, Pending) for entry in formats.entries())
    assert geobrep.read(TSURF).surfaces
