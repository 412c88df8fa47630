"""Draw the pictures of docs/fitting.md: the four fitters on the built-in survey points.

Needs the ``viz`` extra (pyvista) for ``geobrep render``. Run from the repository root:
``python docs/images/fit_figures.py``. Heights are exaggerated 4 × so the dome and fold show.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

import geobrep
from geobrep.cli import main as cli
from geobrep.ops.fitting import fit

HERE = Path(__file__).resolve().parent
EXAGGERATION = 4.0


def _exaggerated(vertices: np.ndarray, base: float) -> np.ndarray:
    out = np.array(vertices, dtype=np.float64)
    out[:, 2] = base + (out[:, 2] - base) * EXAGGERATION
    return out


def main() -> None:
    points = geobrep.datasets.scattered_points()
    core = np.asarray(points.point_data["core"].values) == 1
    base = float(points.vertices[:, 2].min())
    runs = {
        "skinning": fit(geobrep.PointSet(vertices=points.vertices[core]), method="skinning"),
        "approximation": fit(points, method="approximation", epsilon=0.5),
        "kriging": fit(points, method="kriging", epsilon=0.5, variogram_model="gaussian"),
        "hybrid": fit(points, method="hybrid", epsilon=0.5, core_property="core"),
    }
    with tempfile.TemporaryDirectory() as folder:
        for name, result in runs.items():
            surface = result.surface
            mesh = (
                surface
                if isinstance(surface, geobrep.Surface)
                else surface.tessellate(resolution=160)
            )
            shown = mesh.replace(
                vertices=_exaggerated(mesh.vertices, base),
                point_data={"elevation": np.asarray(mesh.vertices[:, 2])},
                name=name,
            )
            dots = geobrep.PointSet(
                vertices=_exaggerated(points.vertices, base) + np.array([0.0, 0.0, 2.0]),
                point_data={"elevation": np.asarray(points.vertices[:, 2])},
                name="survey points",
            )
            scene = Path(folder) / f"{name}.geobrep"
            geobrep.write([shown, dots], scene)
            cli(
                [
                    "render",
                    str(scene),
                    str(HERE / f"fit_{name}.png"),
                    "--property",
                    "elevation",
                    "--size",
                    "720",
                    "540",
                ]
            )


if __name__ == "__main__":
    main()
