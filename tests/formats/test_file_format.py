"""The file-format helper the adapters share: readers without options, writers that only meet
what their format holds (geobrep.adapters._file_format)."""

from __future__ import annotations

import doctest
import warnings
from pathlib import Path

import numpy as np
import pytest
from pydantic import BaseModel

import geobrep
from geobrep.adapters import _file_format
from geobrep.adapters._file_format import file_format, full_capabilities
from geobrep.host.registry import FormatCapabilities, NoOptions
from geobrep.plugins import registries


def _mixed_scene() -> geobrep.Scene:
    """A surface, a point set and a polygon (which no mesh format holds), with a CRS."""
    surface = geobrep.Surface(
        vertices=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]],
        faces=[[0, 1, 2]],
        name="tri",
        point_data={"depth": np.array([1.0, 2.0, 3.0])},
    )
    wells = geobrep.PointSet(vertices=[[0.25, 0.25, 0.125]], name="wells")
    outline = geobrep.Polygon(
        vertices=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]], name="outline"
    )
    return geobrep.Scene(entities=[surface, wells, outline], crs="EPSG:32631", name="mixed")


def test_module_examples() -> None:
    result = doctest.testmod(_file_format, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0


def test_the_writer_meets_only_what_the_capabilities_hold(tmp_path: Path) -> None:
    seen: list[tuple[geobrep.Scene, BaseModel]] = []
    spec = file_format(
        "pts",
        "points only, no CRS",
        (".pts",),
        capabilities=FormatCapabilities(entity_types=frozenset({"PointSet"})),
        options=NoOptions,
        write=lambda scene, path, options: seen.append((scene, options)),
    )
    assert spec.writer is not None
    assert spec.reader is None
    spec.writer(_mixed_scene(), tmp_path / "a.pts", NoOptions())
    ((kept, options),) = seen
    assert [e.name for e in kept.entities] == ["wells"]
    assert kept.crs is None
    assert isinstance(options, NoOptions)


def test_the_reader_takes_no_options(tmp_path: Path) -> None:
    spec = file_format(
        "named",
        "a scene named after the file",
        (".named",),
        capabilities=full_capabilities({"PointSet"}),
        options=NoOptions,
        read=lambda path: geobrep.Scene(name=path.stem),
    )
    assert spec.reader is not None
    assert spec.reader(tmp_path / "rocks.named", NoOptions()).name == "rocks"
    assert spec.capabilities.crs
    assert spec.capabilities.point_data
    assert spec.capabilities.entity_types == frozenset({"PointSet"})


@pytest.mark.parametrize("suffix", [".ply", ".vtu", ".vtk", ".csv", ".geobrep", ".vtp"])
def test_registered_writers_keep_what_their_format_holds(tmp_path: Path, suffix: str) -> None:
    if suffix == ".vtp":
        pytest.importorskip("pyvista")
    scene = _mixed_scene()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        back = geobrep.read(geobrep.write(scene, tmp_path / f"mixed{suffix}"))
    caps = registries().formats.choose_writer(tmp_path / f"mixed{suffix}").capabilities
    expected = [e.name for e in scene.entities if e.type in caps.entity_types]
    assert sorted(e.name for e in back.entities) == sorted(expected)
    assert len(expected) < len(scene.entities) or suffix == ".geobrep"
    assert (back.crs is not None) == caps.crs
