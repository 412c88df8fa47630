"""Fixtures for the plugin-system tests: a clean global host, fake entry points, the example."""

from __future__ import annotations

import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

from geobrep.host import loader as plugin_loader
from geobrep.host.loader import DISABLE_ENV, ENTRY_POINT_GROUP, STRICT_ENV

FAKE_PLUGINS = Path(__file__).parent / "fake_plugins"
REPO = Path(__file__).resolve().parents[2]
EXAMPLE_PLUGIN = REPO / "docs" / "examples" / "geobrep-example-plugin"

SetEntryPoints = Callable[..., list[EntryPoint]]


def _forget_modules(prefix: str) -> None:
    for name in [m for m in sys.modules if m == prefix or m.startswith(prefix + ".")]:
        del sys.modules[name]


@pytest.fixture(autouse=True)
def clean_plugin_state(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Each test starts with no host and no plugin env vars; the previous host comes back."""
    monkeypatch.delenv(STRICT_ENV, raising=False)
    monkeypatch.delenv(DISABLE_ENV, raising=False)
    previous = plugin_loader.set_host(None)
    yield
    plugin_loader.set_host(previous)


@pytest.fixture
def fake_entry_points(monkeypatch: pytest.MonkeyPatch) -> Iterator[SetEntryPoints]:
    """Call with ``name=module`` pairs; discovery then sees exactly those entry points."""
    monkeypatch.syspath_prepend(str(FAKE_PLUGINS))

    def install(**plugins: str) -> list[EntryPoint]:
        eps = [
            EntryPoint(name=name, value=module, group=ENTRY_POINT_GROUP)
            for name, module in plugins.items()
        ]

        def entry_points(*, group: str) -> list[EntryPoint]:
            assert group == ENTRY_POINT_GROUP
            return list(eps)

        monkeypatch.setattr(plugin_loader, "entry_points", entry_points)
        return eps

    yield install
    for name in [m for m in sys.modules if m.startswith("geobrep_fake_")]:
        del sys.modules[name]


@pytest.fixture(scope="session")
def example_plugin_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example plugin installed with pip into a private target folder (once per session)."""
    base = tmp_path_factory.mktemp("example-plugin")
    source = base / "source"
    shutil.copytree(
        EXAMPLE_PLUGIN,
        source,
        ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"),
    )
    target = base / "site"
    command = [
        sys.executable,
        "-m",
        "pip",
        "install",
        "--quiet",
        "--no-deps",
        "--no-build-isolation",
        "--disable-pip-version-check",
        "--target",
        str(target),
        str(source),
    ]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    assert result.returncode == 0, f"pip install failed:\n{result.stdout}\n{result.stderr}"
    return target


@pytest.fixture
def example_plugin(example_plugin_dir: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """The installed example plugin on ``sys.path`` for one test, then gone again."""
    monkeypatch.syspath_prepend(str(example_plugin_dir))
    yield example_plugin_dir
    _forget_modules("geobrep_example_plugin")
