"""Every exchange format on a rebuilt model (``build_blocks`` of the sample model's surfaces)
and on a clipped one: float64 geometry bit for bit (RESQML, OMF, geoh5) or within the float32
bound (glTF, 3D Tiles), names, kinds, properties, CRS and blocks where the format holds them,
and what it cannot hold reported by the format's losses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_geoh5 import assert_geometry_names_and_data_kept

import geobrep
from geobrep.host.capabilities import SKIPPED_ON_READ, format_losses
from geobrep.model.entities import Block, Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries

pytest.importorskip("resqpy")
pytest.importorskip("omf")
pytest.importorskip("pygltflib")
pytest.importorskip("pyproj")


def _models() -> dict[str, Scene]:
    sample = geobrep.datasets.faulted_layer_cake()
    rebuilt = geobrep.build_blocks(Scene(entities=sample.surfaces, crs=sample.crs))
    centre = sample.bounds.center  # type: ignore[union-attr]
    clipped = geobrep.clip(sample, geobrep.Plane.from_point_normal(centre, (1.0, 0.3, 0.0)))
    assert isinstance(clipped, Scene)
    return {"rebuilt": rebuilt, "clipped": clipped}


MODELS = _models()


def _losses(model: Scene, path: Path) -> list[str]:
    return format_losses(model, registries().formats.choose_writer(path, None), path)


@pytest.fixture(params=sorted(MODELS))
def model(request: pytest.FixtureRequest) -> Scene:
    scene = MODELS[request.param]
    assert scene.blocks
    assert any(s.patch_labels is not None for s in scene.surfaces)
    return scene


def test_resqml_keeps_everything(model: Scene, tmp_path: Path) -> None:
    path = write(model, tmp_path / "m.epc")
    assert _losses(model, path) == []
    back = read(path)
    assert back == model  # blocks, sides, topology, patch labels, CRS, ids, float64 exactly


@pytest.mark.parametrize("name", ["omf", "geoh5"])
def test_omf_and_geoh5_keep_geometry_and_report_blocks_and_topology(
    model: Scene, name: str, tmp_path: Path
) -> None:
    path = write(model, tmp_path / f"m.{name}")
    back = read(path)
    assert_geometry_names_and_data_kept(model, back, name)  # float64 bit for bit
    lost = _losses(model, path)
    blocks = sum(isinstance(e, Block) for e in model.entities)  # the universe too
    assert f"{blocks} Block entities dropped" in " ".join(lost)
    assert any(line.startswith("topology dropped") for line in lost)
    assert any(line.startswith("patch labels of") for line in lost)
    assert not back.blocks


@pytest.mark.parametrize("suffix", [".glb", ".json"])
def test_gltf_and_tiles_within_the_float32_bound(model: Scene, suffix: str, tmp_path: Path) -> None:
    options = {"max_tile_triangles": 1} if suffix == ".json" else {}
    path = write(model, tmp_path / f"m{suffix}", **options)
    back = read(path)
    lost = _losses(model, path)
    assert any("Block entities dropped" in line for line in lost)
    assert any(line.startswith("topology dropped") for line in lost)
    assert back.crs == model.crs
    assert len(back.metadata[SKIPPED_ON_READ]) == len(
        [b for b in model.blocks if b is not model.universe and b.sides]
    )
    assert len(back.surfaces) == len(model.surfaces)
    for want, got in zip(model.surfaces, back.surfaces, strict=True):
        assert isinstance(got, Surface)
        assert (got.id, got.name, got.kind, got.patch_names) == (
            want.id,
            want.name,
            want.kind,
            want.patch_names,
        )
        assert np.array_equal(got.faces, want.faces)
        assert np.array_equal(got.patch_labels, want.patch_labels)  # type: ignore[arg-type]
        assert got.point_data == want.point_data
        assert got.cell_data == want.cell_data
        # positions relative to the model's centre, float32: half an ulp of 5 km is 0.15 mm
        assert np.abs(got.vertices - want.vertices).max() < 1e-3
