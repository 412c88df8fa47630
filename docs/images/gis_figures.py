"""Draw the pictures of docs/gis.md from the layer cake's map products (needs matplotlib).

Run from the repository root: ``python docs/images/gis_figures.py``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import PathPatch
from matplotlib.path import Path as MplPath

import geobrep
from geobrep.gis.map_products import block_sections, map_products

HERE = Path(__file__).resolve().parent
COLOURS = {"unit 1": "#e9c46a", "unit 2": "#2a9d8f", "unit 3": "#8ab17d"}


def _patch(polygon: geobrep.Polygon, axes: tuple[int, int], **style: object) -> PathPatch:
    vertices, codes = [], []
    for ring in range(polygon.n_rings):
        xy = polygon.ring(ring)[:, list(axes)]
        vertices += [*xy.tolist(), xy[0].tolist()]
        codes += [MplPath.MOVETO] + [MplPath.LINETO] * (len(xy) - 1) + [MplPath.CLOSEPOLY]
    return PathPatch(MplPath(vertices, codes), **style)


def main() -> None:
    cake = geobrep.datasets.faulted_layer_cake()
    products = map_products(cake, section_levels=[-150.0])
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    for panel, layer, title in (
        (axes[0], "block_outlines", "block outlines and the fault trace"),
        (axes[1], "sections", "horizontal section at z = -150 m"),
    ):
        for entity in products.polygons:
            if entity.metadata["layer"] != layer:
                continue
            colour = COLOURS.get(str(entity.metadata.get("unit_name")), "grey")
            if layer == "sections":
                style = {"facecolor": colour, "edgecolor": "k", "alpha": 0.6}
            else:  # outlines overlap (the fault dips): draw their edges only
                style = {"facecolor": "none", "edgecolor": colour, "lw": 2.0}
            panel.add_patch(_patch(entity, (0, 1), **style))
        for trace in products.polylines:
            panel.plot(trace.vertices[:, 0], trace.vertices[:, 1], "r-", lw=2.5, label=trace.name)
        panel.set_title(title)
        panel.set_aspect("equal")
        panel.autoscale()
        panel.set_xlabel("easting (m, EPSG:32631)")
    axes[0].set_ylabel("northing (m)")
    axes[0].legend(loc="lower left")
    figure.tight_layout()
    figure.savefig(HERE / "gis_map.png", dpi=80)

    panel_entities = block_sections(cake, [geobrep.Plane.y(6_700_400.0)], with_traces=True)
    figure, axis = plt.subplots(figsize=(9, 4.2))
    for entity in panel_entities:
        if isinstance(entity, geobrep.Polygon):
            colour = COLOURS.get(str(entity.metadata.get("unit_name")), "grey")
            axis.add_patch(_patch(entity, (0, 2), facecolor=colour, edgecolor="k", alpha=0.6))
            centre = entity.vertices.mean(axis=0)
            axis.text(centre[0], centre[2], entity.name, ha="center", fontsize=8)
    axis.set_aspect("equal")
    axis.autoscale()
    axis.set_xlabel("easting (m)")
    axis.set_ylabel("z (m)")
    axis.set_title("vertical section at y = 6 700 400 m, one polygon per block")
    figure.tight_layout()
    figure.savefig(HERE / "gis_section.png", dpi=80)


if __name__ == "__main__":
    main()
