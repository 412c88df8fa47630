"""Foundation figures: import time, validation overhead, native save+load of 1M triangles.

Anchors in the same run: constructing the raw numpy arrays alone, and ``np.savez`` + ``np.load``
of the same arrays (the least a lossless binary container can cost).

    python benchmarks/foundation.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def best_of(function, repeat: int = 5) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def grid_surface_arrays(n_triangles: int) -> tuple[np.ndarray, np.ndarray]:
    side = int(np.ceil(np.sqrt(n_triangles / 2))) + 1
    x, y = np.meshgrid(np.linspace(0, 1000, side), np.linspace(0, 1000, side))
    vertices = np.column_stack(
        [x.ravel() + 450_000.123, y.ravel() + 6_700_000.456, np.sin(x.ravel() / 50.0) * 20]
    )
    i, j = np.meshgrid(np.arange(side - 1), np.arange(side - 1), indexing="ij")
    v0 = (i * side + j).ravel()
    faces = np.concatenate(
        [np.stack([v0, v0 + side, v0 + side + 1], 1), np.stack([v0, v0 + side + 1, v0 + 1], 1)]
    )
    return vertices, faces[:n_triangles]


def main() -> None:
    imports = []
    for _ in range(5):
        out = subprocess.run(
            [
                sys.executable,
                "-c",
                "import time; t=time.perf_counter(); import geobrep; print(time.perf_counter()-t)",
            ],
            capture_output=True,
            text=True,
            check=True,
        )
        imports.append(float(out.stdout))
    print(
        f"import geobrep: best {min(imports) * 1e3:.0f} ms, median "
        f"{statistics.median(imports) * 1e3:.0f} ms (target < 500 ms)"
    )

    import geobrep

    vertices, faces = grid_surface_arrays(1_000_000)
    props = {"z2": vertices[:, 2] * 2}
    build = best_of(
        lambda: geobrep.Surface(vertices=vertices, faces=faces, point_data=props, name="grid")
    )
    print(
        f"Surface of {len(faces):,} triangles ({len(vertices):,} vertices): validation "
        f"{build * 1e3:.2f} ms (target < 10 ms)"
    )

    surface = geobrep.Surface(vertices=vertices, faces=faces, point_data=props, name="grid")
    scene = geobrep.Scene(entities=[surface])
    folder = Path(tempfile.mkdtemp())
    path = folder / "grid.geobrep"
    raw = folder / "grid.npz"

    def native_round_trip() -> None:
        geobrep.write(scene, path)
        geobrep.read(path)

    def numpy_round_trip() -> None:
        np.savez(raw, vertices=vertices, faces=faces, z2=props["z2"])
        with np.load(raw) as data:
            for key in data.files:
                data[key]

    native = best_of(native_round_trip, 3)
    anchor = best_of(numpy_round_trip, 3)
    again = geobrep.read(path).surfaces[0]
    identical = (
        again.vertices.tobytes() == vertices.tobytes()
        and again.faces.tobytes() == faces.tobytes()
        and again.point_data["z2"].values.tobytes() == props["z2"].tobytes()
    )
    print(
        f"native save+load of 1M triangles: {native * 1e3:.0f} ms (target < 1000 ms); "
        f"np.savez+np.load of the same arrays: {anchor * 1e3:.0f} ms; "
        f"ratio {native / anchor:.2f}; bit-identical: {identical}; "
        f"file {path.stat().st_size / 1e6:.1f} MB"
    )


if __name__ == "__main__":
    main()
