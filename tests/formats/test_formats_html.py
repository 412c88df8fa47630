"""``geobrep view``: the offline HTML page, opened in headless Chromium.

Chromium is Debian's ``chromium`` package (``make sysdeps`` installs it); the test skips only
when no Chromium is on the machine. The page must draw (the screenshot is not blank, the model's
colours are in it) and report the model's objects on the console.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.adapters.colors import hex_colour, scene_colours
from geobrep.cli import main
from geobrep.errors import OptionsError
from geobrep.ops.io import write

GOCAD = Path(__file__).parent.parent / "data" / "gocad"
_CONSOLE = re.compile(r'"geobrep-view: (\{.*\})", source:')
_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--enable-logging=stderr",
    "--v=0",
    "--window-size=1200,800",
    "--virtual-time-budget=8000",
)


def _chromium() -> str:
    for name in (os.environ.get("GEOBREP_CHROMIUM"), "chromium", "chromium-browser"):
        if name and shutil.which(name):
            return str(shutil.which(name))
    pytest.skip("no Chromium: apt-get install chromium (make sysdeps installs it)")


def _open(page: Path, shot: Path, tmp_path: Path, fragment: str = "") -> dict[str, object]:
    """Open ``page`` in headless Chromium: the screenshot in ``shot``, the page's report."""
    done = subprocess.run(
        [
            _chromium(),
            *_FLAGS,
            f"--user-data-dir={tmp_path / 'profile'}",
            f"--screenshot={shot}",
            page.resolve().as_uri() + fragment,
        ],
        capture_output=True,
        text=True,
        timeout=180,
        check=False,
    )
    found = _CONSOLE.search(done.stderr)
    assert found, f"no report on the console (exit {done.returncode}):\n{done.stderr[-3000:]}"
    assert shot.is_file(), done.stderr[-3000:]
    report: dict[str, object] = json.loads(found.group(1).replace('\\"', '"'))
    return report


def _pixels(shot: Path) -> np.ndarray:
    image = pytest.importorskip("PIL.Image")
    with image.open(shot) as picture:
        rgb = np.asarray(picture.convert("RGB"), dtype=np.int64)
    return rgb[:, 300:]  # the 3D view (the object list is on the left)


def _has_colour(pixels: np.ndarray, colour: str, tolerance: int = 60) -> bool:
    """A pixel close to ``colour`` (lit colours are shaded: compare the hue ratios loosely)."""
    target = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
    return bool((np.abs(pixels - target).max(axis=-1) < tolerance).sum() > 200)


def test_view_page_draws_the_model_in_chromium(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    page = tmp_path / "cake.html"
    assert (
        main(["view", str(geobrep.write(scene, tmp_path / "cake.geobrep")), "-o", str(page)]) == 0
    )
    text = page.read_text()
    assert "http://" not in text.split("<script", 1)[0]  # nothing fetched: all inline
    assert "Permission is hereby granted" in text  # three.js's licence ships with it
    report = _open(page, tmp_path / "shot.png", tmp_path)
    blocks = [b for b in scene.blocks if b is not scene.universe]
    assert report["webgl"] is True
    assert report["objects"] == [s.name for s in scene.surfaces] + [b.name for b in blocks]
    assert report["crs"] == "EPSG:32631"
    assert report["triangles"] == sum(s.n_faces for s in scene.surfaces) + sum(
        scene.block_mesh(b).n_faces for b in blocks
    )
    pixels = _pixels(tmp_path / "shot.png")
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 200  # not blank
    assert (pixels.min(axis=-1) < 230).mean() > 0.15  # the model covers the view
    colours = scene_colours(scene)
    for block in blocks:  # every unit's colour is on screen
        assert _has_colour(pixels, hex_colour(colours[block.id])), block.unit_name  # type: ignore[index]


def test_the_clipping_plane_cuts_the_model(tmp_path: Path) -> None:
    page = write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.html")
    whole = (
        _pixels(tmp_path / "whole.png") if _open(page, tmp_path / "whole.png", tmp_path) else None
    )
    report = _open(page, tmp_path / "cut.png", tmp_path, "#clip=x:0.3")
    assert str(report["clip"]).startswith("X = 450")
    cut = _pixels(tmp_path / "cut.png")
    assert whole is not None
    covered = lambda p: (p.min(axis=-1) < 230).mean()  # noqa: E731
    assert covered(cut) < covered(whole) * 0.85  # 70 % of the x range cut away


def test_model3d_file_page(tmp_path: Path) -> None:
    page = tmp_path / "a1.html"
    assert main(["view", str(GOCAD / "modelA1.ml"), "-o", str(page), "--title", "A1"]) == 0
    assert "<title>A1</title>" in page.read_text()
    report = _open(page, tmp_path / "a1.png", tmp_path)
    scene = geobrep.read(GOCAD / "modelA1.ml")
    assert set(report["objects"]) >= {s.name for s in scene.surfaces}  # type: ignore[arg-type]


def test_nothing_to_show_is_an_options_error(tmp_path: Path) -> None:
    with pytest.raises(OptionsError, match="nothing to show"):
        write(geobrep.Scene(), tmp_path / "empty.html")


def test_names_are_escaped(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    odd = scene.surfaces[0].replace(name="</script><b>H1</b>")
    page = write(scene.replace(entities=[odd, *scene.entities[1:]]), tmp_path / "odd.html")
    text = page.read_text()
    assert text.count("</script>") == 3  # the model's, three.js's and the viewer's
    assert "<\\/script><b>H1<\\/b>" in text


def test_grids_and_wells_are_drawn_and_listed(tmp_path: Path) -> None:
    from grid_shapes import build_well, faulted, rotated_grid

    from geobrep.adapters._grid_boundary import grid_boundary

    grid, corner_point, well = rotated_grid(), faulted(), build_well()
    shift = grid.origin - well.head + np.array([60.0, 40.0, 800.0])  # beside the grid
    well = well.replace(head=well.head + shift, vertices=well.vertices + shift)
    moved = corner_point.coord + np.r_[grid.origin, grid.origin] + np.r_[0, -30, 0, 0, -30, 0]
    corner_point = corner_point.replace(coord=moved, zcorn=corner_point.zcorn + grid.origin[2])
    scene = geobrep.Scene(entities=[grid, corner_point, well], name="grids")
    page = tmp_path / "grids.html"
    model = geobrep.write(scene, tmp_path / "grids.geobrep")
    assert main(["view", str(model), "-o", str(page), "--property", "por"]) == 0
    report = _open(page, tmp_path / "grids.png", tmp_path)
    assert report["webgl"] is True
    assert report["objects"] == ["g", "cp", "W1"]
    assert report["types"] == ["RegularGrid", "StructuredGrid", "Well"]
    assert report["markers"] == len(well.markers) == 2
    assert (
        report["triangles"]
        == grid_boundary(grid, "por").n_faces + grid_boundary(corner_point).n_faces
    )
    text = page.read_text()
    assert '"names": ["topA", "topB"]' in text
    pixels = _pixels(tmp_path / "grids.png")
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 200  # not blank: a ramp of colours
    with pytest.raises(OptionsError, match="no grid of the scene has a property 'nothing'"):
        write(scene, tmp_path / "bad.html", property="nothing")
