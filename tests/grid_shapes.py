"""Grids and wells the clip, render and pipeline tests share (their truth is analytic)."""

from __future__ import annotations

import numpy as np

from geobrep import RegularGrid, StructuredGrid, Well, WellLog, WellMarker, WellZone
from geobrep.geometry.trajectory import minimum_curvature

ROTATED = {
    "origin": [450_000.0, 6_700_000.0, -1200.0],
    "u": [8.660254037844387, 5.0, 0.0],
    "v": [-2.5, 4.330127018922194, 0.0],
    "w": [0.3, 0.1, 2.0],  # non-orthogonal
    "counts": (12, 9, 7),
}


def rotated_grid() -> RegularGrid:
    n = 12 * 9 * 7
    return RegularGrid(
        name="g",
        cell_data={"por": np.linspace(0.1, 0.3, n), "facies": np.arange(n) % 5},
        point_data={"t": np.arange(13 * 10 * 8, dtype=np.float64)},
        **ROTATED,  # type: ignore[arg-type]
    )


def faulted(throw: float = 3.0) -> StructuredGrid:
    """6 × 4 × 3 cells on vertical pillars, the cells with i ≥ 3 dropped by ``throw``."""
    ni, nj, nk = 6, 4, 3
    coord = [[x, y, 0.0, x, y, 100.0] for y in range(nj + 1) for x in range(ni + 1)]
    z = np.zeros((nk, 2, nj, 2, ni, 2))
    shift = np.where(np.arange(ni) >= 3, throw, 0.0)
    for k in range(nk):
        for b in (0, 1):
            z[k, b] = (10.0 + 2.0 * (k + b) + shift)[None, None, :, None]
    actnum = np.ones(ni * nj * nk, bool)
    actnum[[0, 7, 30]] = False
    return StructuredGrid(
        name="cp", counts=(ni, nj, nk), coord=coord, zcorn=z.ravel(), actnum=actnum,
        cell_data={"poro": np.arange(ni * nj * nk, dtype=np.float64)},
    )  # fmt: skip


BUILD = 3.0  # degrees per 30 m
RADIUS = 30.0 / np.radians(BUILD)  # of the build section


def build_well() -> Well:
    """Vertical to 200 m MD, then a constant build of 3°/30 m at azimuth 60°: a circular arc."""
    md = np.concatenate([[0.0, 100.0, 200.0], np.arange(230.0, 1101.0, 30.0)])
    inclination = np.clip((md - 200.0) / 30.0 * BUILD, 0.0, None)
    azimuth = np.full(md.shape, 60.0)
    xyz = minimum_curvature(md, inclination, azimuth) + np.array([1000.0, 2000.0, 50.0])
    return Well(
        name="W1",
        head=xyz[0],
        vertices=xyz,
        md=md,
        point_data={"INCL": inclination, "AZIM_GN": azimuth, "GR": np.linspace(10, 90, md.size)},
        markers=[WellMarker(name="topA", md=150.0, surface="A"),
                 WellMarker(name="topB", md=700.0, surface="B")],
        zones=[WellZone(name="unit 1", top_md=150.0, base_md=700.0)],
        logs={"DT": WellLog(md=np.arange(0.0, 1100.0, 0.5), values=np.arange(2200.0))},
    )  # fmt: skip
