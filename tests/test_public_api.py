"""The public API: exported names, the exception tree, and what ``import geobrep`` costs."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import errors
from geobrep.host._declared import BUILTIN_PLUGINS

# Written out so that any change to the public surface is a deliberate, reviewed edit.
EXPECTED_ALL = [
    "CRS",
    "Annotation",
    "Arc",
    "Block",
    "BoundingBox",
    "ConversionSummary",
    "Corner",
    "DegenerateGeometryError",
    "Entity",
    "EntityNotFoundError",
    "EntityValidationError",
    "FileAccessError",
    "FileReport",
    "FitReport",
    "FitResult",
    "FormatError",
    "GeobrepError",
    "Group",
    "InspectionReport",
    "LinearOctree",
    "MissingDependencyError",
    "NurbsSurface",
    "OptionsError",
    "Patch",
    "PatchSide",
    "Pipeline",
    "PipelineSummary",
    "Plane",
    "PluginError",
    "PointSet",
    "PolyLine",
    "Polygon",
    "Property",
    "RegularGrid",
    "RepairReport",
    "Scene",
    "StructuredGrid",
    "Surface",
    "TetMesh",
    "Topology",
    "TopologyError",
    "UnknownFormatError",
    "VoxelizationWarning",
    "Well",
    "WellLog",
    "WellMarker",
    "WellZone",
    "__version__",
    "build_blocks",
    "clip",
    "clip_box",
    "convert",
    "datasets",
    "fit",
    "from_geodataframe",
    "inspect",
    "map_products",
    "plugins",
    "read",
    "repair",
    "run_pipeline",
    "section",
    "to_geodataframe",
    "voxelize",
    "write",
]


def isort_key(name: str) -> tuple[int, str]:
    """ruff's RUF022 order: SCREAMING_CASE, then CamelCase, then everything else."""
    if name.isupper() and len(name) > 1:
        return 0, name
    if name[:1].isupper():
        return 1, name
    return 2, name


def test_all_is_exactly_the_expected_list() -> None:
    assert geobrep.__all__ == EXPECTED_ALL
    assert len(set(geobrep.__all__)) == len(geobrep.__all__)
    assert sorted(geobrep.__all__, key=isort_key) == geobrep.__all__


@pytest.mark.parametrize("name", EXPECTED_ALL)
def test_every_name_resolves(name: str) -> None:
    assert getattr(geobrep, name) is not None


def test_lazy_submodules() -> None:
    import geobrep.datasets
    import geobrep.plugins

    assert geobrep.datasets.faulted_layer_cake is not None
    assert callable(geobrep.plugins.list_plugins)
    assert {"datasets", "plugins"} <= set(dir(geobrep))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        geobrep.nothing  # noqa: B018


def test_version() -> None:
    from importlib.metadata import version

    assert geobrep.__version__ == version("geobrep")


# ----------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    ("error", "builtin"),
    [
        (errors.EntityValidationError, ValueError),
        (errors.TopologyError, ValueError),
        (errors.DegenerateGeometryError, ValueError),
        (errors.OptionsError, ValueError),
        (errors.FormatError, ValueError),
        (errors.UnknownFormatError, ValueError),
        (errors.EntityNotFoundError, KeyError),
        (errors.FileAccessError, OSError),
        (errors.PluginError, RuntimeError),
        (errors.MissingDependencyError, ImportError),
    ],
)
def test_error_tree(error: type[Exception], builtin: type[Exception]) -> None:
    assert issubclass(error, errors.GeobrepError)
    assert issubclass(error, builtin)
    assert getattr(geobrep, error.__name__) is error


def test_every_error_is_exported_and_in_the_tree() -> None:
    exported = {
        name
        for name in errors.__all__
        if isinstance(getattr(errors, name), type) and issubclass(getattr(errors, name), Exception)
    }
    assert exported <= set(geobrep.__all__)
    for name in exported:
        if name != "GeobrepError":
            assert name in (errors.__doc__ or ""), f"{name} missing from the drawn tree"
    assert issubclass(errors.UnknownFormatError, errors.FormatError)


def test_error_messages() -> None:
    validation = errors.EntityValidationError("Surface 'top'", "faces", "bad")
    assert str(validation) == "Surface 'top': faces: bad"
    assert (validation.entity, validation.field, validation.reason) == (
        "Surface 'top'",
        "faces",
        "bad",
    )
    fmt = errors.FormatError("TRGL refers to vertex 98", "model.ts", line=1234)
    assert str(fmt) == "model.ts:1234: TRGL refers to vertex 98"
    assert fmt.line == 1234
    assert str(errors.FormatError("broken", "model.ts")) == "model.ts: broken"
    assert str(errors.FormatError("broken")) == "broken"
    access = errors.FileAccessError("no such file", "a/b.geobrep")
    assert str(access) == "a/b.geobrep: no such file"
    # KeyError would quote its message: this one reads like the others
    assert str(errors.EntityNotFoundError("no entity named 'x'")) == "no entity named 'x'"
    missing = errors.MissingDependencyError("open3d", "open3d", "Poisson reconstruction")
    assert str(missing) == (
        "Poisson reconstruction needs the optional package 'open3d': pip install 'geobrep[open3d]'"
    )
    assert (missing.package, missing.extra) == ("open3d", "open3d")


# ----------------------------------------------------------------------------- import cost
IMPORT_PROBE = """
import json, sys, time
start = time.perf_counter()
import geobrep
elapsed = time.perf_counter() - start
heavy = ["open3d", "pyvista", "vtk", "vtkmodules", "trimesh", "scipy", "scipy.spatial", "rtree",
         "meshio", "matplotlib", "numpy", "pydantic", "pluggy", "importlib.metadata",
         "geobrep.host.loader", "geobrep.model", "geobrep.plugins", "geobrep.adapters"]
print(json.dumps({"seconds": elapsed, "loaded": [m for m in heavy if m in sys.modules]}))
"""


def test_import_is_light(record_property: Callable[[str, object], None]) -> None:
    result = subprocess.run(
        [sys.executable, "-c", IMPORT_PROBE],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    report = json.loads(result.stdout)
    loaded = set(report["loaded"])
    assert not loaded, loaded  # no library, no model, no plugin: each is imported on first use
    record_property("import_seconds", report["seconds"])
    print(f"\nimport geobrep: {report['seconds'] * 1000:.0f} ms; also loaded: {sorted(loaded)}")


READ_PROBE = """
import json, sys, warnings
warnings.simplefilter("ignore")
import geobrep
geobrep.read(sys.argv[1])
print(json.dumps(sorted(sys.modules)))
"""

#: What reading a small TSurf must not import: any plugin but GOCAD's (the others are declared,
#: geobrep.host._declared, and imported on first use), meshio, scipy and pyproj (no merge, no
#: graph, no reprojection), nor the GOCAD readers of other object types (Model3d, grids, wells)
#: or the GOCAD writer, nor the records of a Model3d header or TSolid MODEL section (their
#: dataclasses) or the rebuilding of corners and arcs, nor the models of entities a TSurf does
#: not hold (grids, wells, tetrahedral meshes, NURBS, octrees, polygons, annotations).
NOT_FOR_A_TSURF = (
    "scipy",
    "pyproj",
    "meshio",
    "geobrep.plugins.blocks",
    "geobrep.plugins.checks",
    "geobrep.plugins.clip",
    "geobrep.plugins.fit",
    "geobrep.plugins.voxelize",
    *(module for name, (module, _) in BUILTIN_PLUGINS.items() if name != "gocad"),
    "geobrep.adapters.gocad._model3d",
    "geobrep.adapters.gocad._model_records",
    "geobrep.model.arcs",
    "geobrep.adapters.gocad._voxet",
    "geobrep.adapters.gocad._sgrid",
    "geobrep.adapters.gocad._well",
    "geobrep.adapters.gocad._writer",
    "geobrep.gis.crs_ops",
    *(
        f"geobrep.model.entities.{module}"
        for module in (
            *("annotation", "grid", "nurbs", "octree"),
            *("polygon", "structured", "tetmesh", "well"),
        )
    ),
)


def _loaded_after_reading(name: str) -> list[str]:
    """The modules of a fresh interpreter that imported geobrep and read ``data/gocad/name``."""
    result = subprocess.run(
        [sys.executable, "-c", READ_PROBE, str(Path(__file__).parent / "data/gocad" / name)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    loaded: list[str] = json.loads(result.stdout.splitlines()[-1])
    return loaded


def _among(loaded: list[str], modules: tuple[str, ...]) -> list[str]:
    below = tuple(f"{name}." for name in modules)
    return [m for m in loaded if m.startswith(below) or m in modules]


def test_reading_a_tsurf_imports_only_what_it_needs() -> None:
    loaded = _loaded_after_reading("2triangles.ts")
    unneeded = _among(loaded, NOT_FOR_A_TSURF)
    assert not unneeded, unneeded
    assert "geobrep.adapters.gocad._reader" in loaded  # the probe did read through GOCAD


#: What reading a Model3d must not import: the plugins (its blocks are built from its regions by
#: the model, not by the blocks plugin), the other GOCAD readers and the writer, scipy, pyproj,
#: meshio, and the command line's modules (argparse: the operation registry builds parsers only
#: for the command line). It loads its own, _MODEL3D_ONLY.
_MODEL3D_ONLY = (
    "geobrep.adapters.gocad._model3d",
    "geobrep.adapters.gocad._model_records",
    "geobrep.model.arcs",
)
NOT_FOR_A_MODEL3D = (
    *(name for name in NOT_FOR_A_TSURF if name not in _MODEL3D_ONLY),
    "geobrep.cli",
    "geobrep.batch",
    "argparse",
)


def test_reading_a_model3d_imports_only_what_it_needs() -> None:
    loaded = _loaded_after_reading("modelA1.ml")
    unneeded = _among(loaded, NOT_FOR_A_MODEL3D)
    assert not unneeded, unneeded
    assert "geobrep.adapters.gocad._model3d" in loaded  # the probe did read a Model3d


def test_validating_a_million_triangles(record_property: Callable[[str, object], None]) -> None:
    nx, ny = 1001, 501
    x, y = np.meshgrid(np.linspace(0.0, 5000.0, nx), np.linspace(0.0, 2500.0, ny))
    vertices = np.column_stack([x.ravel() + 450_000.0, y.ravel() + 6_700_000.0, np.zeros(x.size)])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    a = (j * nx + i).ravel()
    faces = np.concatenate(
        [np.stack([a, a + 1, a + nx + 1], axis=1), np.stack([a, a + nx + 1, a + nx], axis=1)]
    )
    start = time.perf_counter()
    surface = geobrep.Surface(vertices=vertices, faces=faces, name="big")
    elapsed = time.perf_counter() - start
    assert surface.n_faces == 1_000_000
    assert np.shares_memory(surface.vertices, vertices)
    assert np.shares_memory(surface.faces, faces)
    record_property("validate_1m_triangles_seconds", elapsed)
    print(f"\nSurface with 1M triangles validated in {elapsed * 1000:.0f} ms")
