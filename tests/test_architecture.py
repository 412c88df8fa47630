"""The package map of docs/architecture.md, enforced: who may import whom, and what is cheap.

* Core packages form layers; a module imports its own package and lower layers only. Imports
  under ``if TYPE_CHECKING:`` are annotations and do not count; the few lazy imports that go
  upward (inside a function) are listed in ``UPWARD`` with their reason.
* No core module imports ``geobrep.plugins`` (core owns its registries: ``geobrep.host``).
* Built-in plugins import geobrep only through ``geobrep`` (the model and operations),
  ``geobrep.plugins`` (the plugin-author surface), ``geobrep.geometry`` and ``geobrep.errors``.
* ``import geobrep.plugins`` and ``import geobrep.hookspecs`` load neither numpy nor the models.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CORE = ROOT / "core"

#: Core layers, lowest first: a package may import its own and any lower layer.
LAYERS = [
    "errors",
    "geometry",
    "model",
    "host",
    "ops",
    "gis",
    "batch",
    "datasets",
    "demo",
    "cli",
]
#: Where the two top-level modules sit.
LAYER_OF_MODULE = {"hookspecs": "host", "errors": "errors", "demo": "demo"}
#: Lazy (function-level) imports that go upward, with why.
UPWARD = {
    ("model/crs.py", "gis"): "a CRS given as WKT/PROJ/pyproj object is parsed by pyproj on demand",
    ("model/scene.py", "gis"): "Scene.to_crs, a convenience for geobrep.gis.crs_ops.to_crs",
    ("ops/fitting.py", "datasets"): "the fit demo stage fits the built-in survey points",
}
#: What built-in plugins may import from geobrep.
PLUGIN_SURFACE = ("geobrep", "geobrep.plugins", "geobrep.geometry", "geobrep.errors")


def _imports(tree: ast.Module) -> list[tuple[str, str, int]]:
    """``(module, context, line)``: context ``module``, ``function`` or ``typing``."""
    found: list[tuple[str, str, int]] = []

    def visit(node: ast.AST, context: str) -> None:
        for child in ast.iter_child_nodes(node):
            here = context
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                for inner in child.body:
                    visit_one(inner, "typing")
                for inner in child.orelse:
                    visit_one(inner, context)
                continue
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                here = "function" if context != "typing" else context
            visit_one(child, here)

    def visit_one(child: ast.AST, context: str) -> None:
        if isinstance(child, ast.ImportFrom) and child.module and child.level == 0:
            if child.module == "geobrep":
                found.extend((f"geobrep.{a.name}", context, child.lineno) for a in child.names)
            else:
                found.append((child.module, context, child.lineno))
        elif isinstance(child, ast.Import):
            found.extend((a.name, context, child.lineno) for a in child.names)
        visit(child, context if not isinstance(child, ast.FunctionDef) else "function")

    visit(tree, "module")
    return [f for f in found if f[0] == "geobrep" or f[0].startswith("geobrep.")]


def _layer(package: str) -> str | None:
    return LAYER_OF_MODULE.get(package, package if package in LAYERS else None)


def _core_modules() -> list[Path]:
    return sorted(p for p in CORE.rglob("*.py") if p.name != "__main__.py")


@pytest.mark.parametrize("path", _core_modules(), ids=lambda p: str(p.relative_to(CORE)))
def test_core_imports_follow_the_layers(path: Path) -> None:
    relative = path.relative_to(CORE)
    if relative.as_posix() == "__init__.py":
        pytest.skip("the facade re-exports every layer")
    own = relative.parts[0].removesuffix(".py")
    own_layer = _layer(own)
    assert own_layer is not None, f"{relative}: not in any layer of docs/architecture.md"
    wrong = []
    for module, context, line in _imports(ast.parse(path.read_text(encoding="utf-8"))):
        parts = module.split(".")
        if len(parts) == 1 or context == "typing":
            continue
        target = parts[1]
        if target in ("plugins", "adapters"):
            wrong.append(f"line {line}: core imports {module} (core owns its registries)")
            continue
        target_layer = _layer(target)
        if target_layer is None:  # __version__ and the like, from the facade
            continue
        if LAYERS.index(target_layer) <= LAYERS.index(own_layer):
            continue
        if context == "function" and (relative.as_posix(), target) in UPWARD:
            continue
        wrong.append(f"line {line}: {own_layer} imports {module} ({context} level)")
    assert not wrong, f"{relative}: " + "; ".join(wrong)


def test_every_upward_exception_is_still_used() -> None:
    used = set()
    for path in _core_modules():
        relative = path.relative_to(CORE).as_posix()
        for module, context, _ in _imports(ast.parse(path.read_text(encoding="utf-8"))):
            parts = module.split(".")
            if context == "function" and len(parts) > 1:
                used.add((relative, parts[1]))
    assert set(UPWARD) <= used


@pytest.mark.parametrize(
    "path", sorted((ROOT / "plugins").rglob("*.py")), ids=lambda p: str(p.relative_to(ROOT))
)
def test_built_in_plugins_use_only_the_plugin_surface(path: Path) -> None:
    if path == ROOT / "plugins" / "__init__.py":
        pytest.skip("the surface itself")
    wrong = []
    for module, _, line in _imports(ast.parse(path.read_text(encoding="utf-8"))):
        if module.startswith("geobrep.plugins.") or module == "geobrep.plugins":
            continue
        if module in PLUGIN_SURFACE or module.startswith("geobrep.geometry."):
            continue
        if module.startswith("geobrep.") and module.split(".")[1] in {"plugins"}:
            continue
        if module.count(".") == 1 and module.split(".")[1][0].isupper():
            continue  # `from geobrep import Surface`
        if module.count(".") == 1 and module.split(".")[1] in {"datasets"}:
            continue
        wrong.append(f"line {line}: {module}")
    assert not wrong, f"{path.relative_to(ROOT)} reaches past the plugin surface: {wrong}"


@pytest.mark.parametrize("module", ["geobrep.plugins", "geobrep.hookspecs"])
def test_importing_the_plugin_surface_is_cheap(module: str) -> None:
    result = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", f"import {module}"],
        capture_output=True,
        text=True,
        check=True,
    )
    loaded = [line.rsplit("|", 1)[-1].strip() for line in result.stderr.splitlines()]
    assert "numpy" not in loaded
    assert not [m for m in loaded if m.startswith("geobrep.model")]
    assert module in loaded


def test_the_plugin_surface_exports_what_plugins_need() -> None:
    import geobrep.plugins as surface

    for name in surface.__all__:
        assert getattr(surface, name) is not None, name
    needed = {
        "hookimpl",
        "ClipContext",
        "SceneDraft",
        "halves",
        "pack_halves",
        "FitResult",
        "FitReport",
        "atomic_write",
        "VoxelizerSpec",
        "FormatError",
    }
    assert needed <= set(surface.__all__)


@pytest.mark.parametrize("path", _core_modules(), ids=lambda p: str(p.relative_to(CORE)))
def test_core_imports_no_plugin_or_adapter_by_name(path: Path) -> None:
    """Not even through ``importlib.import_module("geobrep.adapters...")``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    calls = [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and ast.unparse(node.func).endswith(("import_module", "__import__"))
        and node.args
        and isinstance(node.args[0], ast.Constant)
        and str(node.args[0].value).startswith(("geobrep.adapters", "geobrep.plugins."))
    ]
    assert not calls, f"{path.relative_to(CORE)} imports {ast.unparse(calls[0].args[0])}"


def _private_imports(path: Path) -> list[tuple[str, str, int]]:
    """``(private module, name, line)`` for each ``from geobrep...._x import name`` in a file."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        module = node.module if isinstance(node, ast.ImportFrom) else None
        if module and module.startswith("geobrep.") and "._" in module:
            found.extend((module, alias.name, node.lineno) for alias in node.names)
    return found


def _public_home(private_module: str) -> str:
    """The public package above a private module: ``geobrep.plugins.clip`` for ``..clip._lines``."""
    parts = private_module.split(".")
    first_private = next(i for i, part in enumerate(parts) if part.startswith("_"))
    return ".".join(parts[:first_private])


_TEST_FILES = sorted(p for p in (ROOT / "tests").rglob("*.py") if "data" not in p.parts)


@pytest.mark.parametrize("path", _TEST_FILES, ids=lambda p: str(p.relative_to(ROOT / "tests")))
def test_tests_use_the_public_api_where_one_exists(path: Path) -> None:
    """A test may reach into an implementation module only for what no public package exports."""
    import importlib

    offending = []
    for module, name, line in _private_imports(path):
        home = importlib.import_module(_public_home(module))
        if name in getattr(home, "__all__", ()):
            offending.append(f"line {line}: {name} from {module} (public in {home.__name__})")
    assert not offending, "; ".join(offending)


def _implementation_modules() -> list[Path]:
    folders = [ROOT / "plugins", ROOT / "adapters"]
    return sorted(
        p
        for folder in folders
        for p in folder.rglob("*.py")
        if p.name.startswith("_") and p.name != "__init__.py"
    )


@pytest.mark.parametrize("path", _implementation_modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_show_no_implementation_module(path: Path) -> None:
    """Every module the docs or the README show is public: no doc names a ``_module``."""
    package = "geobrep." + ".".join(path.relative_to(ROOT).with_suffix("").parts)
    texts = [
        p.read_text(encoding="utf-8") for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]
    ]
    assert not any(package in text for text in texts), f"the docs show {package}"


_PACKAGES = sorted(
    p.parent
    for folder in ("core", "plugins", "adapters")
    for p in (ROOT / folder).rglob("__init__.py")
)


@pytest.mark.parametrize("package", _PACKAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_package_name_is_shadowed_by_its_submodule(package: Path) -> None:
    """Importing ``pkg._x`` sets ``pkg._x`` to the module: a function of that name would vanish."""
    submodules = {p.stem for p in package.glob("*.py") if p.name != "__init__.py"}
    submodules |= {p.name for p in package.iterdir() if (p / "__init__.py").exists()}
    tree = ast.parse((package / "__init__.py").read_text(encoding="utf-8"))
    defined = {
        node.name
        for node in tree.body
        if isinstance(node, ast.FunctionDef | ast.ClassDef | ast.AsyncFunctionDef)
    }
    assert not defined & submodules, f"{sorted(defined & submodules)} shadowed in {package.name}"


def test_no_benchmark_script_shadows_a_standard_module() -> None:
    """A script run from benchmarks/ puts that folder first on sys.path: a file named after a
    standard module (inspect.py did) would replace it for numpy and everything else."""
    names = {path.stem for path in (ROOT / "benchmarks").glob("*.py")}
    assert not names & set(sys.stdlib_module_names)
