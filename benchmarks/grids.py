"""Voxet and GRDECL read speed next to OpenGeode-GeosciencesIO, in the same run.

Run: ``.venv/bin/python benchmarks/grids.py [--voxet 256] [--grdecl 200 200 50] [--repeat 5]
[--only voxet|ascii|grdecl]``

* Voxet: a ``n³`` float32 property. geobrep reads it as GOCAD writes it (raw big-endian
  ``PROP_FILE``, memory-mapped) and as an ``ASCII_DATA_FILE`` table; OpenGeode-GeosciencesIO
  reads only the ASCII form (``load_regular_grid3D``), so its ratio is taken on that file;
  every value geobrep reads from the ASCII table is checked to be the float written.
* GRDECL: an ``ni × nj × nk`` corner-point grid on slanted pillars with a fault throw and a
  PORO property; OpenGeode reads it with ``load_hybrid_solid3D``.

Each of ``--repeat`` (5) runs reads with geobrep, then with OpenGeode, so both meet the same
load; the times are CPU times (``time.process_time``, every thread of the process); printed
are the best and median times and the ratios geobrep / OpenGeode of the best
times and the median of the per-run ratios, the figures to trust on a shared machine (goal
≤ 1.0).
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
from geobrep import Property, RegularGrid, StructuredGrid


def timed(work: Callable[[], Any]) -> tuple[float, Any]:
    """CPU time of ``work`` (all threads of the process: fair to a multi-threaded reader and
    less noisy than wall time on a shared machine) and its result."""
    started = time.process_time()
    result = work()
    return time.process_time() - started, result


def side_by_side(
    repeat: int, ours: Callable[[], Any], theirs: Callable[[], Any] | None
) -> tuple[list[float], list[float], Any, Any]:
    """Each run times geobrep, then OpenGeode (the same load on both); all the times."""
    mine: list[float] = []
    other: list[float] = []
    result = anchor = None
    for _ in range(repeat):
        seconds, result = timed(ours)
        mine.append(seconds)
        if theirs is not None:
            seconds, anchor = timed(theirs)
            other.append(seconds)
    return mine, other, result, anchor


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


def _row(label: str, ours: list[float], theirs: list[float]) -> str:
    mine = f"geobrep best {min(ours):7.3f} s median {statistics.median(ours):7.3f} s"
    if not theirs:
        return f"{label:<32} {mine}   (OpenGeode not installed)"
    best = min(ours) / min(theirs)
    median = statistics.median(a / b for a, b in zip(ours, theirs, strict=True))
    other = f"OpenGeode best {min(theirs):7.3f} s median {statistics.median(theirs):7.3f} s"
    return f"{label:<32} {mine}   {other}   ratio best {best:.2f}x median {median:.2f}x"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--voxet", type=int, default=256)
    parser.add_argument("--grdecl", type=int, nargs=3, default=(200, 200, 50))
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--only",
        choices=("voxet", "ascii", "grdecl"),
        default=None,
        help="run only the Voxets, only the ASCII Voxet or only the GRDECL",
    )
    args = parser.parse_args()
    og = opengeode()
    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        root = Path(folder)
        if args.only != "grdecl":
            _voxets(args.voxet, args.repeat, root, og, binary=args.only != "ascii")
        if args.only is None or args.only == "grdecl":
            _grdecl(args.grdecl, args.repeat, root, og)


def _voxets(n: int, repeat: int, root: Path, og: Any | None, binary: bool) -> None:
    grid = voxet(n)
    expected = grid.point_data["amplitude"]
    text = geobrep.write(grid, root / "text.vo", voxet_ascii=True)
    load_voxet = None if og is None else (lambda: og.load_regular_grid3D(str(text)))
    if binary:
        path = geobrep.write(grid, root / "bin.vo")
        ours_bin, theirs, back, loaded = side_by_side(
            repeat, lambda: geobrep.read(path), load_voxet
        )
        assert back.entities[0].point_data["amplitude"] == expected
        if loaded is not None:
            assert loaded.nb_cells() == grid.n_points
        print(_row(f"Voxet {n}^3 float32 (binary)", ours_bin, theirs))
    ours_txt, theirs_txt, back, _ = side_by_side(repeat, lambda: geobrep.read(text), load_voxet)
    read = back.entities[0].point_data["amplitude"].values
    assert back.entities[0].n_points == grid.n_points
    assert np.array_equal(read, expected.values.astype(np.float64))  # every value exact
    print(_row(f"Voxet {n}^3 float32 (ASCII)", ours_txt, theirs_txt))


def _grdecl(counts: tuple[int, int, int], repeat: int, root: Path, og: Any | None) -> None:
    cp = corner_point(*counts)
    path = geobrep.write(cp, root / "grid.grdecl")
    load_grdecl = None if og is None else (lambda: og.load_hybrid_solid3D(str(path)))
    ours, theirs, back, solid = side_by_side(repeat, lambda: geobrep.read(path), load_grdecl)
    assert back.entities[0].n_cells == cp.n_cells
    if solid is not None:
        assert solid.nb_polyhedra() == cp.n_cells
    ni, nj, nk = counts
    print(_row(f"GRDECL {ni}x{nj}x{nk} ({cp.n_cells:,} cells)", ours, theirs))


if __name__ == "__main__":
    main()
