"""Round trips through every writable format: what the capability table holds comes back equal."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from formats_support import OUR_FORMATS, assert_held_equal, merged_cells, rich_scene

from geobrep.errors import FormatError
from geobrep.host.capabilities import capability_losses, restrict_scene
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries

DATA = Path(__file__).parent.parent / "data" / "gocad"
#: The GOCAD files (not SOURCES.md, nor the ``@@`` property files a group's Voxet reads).
GOCAD_FILES = sorted(
    p.name for p in DATA.glob("*") if p.suffix != ".md" and not p.name.endswith("@@")
)


@pytest.fixture(scope="module")
def scene() -> Scene:
    return rich_scene()


def _roundtrip_formats() -> list[str]:
    formats = registries().formats
    return [
        s.name
        for s in formats.writers()
        if s.can_read and s.name in OUR_FORMATS and s.name != "native"
    ] + ["native"]


def test_every_writable_format_of_ours_is_registered() -> None:
    names = set(registries().formats.names())
    assert set(OUR_FORMATS) <= names
    assert registries().formats.get("png").can_write


@pytest.mark.parametrize("name", _roundtrip_formats())
def test_roundtrip_demo_model(name: str, scene: Scene, tmp_path: Path) -> None:
    spec = registries().formats.get(name)
    binary_off = {"binary": False} if name in ("ply", "vtk", "vtp") else {}
    for options in ({}, binary_off) if binary_off else ({},):
        path = write(scene, tmp_path / f"model{spec.extensions[0]}", format=name, **options)
        back = read(path)
        assert_held_equal(scene, back, spec.capabilities)


@pytest.mark.parametrize("name", _roundtrip_formats())
def test_losses_match_what_is_dropped(name: str, scene: Scene, tmp_path: Path) -> None:
    spec = registries().formats.get(name)
    caps = spec.capabilities
    lost = capability_losses(scene, caps)
    back = read(write(scene, tmp_path / f"m{spec.extensions[0]}", format=name))
    dropped_types = {e.type for e in scene.entities} - {e.type for e in back.entities}
    for type_name in dropped_types:
        assert any(f"{type_name} entities dropped" in line for line in lost), (type_name, lost)
    if not caps.multiple_entities:
        held = [e for e in scene.entities if e.type in caps.entity_types]
        assert any("merged into one" in line for line in lost) == (len(held) > 1)
        assert len(back.entities) == 1
    if not caps.names:
        assert any("names of" in line for line in lost)
    if not caps.point_data:
        assert "point properties dropped: depth, gradient" in lost
    if name == "native":
        assert lost == []
        assert back == scene


def test_capability_losses_empty_when_everything_fits(scene: Scene) -> None:
    caps = registries().formats.get("vtu").capabilities
    held = restrict_scene(scene, caps).replace(topology=scene.topology.__class__())
    assert capability_losses(held, caps) == []


@pytest.mark.parametrize("file_name", GOCAD_FILES)
@pytest.mark.parametrize("name", ["vtu", "ply", "vtk", "vtp", "resqml"])
def test_roundtrip_gocad_files(file_name: str, name: str, tmp_path: Path) -> None:
    if "gocad" not in registries().formats:
        pytest.skip("the GOCAD adapter is not installed")
    source = tmp_path / file_name
    shutil.copy(DATA / file_name, source)
    for side in DATA.glob("*@@"):  # found beside the file that names them
        shutil.copy(side, tmp_path / side.name)
    scene = read(source)
    spec = registries().formats.get(name)
    back = read(write(scene, tmp_path / f"out{spec.extensions[0]}", format=name))
    assert_held_equal(scene, back, spec.capabilities)


def test_obj_stl_off_keep_surface_cells_exactly(scene: Scene, tmp_path: Path) -> None:
    surfaces = merged_cells(scene.surfaces)["Surface"]
    for name in ("obj", "stl", "off"):
        back = read(write(scene, tmp_path / f"m.{name}"))
        assert np.array_equal(merged_cells(back.surfaces)["Surface"], surfaces), name
        # UTM coordinates survive to the last bit (no float32 anywhere)
        assert back.surfaces[0].vertices.dtype == np.float64


def test_surface_formats_refuse_a_scene_without_surfaces(scene: Scene, tmp_path: Path) -> None:
    wells = Scene(entities=[scene["well tops"]])
    with pytest.raises(FormatError, match="surfaces"):
        write(wells, tmp_path / "w.stl")
    assert not (tmp_path / "w.stl").exists()
    assert list(tmp_path.iterdir()) == []  # nothing half-written


@pytest.mark.parametrize("extension", [".ply", ".vtp"])
def test_face_index_beyond_the_points_of_a_geobrep_file_is_a_format_error(
    extension: str, tmp_path: Path
) -> None:
    from geobrep.model.entities import Surface

    surface = Surface(vertices=np.eye(3), faces=[[0, 1, 2]], name="one", cell_data={"z": [7]})
    path = write(Scene(entities=[surface]), tmp_path / f"one{extension}")
    if extension == ".ply":  # the binary face record ends with its 3 int32 indices and z
        data = bytearray(path.read_bytes())
        data[-8:-4] = np.int32(9).tobytes()
        path.write_bytes(bytes(data))
    else:
        pv = pytest.importorskip("pyvista")
        mesh = pv.read(path)
        mesh.faces = np.array([3, 0, 1, 9])
        mesh.save(path)
    with pytest.raises(FormatError, match="refers to vertex 9") as caught:
        read(path)
    assert caught.value.path == path
