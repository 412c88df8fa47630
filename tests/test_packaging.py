"""The wheel: every package folder is declared, schemas ship, test data do not, it works."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _declared_packages() -> tuple[list[str], dict[str, str]]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    return list(config["packages"]), dict(config["package-dir"])


def test_every_package_folder_is_declared() -> None:
    packages, mapping = _declared_packages()
    found = set()
    for name, folder in mapping.items():
        for init in (ROOT / folder).rglob("__init__.py"):
            relative = init.parent.relative_to(ROOT / folder)
            found.add(".".join([name, *relative.parts]))
    # a mapped name's own sub-folders that are separately mapped count once
    missing = sorted(found ^ set(packages))
    assert found == set(packages), f"pyproject packages out of date: {missing}"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    source = tmp_path_factory.mktemp("src")
    for item in ("pyproject.toml", "README.md", "core", "plugins", "adapters", "schemas"):
        path = ROOT / item
        if path.is_dir():
            shutil.copytree(path, source / item, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy(path, source / item)
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--no-build-isolation",
            "-q",
            "-w",
            str(out),
            str(source),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    return next(out.glob("geobrep-*.whl"))


def test_wheel_contents(wheel: Path) -> None:
    names = zipfile.ZipFile(wheel).namelist()
    assert "geobrep/__init__.py" in names
    assert "geobrep/schemas/scene.schema.json" in names
    assert "geobrep/adapters/native/container.py" in names
    assert "geobrep/py.typed" in names
    assert not [n for n in names if n.startswith("tests/") or "/data/" in n]
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    text = zipfile.ZipFile(wheel).read(entry_points).decode()
    assert "[geobrep.plugins]" in text
    assert "native = geobrep.adapters.native" in text
    assert "geobrep = geobrep.cli:main" in text


def test_installed_wheel_works(wheel: Path, tmp_path: Path) -> None:
    target = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--no-deps",
            "-q",
            "--target",
            str(target),
            str(wheel),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    script = (
        "import geobrep, json, pathlib, tempfile\n"
        "assert pathlib.Path(geobrep.__file__).parent.parent == pathlib.Path(TARGET)\n"
        "scene = geobrep.datasets.faulted_layer_cake()\n"
        "path = pathlib.Path(tempfile.mkdtemp()) / 'cake.geobrep'\n"
        "geobrep.write(scene, path)\n"
        "assert geobrep.read(path) == scene\n"
        "print(json.dumps([p.name for p in geobrep.plugins.list_plugins()]))\n"
    ).replace("TARGET", repr(str(target)))
    env = {**os.environ, "PYTHONPATH": str(target)}
    result = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    assert "native" in result.stdout
