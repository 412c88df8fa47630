"""GOCAD TSurf read/write speed on a generated 1M-triangle surface, next to OpenGeode.

Run: ``.venv/bin/python benchmarks/gocad_io.py [--repeat 3] [--size 708]``

The surface is a ``size × size`` vertex grid at UTM coordinates (≈ 1M triangles for 708) with
two vertex properties (a scalar and a 3-vector) and one triangle property. Two variants:

* ``mm``: coordinates rounded to the millimetre and properties to 5 decimals, as survey-derived
  files usually are;
* ``full``: every value a full-precision float64 (17 significant digits on disk): the worst
  case for any text reader.

For each variant the script writes the file with ``geobrep.write`` (timed), reads it back with
``geobrep.read`` (timed, and checked bit for bit), and reads the same file with
``opengeode-geosciencesio`` (``opengeode.load_triangulated_surface3D``) in the same run. Times
are the best and median of ``--repeat`` runs; on a shared machine the ratio is the figure to
trust.
Targets: read ≤ 1.5 s and ≤ 3× OpenGeode, write ≤ 1.5 s.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import geobrep
from geobrep import Property, Scene, Surface


def grid_surface(size: int, variant: str) -> Surface:
    """A folded UTM-scale grid surface with properties."""
    rng = np.random.default_rng(7)
    i, j = np.meshgrid(np.arange(size, dtype=np.float64), np.arange(size, dtype=np.float64))
    x = 450_000.0 + 12.5 * i + rng.normal(0.0, 0.8, i.shape)
    y = 6_700_000.0 + 12.5 * j + rng.normal(0.0, 0.8, i.shape)
    z = -1500.0 + 80.0 * np.sin(i / 37.0) * np.cos(j / 53.0) + rng.normal(0.0, 0.3, i.shape)
    vertices = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    porosity = rng.uniform(0.05, 0.35, vertices.shape[0])
    normal = rng.normal(size=(vertices.shape[0], 3))
    if variant == "mm":
        vertices = np.round(vertices, 3)
        porosity = np.round(porosity, 5)
        normal = np.round(normal, 5)
    a = (np.arange(size - 1)[None, :] + size * np.arange(size - 1)[:, None]).ravel()
    faces = np.concatenate(
        [np.stack([a, a + 1, a + size], axis=1), np.stack([a + 1, a + size + 1, a + size], axis=1)]
    )
    zone = (faces[:, 0] % 7).astype(np.float64)
    return Surface(
        vertices=vertices,
        faces=faces,
        name="grid",
        kind="horizon",
        point_data={
            "porosity": Property(values=porosity, unit="1", no_data_value=-99999.0),
            "normal": Property(values=normal, unit="m"),
        },
        cell_data={"zone": zone},
    )


def best_of(repeat: int, function: Callable[[], Any]) -> tuple[float, float, Any]:
    """Best and median time of ``repeat`` runs, and the last result."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), statistics.median(times), result


def opengeode_reader() -> Callable[[Path], Any] | None:
    try:
        import opengeode
        import opengeode_geosciencesio
    except ImportError:
        return None
    opengeode_geosciencesio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    opengeode.Logger.set_level(opengeode.Logger.LEVEL.warning)

    def read(path: Path) -> Any:
        return opengeode.load_triangulated_surface3D(str(path))

    return read


def run(size: int, repeat: int) -> None:
    folder = Path(tempfile.mkdtemp(prefix="gocad-bench-"))
    opengeode_read = opengeode_reader()
    print(f"grid {size} × {size}: {(size - 1) ** 2 * 2:,} triangles, {size * size:,} vertices")
    for variant in ("mm", "full"):
        surface = grid_surface(size, variant)
        scene = Scene(entities=[surface], crs=geobrep.CRS(name="bench", z_positive="down"))
        path = folder / f"grid_{variant}.ts"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            write_s, write_med, _ = best_of(repeat, lambda s=scene, p=path: geobrep.write(s, p))
            read_s, read_med, again = best_of(repeat, lambda p=path: geobrep.read(p))
        back = again.surfaces[0]
        exact = (
            np.array_equal(back.vertices, surface.vertices)
            and np.array_equal(back.faces, surface.faces)
            and all(
                np.array_equal(back.point_data[n].values, surface.point_data[n].values)
                for n in surface.point_data
            )
        )
        size_mb = path.stat().st_size / 1e6
        line = (
            f"  {variant:4}  file {size_mb:5.1f} MB  geobrep write {write_s:5.3f} s "
            f"(median {write_med:5.3f})  read {read_s:5.3f} s (median {read_med:5.3f})  "
            f"bit-identical={exact}"
        )
        if opengeode_read is not None:
            og_s, og_med, mesh = best_of(repeat, lambda p=path: opengeode_read(p))
            assert mesh.nb_polygons() == surface.n_faces
            line += (
                f"\n        OpenGeode read {og_s:5.3f} s (median {og_med:5.3f})  "
                f"ratio read/OpenGeode best {read_s / og_s:4.2f}, median {read_med / og_med:4.2f}"
            )
        else:
            line += "   (opengeode-geosciencesio not installed)"
        print(line)
    print("targets: read ≤ 1.5 s and ≤ 3× OpenGeode; write ≤ 1.5 s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=708, help="vertices per grid side")
    parser.add_argument("--repeat", type=int, default=3, help="runs per timing (best kept)")
    args = parser.parse_args()
    run(args.size, args.repeat)


if __name__ == "__main__":
    main()
