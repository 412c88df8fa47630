"""Inputs generated for benchmarks/user_work.py (imported, never run by ``make bench`` itself).

* :func:`model3d_files`: GOCAD Model3d files of 1–4 MB with 20–100 patches (faulted layer cakes
  written by geobrep);
* :func:`small_gocad_files`: many small TSurf files (1–100 kB) and the equivalent .vtu files;
* :func:`big_surface`: a closed UV sphere of about ``n_triangles`` triangles.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

import geobrep

#: (horizons, resolution): 31, 51, 71 and 91 patches; about 1.1, 3.0, 2.0 and 3.6 MB.
MODEL3D_CASES = ((2, 20.0), (4, 15.0), (6, 20.0), (8, 18.0))


def model3d_files(folder: Path) -> list[Path]:
    """One .ml file per :data:`MODEL3D_CASES` entry (written once, reused)."""
    paths = []
    for n_horizons, resolution in MODEL3D_CASES:
        path = folder / f"cake_{n_horizons}h_{resolution:g}m.ml"
        if not path.exists():
            scene = geobrep.datasets.faulted_layer_cake(
                n_horizons=n_horizons, resolution=resolution, throw=240.0 / (n_horizons + 1)
            )
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                geobrep.write(scene, path)
        paths.append(path)
    return paths


def _grid(n: int, seed: int) -> geobrep.Surface:
    """A folded ``n × n`` vertex grid surface with one vertex property."""
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(n, dtype=np.float64), np.arange(n, dtype=np.float64))
    z = 30.0 * np.sin(i / 7.0) * np.cos(j / 5.0) + rng.normal(0.0, 0.1, i.shape)
    vertices = np.column_stack(
        [450_000.0 + 25.0 * i.ravel(), 6_700_000.0 + 25.0 * j.ravel(), z.ravel()]
    )
    a = (np.arange(n - 1)[None, :] + n * np.arange(n - 1)[:, None]).ravel()
    faces = np.concatenate(
        [np.stack([a, a + 1, a + n], axis=1), np.stack([a + 1, a + n + 1, a + n], axis=1)]
    )
    values = np.round(rng.uniform(0.0, 1.0, vertices.shape[0]), 4)
    return geobrep.Surface(
        vertices=np.round(vertices, 3), faces=faces, name=f"s{seed}", point_data={"v": values}
    )


def small_gocad_files(folder: Path, count: int) -> tuple[list[Path], list[Path]]:
    """``count`` TSurf files of 1–100 kB and the same surfaces as .vtu files."""
    ts_dir, vtu_dir = folder / "ts", folder / "vtu"
    ts_dir.mkdir(parents=True, exist_ok=True)
    vtu_dir.mkdir(parents=True, exist_ok=True)
    sides = np.round(np.geomspace(4, 36, count)).astype(int)  # about 1 kB … 100 kB
    ts_paths, vtu_paths = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for index, side in enumerate(sides.tolist()):
            ts, vtu = ts_dir / f"f{index:05d}.ts", vtu_dir / f"f{index:05d}.vtu"
            if not ts.exists() or not vtu.exists():
                scene = geobrep.Scene(entities=[_grid(side, index)])
                geobrep.write(scene, ts)
                geobrep.write(scene, vtu)
            ts_paths.append(ts)
            vtu_paths.append(vtu)
    return ts_paths, vtu_paths


def big_surface(n_triangles: int) -> geobrep.Surface:
    """A closed UV sphere (radius 1000 m) of about ``n_triangles`` triangles."""
    n = max(4, int(np.sqrt(n_triangles / 2.0)))
    theta = np.linspace(0.0, np.pi, n + 1)[1:-1]  # latitudes, poles excluded
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.column_stack(
        [(np.sin(t) * np.cos(p)).ravel(), (np.sin(t) * np.sin(p)).ravel(), np.cos(t).ravel()]
    )
    vertices = 1000.0 * np.vstack([ring, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    north, south = ring.shape[0], ring.shape[0] + 1
    rows, cols = n - 1, n
    r, c = np.meshgrid(np.arange(rows - 1), np.arange(cols), indexing="ij")
    a = (r * cols + c).ravel()
    b = (r * cols + (c + 1) % cols).ravel()
    quads = np.concatenate(
        [np.stack([a, a + cols, b], axis=1), np.stack([b, a + cols, b + cols], axis=1)]
    )
    top = np.arange(cols)
    bottom = (rows - 1) * cols + np.arange(cols)
    caps = np.concatenate(
        [
            np.stack([np.full(cols, north), top, (top + 1) % cols], axis=1),
            np.stack([np.full(cols, south), (rows - 1) * cols + (top + 1) % cols, bottom], axis=1),
        ]
    )
    faces = np.concatenate([quads, caps]).astype(np.int64)
    return geobrep.Surface(vertices=vertices, faces=faces, name="sphere", kind="other")
