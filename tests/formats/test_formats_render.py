"""Pictures: off-screen renders that are not blank, colouring modes, cut-away, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from geobrep.cli.main import main
from geobrep.errors import OptionsError
from geobrep.model.scene import Scene
from geobrep.ops.io import write

pytest.importorskip("pyvista")


def _pixels(path: Path) -> NDArray[np.uint8]:
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"))


def _drawn_fraction(pixels: NDArray[np.uint8]) -> float:
    """Share of pixels that differ from the white background."""
    return float((np.abs(pixels.astype(int) - 255).sum(axis=2) > 30).mean())


def test_render_is_not_blank(layer_cake: Scene, tmp_path: Path) -> None:
    path = write(layer_cake, tmp_path / "cake.png", window_size=(400, 300))
    pixels = _pixels(path)
    assert pixels.shape == (300, 400, 3)
    assert 0.15 < _drawn_fraction(pixels) < 0.95
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 50  # shaded, several colours


def test_cut_away_removes_part_of_the_picture(layer_cake: Scene, tmp_path: Path) -> None:
    points = np.concatenate([s.vertices for s in layer_cake.surfaces])
    centre = tuple(float(v) for v in (points.min(axis=0) + points.max(axis=0)) / 2)
    full = _pixels(write(layer_cake, tmp_path / "full.png", color_by="block",
                         window_size=(400, 300)))  # fmt: skip
    cut = _pixels(write(layer_cake, tmp_path / "cut.png", color_by="block",
                        window_size=(400, 300), clip_origin=centre,
                        clip_normal=(1.0, 0.0, 0.0)))  # fmt: skip
    assert _drawn_fraction(cut) > 0.05
    assert (np.abs(full.astype(int) - cut.astype(int)).sum(axis=2) > 30).mean() > 0.05


def test_colour_by_property(layer_cake: Scene, tmp_path: Path) -> None:
    h1 = layer_cake["H1"]
    coloured = h1.replace(point_data={"z": h1.vertices[:, 2]})
    scene = layer_cake.replace(
        entities=[coloured if e.id == h1.id else e for e in layer_cake.entities]
    )
    path = write(scene, tmp_path / "prop.png", color_by="property", property="z",
                 window_size=(400, 300))  # fmt: skip
    assert _drawn_fraction(_pixels(path)) > 0.1
    with pytest.raises(OptionsError, match="properties: z"):
        write(scene, tmp_path / "bad.png", color_by="property", property="porosity")
    assert not (tmp_path / "bad.png").exists()
    with pytest.raises(OptionsError, match="needs property"):
        write(scene, tmp_path / "bad.png", color_by="property")


def test_cli_render(layer_cake: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = write(layer_cake, tmp_path / "cake.vtu")
    out = tmp_path / "cake.png"
    code = main(["render", str(source), str(out), "--size", "320", "240",
                 "--clip-origin", "450500,6700500,0", "--clip-normal", "0,1,0"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert _pixels(out).shape == (240, 320, 3)
    assert main(["render", str(source), str(out), "--clip-normal", "0,1,0"]) == 1
    assert "go together" in capsys.readouterr().err
