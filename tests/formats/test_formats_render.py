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


# -- legend, axes, scale bar, title, view direction, section ------------------------------


def _near(pixels: NDArray[np.uint8], colour: tuple[float, ...], tolerance: int = 25) -> int:
    target = np.array([round(c * 255) for c in colour[:3]])
    return int((np.abs(pixels.astype(int) - target).max(axis=2) < tolerance).sum())


def test_legend_shows_every_unit_colour_unshaded(layer_cake: Scene, tmp_path: Path) -> None:
    from geobrep.adapters.colors import scene_colours

    colours = scene_colours(layer_cake)
    units = {b.unit_name: colours[b.id] for b in layer_cake.blocks if b.id and b.unit_name}  # type: ignore[index]
    with_legend = _pixels(write(layer_cake, tmp_path / "l.png", color_by="block",
                                window_size=(800, 600)))  # fmt: skip
    without = _pixels(write(layer_cake, tmp_path / "n.png", color_by="block",
                            window_size=(800, 600), legend=False))  # fmt: skip
    corner = (slice(0, 200), slice(600, 800))  # the legend's place: upper right
    for unit, colour in units.items():
        # the legend's swatches are the exact colours; the lit model is shaded
        assert _near(with_legend[corner], colour) > _near(without[corner], colour) + 20, unit


def test_axes_title_and_scale_bar_draw_something(layer_cake: Scene, tmp_path: Path) -> None:
    bare = _pixels(write(layer_cake, tmp_path / "bare.png", window_size=(600, 450),
                         legend=False, axes=False, scale_bar=False, title=" "))  # fmt: skip
    axes = _pixels(write(layer_cake, tmp_path / "axes.png", window_size=(600, 450),
                         legend=False, scale_bar=False, title=" "))  # fmt: skip
    bar = _pixels(write(layer_cake, tmp_path / "bar.png", window_size=(600, 450),
                        legend=False, axes=False, title=" "))  # fmt: skip
    titled = _pixels(write(layer_cake, tmp_path / "title.png", window_size=(600, 450),
                           legend=False, axes=False, scale_bar=False))  # fmt: skip
    dark = lambda p: int((p.max(axis=2) < 60).sum())  # noqa: E731  text and lines are black
    assert dark(axes) > dark(bare) + 200
    assert dark(bar) > dark(bare) + 200
    assert dark(titled[:40]) > dark(bare[:40]) + 100  # the title line, with the CRS


def test_scale_bar_length(tmp_path: Path) -> None:
    from geobrep.adapters.pyvista._render import _nice_length

    assert [_nice_length(s) for s in (1000.0, 740.0, 12.0, 3.3e4)] == [200.0, 200.0, 5.0, 1e4]


def test_view_directions_differ(layer_cake: Scene, tmp_path: Path) -> None:
    pictures = {
        view: _pixels(
            write(
                layer_cake,
                tmp_path / f"{view}.png",
                view=view,
                window_size=(400, 300),
                legend=False,
            )
        )
        for view in ("isometric", "top", "south")
    }
    top, south = pictures["top"], pictures["south"]
    assert (np.abs(top.astype(int) - south.astype(int)).sum(axis=2) > 30).mean() > 0.1
    turned = _pixels(write(layer_cake, tmp_path / "turned.png", azimuth=40, elevation=20,
                           window_size=(400, 300), legend=False))  # fmt: skip
    assert (
        np.abs(turned.astype(int) - pictures["isometric"].astype(int)).sum(axis=2) > 30
    ).mean() > 0.05


def test_section_fills_the_units_it_cuts(layer_cake: Scene, tmp_path: Path) -> None:
    from geobrep.adapters.colors import scene_colours

    centre = tuple(float(v) for v in layer_cake.bounds.center)  # type: ignore[union-attr]
    path = write(layer_cake, tmp_path / "section.png", color_by="block", legend=False,
                 section_origin=centre, section_normal=(0.0, -1.0, 0.0),
                 window_size=(800, 600))  # fmt: skip
    pixels = _pixels(path)
    colours = scene_colours(layer_cake)
    for block in layer_cake.blocks:
        if block.id is not None and block.kind != "universe":
            # the cut faces the camera square: lit flat, near the unit's own colour
            assert _near(pixels, colours[block.id], tolerance=70) > 2000, block.name
    with pytest.raises(OptionsError, match="cuts everything away"):
        write(layer_cake, tmp_path / "none.png", section_origin=(0.0, 0.0, 1e7),
              section_normal=(0.0, 0.0, -1.0))  # fmt: skip
    with pytest.raises(OptionsError, match="go together"):
        write(layer_cake, tmp_path / "bad.png", section_normal=(0.0, 1.0, 0.0))


def test_cli_render_view_and_section(layer_cake: Scene, tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    source = write(layer_cake, tmp_path / "cake.geobrep")
    out = tmp_path / "cake.png"
    code = main(["render", str(source), str(out), "--size", "320", "240", "--color-by", "block",
                 "--section-origin", "450500,6700500,-300", "--section-normal", "0,-1,0",
                 "--title", "Section", "--no-scale-bar"])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert main(["render", str(source), str(out), "--view", "top", "--no-legend",
                 "--no-axes", "--azimuth", "10"]) == 0  # fmt: skip
    assert main(["render", str(source), str(out), "--section-normal", "0,1,0"]) == 1
    assert "go together" in capsys.readouterr().err
