"""Start-up of the command line (issue 17): a command loads only what it uses.

``geobrep --help`` lists every command from the declarations (:mod:`geobrep.cli.commands`)
without pydantic, numpy, the entity models or a plugin; ``geobrep info FILE.ts`` reads the file
without the block builder, pyproj, scipy, the pipeline step models or another command's module.
Each probe runs in a fresh interpreter and prints the modules it loaded.
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from geobrep import Scene, read
from geobrep.batch.operations import builtin_operations
from geobrep.cli.commands import COMMANDS, Command
from geobrep.cli.main import build_parser, main
from geobrep.host._declared import BUILTIN_PLUGINS
from geobrep.host.loader import set_host
from geobrep.plugins import OperationRegistry, OperationSpec, hookimpl, register

TSURF = Path(__file__).parents[1] / "data" / "gocad" / "2triangles.ts"

PROBE = """
import contextlib, io, json, sys
from geobrep.cli import main
with contextlib.redirect_stdout(io.StringIO()) as out:
    code = main(sys.argv[1:])

def models():  # the pydantic models whose validators were built (schemas are deferred)
    if "pydantic" not in sys.modules:
        return []
    from pydantic import BaseModel
    seen, todo = set(), [BaseModel]
    while todo:
        for sub in todo.pop().__subclasses__():
            if sub not in seen:
                seen.add(sub)
                todo.append(sub)
    return sorted(f"{c.__module__}.{c.__qualname__}" for c in seen if c.__pydantic_complete__)

found = {"code": code, "out": out.getvalue(), "modules": sorted(sys.modules), "built": models()}
print(json.dumps(found))
"""

#: What listing the commands must not load: the models, numpy, the plugins and their host, and
#: importlib.metadata with the email package (~25 ms: geobrep's entry points are found by
#: geobrep.host._entry_points).
NOT_FOR_HELP = (
    "importlib.metadata",
    "email",
    "difflib",  # for a mistyped word only
    "traceback",  # for GEOBREP_TRACEBACK only
    "pydantic",
    "numpy",
    "pyproj",
    "geobrep.model",
    "geobrep.host.loader",
    "geobrep.host.registry",
    "geobrep.batch.pipeline",
    "geobrep.batch.operations",
    "geobrep.plugins",
    "geobrep.adapters",
)

#: What describing a TSurf must not load: kernels, reprojection, other commands, step models,
#: any plugin but GOCAD's (geobrep's own are declared and imported on first use), meshio, the
#: models of entity types the file does not hold.
NOT_FOR_INFO = (
    "difflib",
    "traceback",
    "email.parser",  # a METADATA file parsed whole
    "scipy",
    "pyproj",
    "meshio",
    "geobrep.gis.crs_ops",
    *(module for name, (module, _) in BUILTIN_PLUGINS.items() if name != "gocad"),
    "geobrep.adapters.gocad._model3d",
    "geobrep.adapters.gocad._model_records",
    "geobrep.model.arcs",
    "geobrep.adapters.gocad._voxet",
    "geobrep.adapters.gocad._sgrid",
    "geobrep.adapters.gocad._well",
    "geobrep.batch.pipeline",
    "geobrep.batch.operations",
    "geobrep.cli.operation",
    *(f"geobrep.cli.{c.module}" for c in COMMANDS if c.module != "info"),
    *(
        f"geobrep.model.entities.{module}"
        for module in (
            *("annotation", "grid", "nurbs", "octree"),
            *("polygon", "structured", "tetmesh", "well"),
        )
    ),
)


#: Models whose validators describing a TSurf must not build (their schemas are deferred).
NOT_BUILT_FOR_INFO = (
    "geobrep.adapters.native._container.NativeDocument",
    "geobrep.plugins.fit.options.",
    "geobrep.batch.",
)


def probe(*args: str) -> dict[str, object]:
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *args], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    found: dict[str, object] = json.loads(done.stdout.splitlines()[-1])
    return found


def loaded(modules: object, unwanted: tuple[str, ...]) -> list[str]:
    assert isinstance(modules, list)
    return [m for m in modules if m in unwanted or m.startswith(tuple(f"{u}." for u in unwanted))]


def test_help_lists_every_command_without_loading_models_or_plugins() -> None:
    found = probe("--help")
    assert found["code"] == 0
    assert not loaded(found["modules"], NOT_FOR_HELP)
    text = str(found["out"])
    for command in COMMANDS:
        assert command.name in text
        assert " ".join(command.help.split()[:3]) in " ".join(text.split())


def test_info_of_a_tsurf_loads_only_what_it_needs() -> None:
    found = probe("info", str(TSURF))
    assert found["code"] == 0
    assert "2 faces" in str(found["out"])
    assert "local (engineering) CRS 'Default'" in str(found["out"])
    modules = found["modules"]
    assert not loaded(modules, NOT_FOR_INFO)
    assert "geobrep.adapters.gocad._reader" in modules  # it did read through GOCAD
    # The models' validators are built on first use: none of the entity models (the reader
    # makes the Surface's fields in their validated form and runs its cross-field checks
    # itself; the scene's union of entity types does not build each type's own), and none
    # of the models of formats and operations the command does not use.
    built = found["built"]
    assert isinstance(built, list)
    entities = {name.rsplit(".", 1)[1] for name in built if ".model.entities." in name}
    assert entities == set()
    assert not [name for name in built if name.startswith(NOT_BUILT_FOR_INFO)]


def test_info_of_a_vtu_reads_it_without_meshio(tmp_path: Path) -> None:
    """geobrep reads a one-piece VTU itself: meshio (~50 ms to import) is not loaded."""
    import meshio

    path = tmp_path / "three.vtu"
    triangle = [("triangle", np.array([[0, 1, 2]]))]
    meshio.write(path, meshio.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), triangle))
    found = probe("info", str(path))
    assert found["code"] == 0
    assert "3 vertices, 1 faces" in str(found["out"])
    modules = found["modules"]
    assert "geobrep.adapters.meshio._vtu_reader" in modules
    assert not loaded(modules, ("meshio", "numpy.ma", "scipy", "pyproj"))


def test_lazy_help_is_the_help_of_the_whole_parser(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    assert capsys.readouterr().out == build_parser().format_help()


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.name)
def test_each_declaration_matches_its_module(command: Command) -> None:
    module = importlib.import_module(f"geobrep.cli.{command.module}")
    if command.operation is None:
        assert hasattr(module, "add_parser")
        return
    assert command.operation == module.OPERATION
    spec = {s.name: s for s in builtin_operations()}[command.operation]
    assert (spec.command_name, spec.summary) == (command.name, command.help)


def test_the_chosen_command_alone_is_built(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["info", "--help"])
    out = capsys.readouterr().out
    assert code == 0
    assert out.startswith("usage: geobrep info ")
    assert "--json" in out
    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    assert list(commands) == [c.name for c in COMMANDS]


class _Shift(BaseModel):
    model_config = ConfigDict(extra="forbid")
    dz: float = 0.0
    """how far to move the model up"""


def _shift(scene: Scene, options: _Shift) -> Scene:
    up = np.array([0.0, 0.0, options.dz])
    moved = [s.model_copy(update={"vertices": s.vertices + up}) for s in scene.surfaces]
    return Scene(entities=moved, crs=scene.crs, name=scene.name)


class _ShiftPlugin:
    @hookimpl
    def geobrep_register_operations(self, registry: OperationRegistry) -> None:
        registry.add(
            OperationSpec(name="shift", summary="move a model up", options=_Shift, function=_shift)
        )


def test_a_plugin_operation_is_a_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    previous = set_host(None)
    try:
        register(_ShiftPlugin(), "shift-plugin")
        assert main(["--help"]) == 0
        assert "shift        move a model up" in capsys.readouterr().out
        out = tmp_path / "up.ts"
        assert main(["shift", str(TSURF), str(out), "--dz", "10"]) == 0
        assert "(shift)" in capsys.readouterr().out
        before, after = read(TSURF).surfaces[0], read(out).surfaces[0]
        np.testing.assert_allclose(after.vertices[:, 2], before.vertices[:, 2] + 10.0)
    finally:
        set_host(previous)


def test_the_heap_is_frozen_at_exit_after_a_command(tmp_path: Path) -> None:
    """The interpreter's last garbage collection is skipped (gc.freeze at exit), the output is
    whole, the written file complete, and exit handlers registered before and after still run."""
    out = tmp_path / "copy.vtu"
    code = (
        "import atexit, gc, sys\n"
        "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0))\n"
        "from geobrep.cli import main\n"
        "code = main(sys.argv[1:])\n"
        "atexit.register(lambda: print('later handler ran'))\n"
        "sys.exit(code)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, "convert", str(TSURF), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-2:] == ["later handler ran", "frozen True"]
    assert read(out).surfaces[0].n_faces == 2


def test_info_scans_the_installed_entry_points_once() -> None:
    """The host, loaded before the parser for a command that uses it, tells whether plugins
    add commands: the entry points are not scanned a second time for that question."""
    code = (
        "import contextlib, io, json, sys\n"
        "import geobrep.host._entry_points as metadata\n"
        "groups = []\n"
        "scan = metadata.entry_points\n"
        "def counted(**params):\n"
        "    groups.append(params.get('group'))\n"
        "    return scan(**params)\n"
        "metadata.entry_points = counted\n"
        "from geobrep.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        "    code = main(sys.argv[1:])\n"
        "print(json.dumps([code, out.getvalue(), groups]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, "info", str(TSURF)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    status, out, groups = json.loads(done.stdout.splitlines()[-1])
    assert status == 0
    assert "2 faces" in out
    assert groups.count("geobrep.plugins") == 1


def test_the_format_registry_builds_no_schema_when_imported() -> None:
    """Importing the registry builds no model's validator, so pydantic's plugin loader (and
    importlib.metadata with it) waits for the first model a command really uses."""
    code = (
        "import json, sys; import geobrep.host.registry as r; "
        "spec = r.FormatSpec.__pydantic_complete__, r.FormatCapabilities.__pydantic_complete__; "
        "print(json.dumps({'complete': spec, 'modules': sorted(sys.modules)}))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout.splitlines()[-1])
    assert found["complete"] == [False, False]
    assert not loaded(found["modules"], ("pydantic.plugin._loader", "importlib.metadata"))
    # The default capabilities made without validation equal validated ones.
    from geobrep.host.registry import FormatCapabilities, FormatSpec

    default = FormatSpec(name="probe-format", reader=lambda path, options: Scene()).capabilities
    assert default == FormatCapabilities()
    assert hash(default) == hash(FormatCapabilities())
    assert repr(default) == repr(FormatCapabilities())
