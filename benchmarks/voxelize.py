"""Voxelization at depth 8 (256³) of closed ~100k-triangle bodies, against the anchors, one run.

geobrep's depth-buffer and exact modes (linear octree included) against
* pyvista ``voxelize_binary_mask`` (a dense 256³ mask only),
* open3d ``VoxelGrid.create_from_triangle_mesh`` (surface voxels only, no interior),
* trimesh ``voxelized(pitch).fill()`` (surface voxels, then the interior filled).

Bodies: an 81,920-triangle icosphere (the issue's anchor body) and a 98,304-triangle torus
turned so that rays along every axis cross it four times (the exact mode is needed there).
Targets: geobrep ≤ 0.5 s and no slower than open3d's surface-only grid. Timings are the best of
``REPEAT`` runs (trimesh: one run, it is slow); the machine is shared, so read the ratios.

    python benchmarks/voxelize.py
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

REPEAT = 5
DEPTH = 8


def best_of(function: Callable[[], Any], repeat: int = REPEAT) -> tuple[float, Any]:
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def icosphere() -> tuple[np.ndarray, np.ndarray, float]:
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=6, radius=100.0)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64), 4 / 3 * np.pi * 1e6


def tilted_torus() -> tuple[np.ndarray, np.ndarray, float]:
    major, minor, around, tube = 100.0, 70.0, 384, 128
    u = np.linspace(0, 2 * np.pi, around, endpoint=False)
    v = np.linspace(0, 2 * np.pi, tube, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ring = major + minor * np.cos(vv)
    vertices = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(vv)], -1)
    r, c = np.meshgrid(np.arange(around), np.arange(tube), indexing="ij")
    a = (r * tube + c).ravel()
    b = (r * tube + (c + 1) % tube).ravel()
    d = (((r + 1) % around) * tube + c).ravel()
    e = (((r + 1) % around) * tube + (c + 1) % tube).ravel()
    faces = np.concatenate([np.stack([a, e, b], 1), np.stack([a, d, e], 1)])
    # Turn the axis to (1, 1, 1): every axis then has rays crossing the body four times.
    k = np.array([-1.0, 1.0, 0.0]) / np.sqrt(2.0)
    angle = np.arccos(1 / np.sqrt(3))
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    turn = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
    vertices = vertices.reshape(-1, 3) @ turn.T
    return vertices, faces.astype(np.int64), 2 * np.pi**2 * major * minor**2


def run_body(name: str, vertices: np.ndarray, faces: np.ndarray, analytic: float) -> None:
    import open3d as o3d
    import pyvista as pv
    import trimesh

    import geobrep
    from geobrep.ops.voxelization import VoxelizationWarning, voxelize

    offset = np.array([450_000.0, 6_700_000.0, -500.0])  # UTM-scale coordinates
    surface = geobrep.Surface(vertices=vertices + offset, faces=faces, name=name)
    assert surface.is_closed
    extent = float(np.ptp(vertices, axis=0).max())
    pitch = extent / 2**DEPTH
    print(f"\n{name}: {len(faces):,} triangles, depth {DEPTH} ({2**DEPTH}³ cells)")

    rows: dict[str, float] = {}
    trees = {}
    for method in ("depth-buffer", "exact", "auto"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", VoxelizationWarning)
            voxelize(surface, depth=DEPTH, method=method)  # warm-up (imports, plugin load)
            seconds, tree = best_of(lambda m=method: voxelize(surface, depth=DEPTH, method=m))
        rows[f"geobrep {method}"] = seconds
        trees[method] = tree

    polydata = pv.PolyData(vertices, np.hstack([np.full((len(faces), 1), 3), faces]).ravel())
    rows["pyvista voxelize_binary_mask"], mask = best_of(
        lambda: polydata.voxelize_binary_mask(dimensions=(2**DEPTH,) * 3)
    )
    o3d_mesh = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(vertices), o3d.utility.Vector3iVector(faces.astype(np.int32))
    )
    rows["open3d VoxelGrid (surface only)"], grid = best_of(
        lambda: o3d.geometry.VoxelGrid.create_from_triangle_mesh(o3d_mesh, pitch)
    )
    tm = trimesh.Trimesh(vertices, faces, process=False)
    rows["trimesh voxelized + fill"], filled = best_of(lambda: tm.voxelized(pitch).fill(), 1)

    anchor = rows["open3d VoxelGrid (surface only)"]
    print(f"  {'':34} {'seconds':>8} {'vs open3d':>10}")
    for label, seconds in rows.items():
        print(f"  {label:34} {seconds:8.3f} {seconds / anchor:9.2f}x")
    for method in ("depth-buffer", "exact"):
        ratio_pv = rows[f"geobrep {method}"] / rows["pyvista voxelize_binary_mask"]
        ratio_tm = rows[f"geobrep {method}"] / rows["trimesh voxelized + fill"]
        print(f"  geobrep {method}: {ratio_pv:.2f}x pyvista, {ratio_tm:.3f}x trimesh")
    auto = trees["auto"]
    used = auto.metadata["voxelization"]["bodies"][0]["method"]
    print(f"  auto used: {used}; target <= 0.5 s: {rows['geobrep auto'] <= 0.5}")

    cell = pitch**3
    mask_volume = float(np.count_nonzero(mask.point_data["mask"])) * cell
    fill_volume = float(filled.filled_count) * cell
    print("  volume vs analytic:")
    for method in ("depth-buffer", "exact"):
        tree = trees[method]
        print(f"    geobrep {method:13} {(tree.volume - analytic) / analytic:+.3%}")
    print(f"    pyvista mask          {(mask_volume - analytic) / analytic:+.3%}")
    print(f"    trimesh fill          {(fill_volume - analytic) / analytic:+.3%}")
    print(f"    open3d: {len(grid.get_voxels()):,} surface voxels (no interior)")
    tree = trees["exact"]
    full = 8**DEPTH
    print(
        f"  memory: linear octree {tree.n_leaves:,} leaves, {tree.memory_bytes / 1e6:.2f} MB "
        f"(codes + levels) vs full {2**DEPTH}³ grid {full / 1e6:.1f} MB at one byte per cell "
        f"({tree.memory_bytes / full:.1%}), {full / 8e6:.1f} MB as bits "
        f"({tree.memory_bytes / (full / 8):.0%})"
    )
    print("  leaves per level:", tree.leaf_count_per_level().tolist())


def main() -> None:
    run_body("icosphere", *icosphere())
    run_body("tilted torus", *tilted_torus())


if __name__ == "__main__":
    main()
