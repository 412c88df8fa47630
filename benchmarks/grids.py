"""Voxet and GRDECL read speed next to OpenGeode-GeosciencesIO, in the same run.

Run: ``.venv/bin/python benchmarks/grids.py [--voxet 256] [--grdecl 200 200 50] [--repeat 3]``

* Voxet: a ``n³`` float32 property. geobrep reads it as GOCAD writes it (raw big-endian
  ``PROP_FILE``, memory-mapped) and as an ``ASCII_DATA_FILE`` table; OpenGeode-GeosciencesIO
  reads only the ASCII form (``load_regular_grid3D``), so its ratio is taken on that file.
* GRDECL: an ``ni × nj × nk`` corner-point grid on slanted pillars with a fault throw and a
  PORO property; OpenGeode reads it with ``load_hybrid_solid3D``.

Times are the best of ``--repeat`` runs; the ratio geobrep / OpenGeode is the figure to trust
on a shared machine (goal ≤ 1.0).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import geobrep
from geobrep import Property, RegularGrid, StructuredGrid


def best(repeat: int, work: Callable[[], Any]) -> tuple[float, Any]:
    times, result = [], None
    for _ in range(repeat):
        started = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - started)
    return min(times), result


def voxet(n: int) -> RegularGrid:
    values = np.random.default_rng(3).normal(size=n**3).astype(np.float32)
    return RegularGrid(
        name="bench",
        origin=[450_000.0, 6_700_000.0, -3_000.0],
        u=[25.0, 0, 0],
        v=[0, 25.0, 0],
        w=[0, 0, 5.0],
        counts=(n - 1, n - 1, n - 1),
        point_data={"amplitude": Property(values=values, no_data_value=-99999.0)},
    )


def corner_point(ni: int, nj: int, nk: int) -> StructuredGrid:
    xs, ys = np.meshgrid(np.arange(ni + 1) * 50.0, np.arange(nj + 1) * 50.0)
    top = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, -1000.0)], axis=1)
    coord = np.hstack([top, top + np.array([10.0, 5.0, -500.0])])
    k = np.arange(nk)[:, None, None, None, None, None]
    b = np.arange(2)[None, :, None, None, None, None]
    depth = 1000.0 + 4.0 * (k + b) + np.zeros((nk, 2, nj, 2, ni, 2))
    depth[:, :, :, :, ni // 2 :, :] += 7.5  # a fault throw half way along i
    poro = np.random.default_rng(5).uniform(0.05, 0.3, ni * nj * nk)
    return StructuredGrid(
        name="bench",
        counts=(ni, nj, nk),
        coord=coord,
        zcorn=-depth.ravel(),
        cell_data={"PORO": poro},
    )


def opengeode() -> Any | None:
    try:
        import opengeode
        import opengeode_geosciencesio
    except ImportError:
        return None
    opengeode_geosciencesio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    opengeode.Logger.set_level(opengeode.Logger.LEVEL.warning)
    return opengeode


def _row(label: str, ours: float, theirs: float | None) -> str:
    ratio = "-" if theirs is None else f"{ours / theirs:.2f}x"
    other = "-" if theirs is None else f"{theirs:.3f} s"
    return f"{label:<34} geobrep {ours:8.3f} s   OpenGeode {other:>9}   ratio {ratio}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--voxet", type=int, default=256)
    parser.add_argument("--grdecl", type=int, nargs=3, default=(200, 200, 50))
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    og = opengeode()
    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        root = Path(folder)
        grid = voxet(args.voxet)
        binary = geobrep.write(grid, root / "bin.vo")
        text = geobrep.write(grid, root / "text.vo", voxet_ascii=True)
        ours_bin, back = best(args.repeat, lambda: geobrep.read(binary))
        assert back.entities[0].point_data["amplitude"] == grid.point_data["amplitude"]
        ours_txt, _ = best(args.repeat, lambda: geobrep.read(text))
        theirs = None
        if og is not None:
            theirs, loaded = best(args.repeat, lambda: og.load_regular_grid3D(str(text)))
            assert loaded.nb_cells() == grid.n_points
        n = args.voxet
        print(_row(f"Voxet {n}^3 float32 (binary)", ours_bin, theirs))
        print(_row(f"Voxet {n}^3 float32 (ASCII)", ours_txt, theirs))
        cp = corner_point(*args.grdecl)
        path = geobrep.write(cp, root / "grid.grdecl")
        ours, back = best(args.repeat, lambda: geobrep.read(path))
        assert back.entities[0].n_cells == cp.n_cells
        theirs = None
        if og is not None:
            theirs, solid = best(args.repeat, lambda: og.load_hybrid_solid3D(str(path)))
            assert solid.nb_polyhedra() == cp.n_cells
        ni, nj, nk = args.grdecl
        print(_row(f"GRDECL {ni}x{nj}x{nk} ({cp.n_cells:,} cells)", ours, theirs))


if __name__ == "__main__":
    main()
