"""Plugins cannot break built-in formats, hang a command or escape with a traceback (issue 15).

The reproducers in tests/data/reliability/plugins/ are real entry points (a module plus a
``*.dist-info`` folder): each test puts one on ``PYTHONPATH`` of a fresh Python process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
import warnings
from collections.abc import Iterator
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

import geobrep
from geobrep.errors import PluginError
from geobrep.host import loader as plugin_loader
from geobrep.host._isolation import (
    DEFAULT_PLUGIN_TIMEOUT,
    PluginTimeoutError,
    call_bounded,
    plugin_timeout,
    sniff_timeout,
)
from geobrep.host.loader import ENTRY_POINT_GROUP, PluginHost
from geobrep.host.registry import (
    FormatRegistry,
    FormatSpec,
    GeobrepPluginWarning,
    break_tie,
)

DATA = Path(__file__).resolve().parents[1] / "data"
PLUGINS = DATA / "reliability" / "plugins"
TRIANGLES = DATA / "gocad" / "2triangles.ts"
GUARD = 120  # seconds: a hang guard for the subprocess, not a timing assertion


def run_with(plugin: str, code: str, **env: str) -> tuple[subprocess.CompletedProcess[str], float]:
    """Run ``python -c code`` with the reproducer ``plugin`` installed; (result, seconds)."""
    clean = {k: v for k, v in os.environ.items() if not k.startswith("GEOBREP_")}
    clean["PYTHONPATH"] = str(PLUGINS / plugin)
    clean.update(env)
    start = time.perf_counter()
    result = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=clean,
        timeout=GUARD,
        check=False,
    )
    return result, time.perf_counter() - start


def cli(plugin: str, *args: str, **env: str) -> tuple[subprocess.CompletedProcess[str], float]:
    """Run the ``geobrep`` command line with the reproducer ``plugin`` installed."""
    code = f"import sys; from geobrep.cli.main import main; sys.exit(main({list(args)!r}))"
    return run_with(plugin, code, **env)


# --- a plugin claiming the built-in extensions ------------------------------------------------

CLAIMED = (".ts", ".geobrep", ".ply", ".vtu", ".csv")

READ_ALL = """
import json, sys, warnings
from pathlib import Path
import geobrep
from geobrep.host import registries
formats = registries().formats
result = {}
for name in sys.argv[1:]:
    path = Path(name)
    scene = geobrep.read(path)
    result[path.suffix] = [formats.choose_reader(path).name, len(scene.entities[0].vertices)]
print(json.dumps(result))
"""


@pytest.fixture(scope="module")
def claimed_files(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """The GOCAD triangles written in each format the reproducer claims."""
    folder = tmp_path_factory.mktemp("claimed")
    scene = geobrep.read(TRIANGLES)
    paths = [folder / "tri.ts"]
    paths[0].write_bytes(TRIANGLES.read_bytes())
    points = geobrep.PointSet(name="tri", vertices=scene.entities[0].vertices)
    for extension in CLAIMED[1:]:
        paths.append(folder / f"tri{extension}")
        geobrep.write(points if extension == ".csv" else scene, paths[-1])
    return paths


def test_a_plugin_claiming_builtin_extensions_leaves_them_builtin(
    claimed_files: list[Path],
) -> None:
    from geobrep.host import registries

    formats = registries().formats
    expected = {
        path.suffix: [
            formats.choose_reader(path).name,
            len(geobrep.read(path).entities[0].vertices),
        ]
        for path in claimed_files
    }
    code = READ_ALL.replace("sys.argv[1:]", repr([str(p) for p in claimed_files]))
    result, _ = run_with("dup_extension_sniff", code)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout.splitlines()[-1]) == expected
    assert "evil-ts" not in result.stderr
    assert set(expected) == set(CLAIMED)


def test_a_plugin_format_is_used_when_asked(claimed_files: list[Path]) -> None:
    code = (
        "from geobrep.host import registries; f = registries().formats; "
        f"print(f.choose_reader({str(claimed_files[1])!r}).name, "
        f"f.choose_reader({str(claimed_files[0])!r}, format='evil-ts').name)"
    )
    preferred, _ = run_with("dup_extension_sniff", code, GEOBREP_PREFER_FORMATS="other, evil-ts")
    assert preferred.returncode == 0, preferred.stderr
    assert preferred.stdout.split() == ["evil-ts", "evil-ts"]
    plain, _ = run_with("dup_extension_sniff", code)
    assert plain.stdout.split() == ["native", "evil-ts"]


def test_break_tie_prefers_the_configured_then_the_builtin(monkeypatch: pytest.MonkeyPatch) -> None:
    own = FormatSpec(name="own", extensions=(".x",), reader=print, builtin=True)
    first = FormatSpec(name="first", extensions=(".x",), reader=print, plugin="a")
    second = FormatSpec(name="second", extensions=(".x",), reader=print, plugin="b")
    assert break_tie([first, own, second]) == [own]
    assert break_tie([first, second]) == [first, second]  # still ambiguous
    monkeypatch.setenv("GEOBREP_PREFER_FORMATS", "second,first")
    assert break_tie([first, own, second]) == [second]
    assert FormatRegistry([first, own]).choose_reader("a.x").name == "first"
    monkeypatch.delenv("GEOBREP_PREFER_FORMATS")
    assert FormatRegistry([first, own]).choose_reader("a.x").name == "own"


def test_a_plugin_cannot_mark_its_own_items_builtin() -> None:
    class Impostor:
        @geobrep.plugins.hookimpl
        def geobrep_register_formats(self, registry: FormatRegistry) -> None:
            registry.add(FormatSpec(name="impostor", reader=print, builtin=True))

    host = PluginHost()
    assert host.register(Impostor(), "impostor").status == "loaded"
    assert host.registries.formats.get("impostor").builtin is False


# --- plugins that hang or raise at import -------------------------------------------------------


def test_a_plugin_hanging_at_import_is_reported_and_skipped() -> None:
    result, seconds = cli("import_hangs", "plugins", "--json", GEOBREP_PLUGIN_TIMEOUT="1")
    assert result.returncode == 0, result.stderr
    infos = {info["name"]: info for info in json.loads(result.stdout)}
    assert infos["import_hangs"]["status"] == "failed"
    assert infos["import_hangs"]["error"].startswith("PluginTimeoutError: the import of")
    assert infos["gocad"]["status"] == "loaded"
    assert infos["gocad"]["builtin"]
    assert "within 1 s (the limit is GEOBREP_PLUGIN_TIMEOUT" in result.stderr
    assert seconds < GUARD / 2  # finished: it did not wait for the hour-long import


def test_a_plugin_hanging_at_import_does_not_stop_reads() -> None:
    result, _ = cli("import_hangs", "info", str(TRIANGLES), GEOBREP_PLUGIN_TIMEOUT="1")
    assert result.returncode == 0, result.stderr
    assert "4 vertices, 2 faces" in result.stdout


def test_strict_mode_makes_a_hanging_import_an_error() -> None:
    result, _ = cli(
        "import_hangs", "plugins", GEOBREP_PLUGIN_TIMEOUT="1", GEOBREP_STRICT_PLUGINS="1"
    )
    assert result.returncode != 0
    assert "geobrep: error: plugin 'import_hangs'" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_base_exception_at_import_is_isolated() -> None:
    result, _ = cli("import_baseexc", "plugins", "--json")
    assert result.returncode == 0, result.stderr
    infos = {info["name"]: info for info in json.loads(result.stdout)}
    assert infos["import_baseexc"] == infos["import_baseexc"] | {
        "status": "failed",
        "error": "Weird: not an Exception subclass",
    }
    assert "Traceback" not in result.stderr
    assert "plugin 'import_baseexc'" in result.stderr
    read, _ = cli("import_baseexc", "info", str(TRIANGLES))
    assert read.returncode == 0, read.stderr
    assert "4 vertices" in read.stdout


def test_strict_mode_makes_a_base_exception_an_error_without_traceback() -> None:
    result, _ = cli("import_baseexc", "plugins", GEOBREP_STRICT_PLUGINS="1")
    assert result.returncode != 0
    assert "Weird: not an Exception subclass" in result.stderr
    assert "Traceback" not in result.stderr


# --- a sniffer that never returns ---------------------------------------------------------------


def test_a_hanging_sniffer_says_no_and_is_reported_once(tmp_path: Path) -> None:
    copies = [tmp_path / "a.dat", tmp_path / "b.dat"]  # no format claims .dat: every reader sniffs
    for copy in copies:
        copy.write_bytes(TRIANGLES.read_bytes())
    code = (
        "import time, warnings, geobrep\n"
        "warnings.simplefilter('always')\n"
        "start = time.perf_counter()\n"
        f"paths = {[str(c) for c in copies]!r}\n"
        "counts = [len(geobrep.read(p).entities[0].vertices) for p in paths]\n"
        "print(counts, round(time.perf_counter() - start, 1))\n"
    )
    result, _ = run_with("sniff_hangs", code, GEOBREP_SNIFF_TIMEOUT="1")
    assert result.returncode == 0, result.stderr
    counts, seconds = result.stdout.rsplit("]", 1)
    assert counts + "]" == "[4, 4]"
    assert 1.0 <= float(seconds) < GUARD / 2  # waited for one sniff only, not two
    assert result.stderr.count("format 'sniff-hangs' from plugin 'sniff_hangs'") == 1
    assert "did not finish within 1 s" in result.stderr


@pytest.fixture
def release() -> Iterator[threading.Event]:
    """An event that blocked plugin code waits on; set at the end so its thread ends."""
    event = threading.Event()
    yield event
    event.set()


def test_sniff_timeout_in_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, release: threading.Event
) -> None:
    monkeypatch.setenv("GEOBREP_SNIFF_TIMEOUT", "0.2")
    calls: list[bytes] = []

    def stuck(head: bytes) -> bool:
        calls.append(head)
        return release.wait(60)

    registry = FormatRegistry(
        [
            FormatSpec(name="stuck", reader=print, sniff=stuck, plugin="p"),
            FormatSpec(name="good", reader=print, sniff=lambda head: head == b"G"),
        ]
    )
    path = tmp_path / "file"
    path.write_bytes(b"G")
    with pytest.warns(GeobrepPluginWarning, match="sniffer of format 'stuck' did not finish"):
        assert registry.choose_reader(path).name == "good"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert registry.choose_reader(path).name == "good"  # not called, not reported again
    assert len(calls) == 1


def test_a_sniffer_raising_a_base_exception_is_isolated(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    class Odd(BaseException):
        pass

    def odd(head: bytes) -> bool:
        raise Odd("odd")

    registry = FormatRegistry(
        [
            FormatSpec(name="odd", reader=print, sniff=odd, plugin="p"),
            FormatSpec(name="good", reader=print, sniff=lambda head: True),
        ]
    )
    path = tmp_path / "file"
    path.write_bytes(b"G")
    with pytest.warns(GeobrepPluginWarning, match="format 'odd' from plugin 'p': sniff raised Odd"):
        assert registry.choose_reader(path).name == "good"
    monkeypatch.setenv("GEOBREP_STRICT_PLUGINS", "1")
    with pytest.raises(PluginError, match="sniff raised Odd: odd"):
        registry.choose_reader(path)


# --- the bounds themselves --------------------------------------------------------------------


def test_call_bounded_returns_raises_or_gives_up(release: threading.Event) -> None:
    assert call_bounded(lambda: 42, 5, "x") == 42
    with pytest.raises(ZeroDivisionError):
        call_bounded(lambda: 1 // 0, 5, "x")
    start = time.perf_counter()
    with pytest.raises(PluginTimeoutError, match=r"the wait did not finish within 0\.2 s"):
        call_bounded(lambda: release.wait(60), 0.2, "the wait")
    assert time.perf_counter() - start < 30


def test_timeouts_come_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("GEOBREP_PLUGIN_TIMEOUT", raising=False)
    assert plugin_timeout() == DEFAULT_PLUGIN_TIMEOUT == 10
    monkeypatch.setenv("GEOBREP_PLUGIN_TIMEOUT", "2.5")
    assert plugin_timeout() == 2.5
    for bad in ("soon", "0", "-1", "inf", "nan"):
        monkeypatch.setenv("GEOBREP_SNIFF_TIMEOUT", bad)
        with pytest.warns(GeobrepPluginWarning, match="GEOBREP_SNIFF_TIMEOUT"):
            assert sniff_timeout() == 2


def plugin_module(folder: Path, name: str, body: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Write module ``name`` and make it the only entry point discovery sees."""
    (folder / f"{name}.py").write_text(body)
    monkeypatch.syspath_prepend(str(folder))
    entry_point = EntryPoint(name=name, value=name, group=ENTRY_POINT_GROUP)
    monkeypatch.setattr(plugin_loader, "entry_points", lambda *, group: [entry_point])


def test_keyboard_interrupt_from_a_plugin_import_is_not_swallowed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugin_module(tmp_path, "gbtest_interrupts", "raise KeyboardInterrupt\n", monkeypatch)
    with pytest.raises(KeyboardInterrupt):
        PluginHost().load_entry_points()
    sys.modules.pop("gbtest_interrupts", None)


def test_a_bounded_hook_using_the_registries_fails_instead_of_waiting(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    body = (
        "from geobrep.plugins import hookimpl, registries\n"
        "@hookimpl\n"
        "def geobrep_register_formats(registry):\n"
        "    registries()\n"
    )
    plugin_module(tmp_path, "gbtest_reentrant", body, monkeypatch)
    monkeypatch.setenv("GEOBREP_PLUGIN_TIMEOUT", "30")
    start = time.perf_counter()
    with pytest.warns(GeobrepPluginWarning, match="used by a plugin hook while loading"):
        host = plugin_loader.get_host()
    assert time.perf_counter() - start < 20  # refused at once, not after the time limit
    assert host.info("gbtest_reentrant").status == "failed"
    sys.modules.pop("gbtest_reentrant", None)
