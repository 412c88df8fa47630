"""Draw ``blocks_layer_cake.png`` for docs/blocks.md: the sample rebuilt from its bare surfaces.

Run from the repository root: ``.venv/bin/python docs/images/blocks_figures.py`` (needs pyvista;
renders off-screen).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyvista as pv

import geobrep
from geobrep.ops.building import build_blocks

COLOURS = ["#e6a23c", "#f3d39b", "#6aa84f", "#b6d7a8", "#3d85c6", "#a4c8ec"]


def main() -> None:
    truth = geobrep.datasets.faulted_layer_cake(resolution=25.0)
    built = build_blocks(geobrep.Scene(entities=truth.surfaces, crs=truth.crs))
    bounds = built.bounds
    assert bounds is not None
    centre = 0.5 * (np.asarray(bounds.mins) + np.asarray(bounds.maxs))
    plotter = pv.Plotter(off_screen=True, window_size=(1400, 1000))
    for k, block in enumerate(built.blocks):
        boundary = built.block_mesh(block)
        local = boundary.vertices - centre
        middle = local.mean(axis=0)
        shift = 0.35 * middle * np.array([1.0, 0.0, 1.4])  # exploded view
        faces = np.hstack([np.full((boundary.n_faces, 1), 3), boundary.faces]).ravel()
        plotter.add_mesh(
            pv.PolyData(local + shift, faces),
            color=COLOURS[k % len(COLOURS)],
            show_edges=True,
            edge_color="#777777",
            line_width=0.2,
        )
        plotter.add_point_labels(
            [middle + shift + np.array([0.0, -420.0, 0.0])],
            [f"{block.name}: {block.unit_name}"],
            font_size=13,
            point_size=1,
            shape_opacity=0.7,
            always_visible=True,
        )
    plotter.view_vector((-0.6, -1.0, 0.55))
    plotter.camera.zoom(1.05)
    plotter.set_background("white")
    plotter.screenshot(str(Path(__file__).with_name("blocks_layer_cake.png")))


if __name__ == "__main__":
    main()
