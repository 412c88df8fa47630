"""Inspection figures: a ~1M-triangle model with every default check, and OpenGeode-Inspector
side by side on the same meshes and models (the ``bench`` extra: ``opengeode-inspector``).

1. Four wavy horizons of ~250k triangles each (~1M in all), with known defects injected into the
   first: 10 duplicated vertices, 10 zero-area triangles (slivers), 10 flipped triangles and
   5 pairs of crossing triangles. ``geobrep.inspect`` runs every default check (reading
   excluded); wall-clock and CPU times are the best of N runs (the machine may be shared: CPU
   time is what an idle machine would take, numpy being single-threaded here).
2. The same surfaces, written as GOCAD .ts and loaded by OpenGeode, go through
   ``SurfaceMeshInspector3D.inspect_surface`` (its mesh criteria: colocated points, degenerate
   edges and polygons, non-manifold edges and vertices, wrong adjacencies, self-intersections):
   the defect counts per shared criterion, and the time ratio.
3. Every Model3d of tests/data/gocad through ``BRepInspector.inspect_brep`` and
   ``geobrep.inspect`` (read with ``repair=False``): the issue counts of each family.

Counting conventions differ, and each difference is printed with its reason: OpenGeode counts
an orientation defect per polygon *edge* seen from each side (a flipped triangle inside a mesh:
3 edges x 2 sides), geobrep per *face* to flip.

    python benchmarks/inspection.py [--quick]
"""

from __future__ import annotations

import os
import sys

# This script is named after the stdlib module numpy imports: run as a script, its folder comes
# first on sys.path and would shadow it.
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != os.path.dirname(__file__)]

import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

import geobrep  # noqa: E402
from geobrep import Scene, Surface  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "gocad"
QUICK = "--quick" in sys.argv
RUNS = 1 if QUICK else 3


def horizon(n: int, z: float, name: str) -> Surface:
    """A wavy n x n horizon of 2 n² triangles over 1 km²."""
    xs, ys = np.meshgrid(np.linspace(0, 1000, n + 1), np.linspace(0, 1000, n + 1))
    zz = z + 20.0 * np.sin(xs / 90.0) * np.cos(ys / 70.0)
    vertices = np.column_stack([xs.ravel(), ys.ravel(), zz.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    faces = np.concatenate(
        [np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])]
    )
    return Surface(vertices=vertices, faces=faces, name=name)


def with_defects(surface: Surface, k: int = 10, crossings: int = 5) -> Surface:
    """``surface`` with ``k`` duplicated vertices, ``k`` slivers, ``k`` flipped triangles and
    ``crossings`` pairs of crossing triangles (away from the surface)."""
    rng = np.random.default_rng(7)
    vertices = surface.vertices.copy()
    faces = surface.faces.copy()
    n = vertices.shape[0]
    picked = rng.choice(np.arange(n // 4, 3 * n // 4), k, replace=False)
    extra = [vertices[picked]]
    for copy, vertex in enumerate(picked):  # one face around each vertex uses its copy
        row = int(np.flatnonzero((faces == vertex).any(axis=1))[0])
        faces[row][faces[row] == vertex] = n + copy
    flipped = rng.choice(np.arange(0, faces.shape[0], 7), k, replace=False)
    faces[flipped] = faces[flipped][:, ::-1]
    base = n + k
    new_faces = []
    for s in range(k):  # slivers: three collinear points above the surface
        extra.append(
            np.array([[10.0 * s, -50.0, 500.0], [10.0 * s + 4, -50, 500], [10.0 * s + 2, -50, 500]])
        )
        new_faces.append([base, base + 1, base + 2])
        base += 3
    for c in range(crossings):  # two triangles piercing each other, far from the rest
        x = 100.0 * c
        extra.append(np.array([[x, -200, 0], [x + 4, -200, 0], [x, -196, 0]]))
        extra.append(np.array([[x + 1, -199, -1], [x + 1, -199, 1], [x + 2, -198.8, 0.2]]))
        new_faces += [[base, base + 1, base + 2], [base + 3, base + 4, base + 5]]
        base += 6
    return surface.replace(
        vertices=np.vstack([vertices, *extra]), faces=np.vstack([faces, new_faces])
    )


def best(function: Any, runs: int = RUNS) -> tuple[float, float, Any]:
    """Best wall-clock and CPU seconds of ``runs`` calls, and the last result."""
    walls, cpus, result = [], [], None
    for _ in range(runs):
        wall, cpu = time.perf_counter(), time.process_time()
        result = function()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return min(walls), min(cpus), result


def geobrep_part(scene: Scene) -> geobrep.InspectionReport:
    n = sum(s.n_faces for s in scene.surfaces)
    wall, cpu, report = best(lambda: geobrep.inspect(scene))
    print(
        f"geobrep.inspect, {n:,} triangles, {len(report.sections)} default checks: "
        f"{wall:.2f} s wall, {cpu:.2f} s CPU (target: < 10 s)"
    )
    for section in sorted(report.sections, key=lambda s: -s.seconds)[:6]:
        print(f"    {section.check:<26} {section.count:>6} defects  {section.seconds:6.2f} s")
    return report


def _cpu(function: Any) -> tuple[float, Any]:
    begin = time.process_time()
    result = function()
    return time.process_time() - begin, result


def side_by_side(scene: Scene, meshes: list[Any], oi: Any, runs: int) -> list[Any]:
    """geobrep (every default check) and OpenGeode-Inspector (its surface criteria) one after
    the other in each run: the CPU ratio geobrep / OpenGeode per run, best and median."""
    ratios, ours, theirs, results = [], [], [], []
    for _ in range(runs):
        mine, _report = _cpu(lambda: geobrep.inspect(scene))
        other, results = _cpu(
            lambda: [oi.SurfaceMeshInspector3D(m).inspect_surface() for m in meshes]
        )
        ours.append(mine)
        theirs.append(other)
        ratios.append(mine / other)
    print(
        f"CPU s per run, geobrep {[round(x, 2) for x in ours]}, "
        f"OpenGeode {[round(x, 2) for x in theirs]}"
    )
    print(
        f"  ratio geobrep / OpenGeode (CPU, same run; target <= 1): best "
        f"{min(ratios):.2f}, median {float(np.median(ratios)):.2f}"
    )
    return results


def _og() -> Any:
    try:
        import opengeode as og
        import opengeode_geosciences as geosciences
        import opengeode_geosciencesio as ogio
        import opengeode_inspector as oi
    except ImportError:
        print("OpenGeode-Inspector is not installed (pip install 'geobrep[bench]'): skipped")
        return None
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    ogio.OpenGeodeGeosciencesIOModelLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)
    return og, oi, geosciences


def _surface_counts(result: Any) -> dict[str, int]:
    return {
        "colocated_vertices": result.colocated_points_groups.nb_issues(),
        "degenerate_elements": result.degenerated_polygons.nb_issues()
        + result.degenerated_edges.nb_issues(),
        "non_manifold_edges": result.non_manifold_edges.nb_issues(),
        "non_manifold_vertices": result.non_manifold_vertices.nb_issues(),
        "inconsistent_orientation": result.polygon_edges_with_wrong_adjacency.nb_issues(),
        "self_intersections": result.intersecting_elements.nb_issues(),
    }


def opengeode_part(scene: Scene, ours: geobrep.InspectionReport, libraries: Any) -> None:
    og, oi, _ = libraries
    folder = Path(tempfile.mkdtemp())
    meshes = []
    for surface in scene.surfaces:
        path = folder / f"{surface.name}.ts"
        geobrep.write(surface, path)
        meshes.append(og.load_triangulated_surface3D(str(path)))
    results = side_by_side(scene, meshes, oi, max(RUNS, 5) if not QUICK else 1)
    theirs: dict[str, int] = {}
    for result in results:
        for name, count in _surface_counts(result).items():
            theirs[name] = theirs.get(name, 0) + count
    reasons = {
        "degenerate_elements": "geobrep: slivers whose height is within the tolerance; "
        "OpenGeode: its own epsilon",
        "inconsistent_orientation": "OpenGeode counts each wrong polygon edge from both "
        "sides (a flipped triangle: 6), geobrep the faces to flip",
        "self_intersections": "OpenGeode also lists the triangles that touch at each "
        "duplicated vertex (5 per vertex here: no shared index); geobrep welds within the "
        "tolerance first and reports those once, as colocated vertices",
    }
    print(f"  {'criterion':<26} {'geobrep':>8} {'OpenGeode':>10}")
    counts = ours.counts()
    for name, count in theirs.items():
        note = "" if counts.get(name, 0) == count else f"   ({reasons.get(name, 'differs')})"
        print(f"  {name:<26} {counts.get(name, 0):>8} {count:>10}{note}")


def _nb(result: Any, depth: int = 0) -> int:
    """Issues of an OpenGeode result: its own count, else its parts' counts added up."""
    if hasattr(result, "nb_issues"):
        return int(result.nb_issues())
    if depth > 4:
        return 0
    parts = [getattr(result, n) for n in dir(result) if not n.startswith("_")]
    return sum(_nb(p, depth + 1) for p in parts if not callable(p) and not isinstance(p, str))


def models_part(libraries: Any) -> None:
    _, oi, geosciences = libraries
    print("Model3d files (read as written), issues per family:")
    for path in sorted(DATA.glob("*.ml")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = geobrep.read(path, repair=False)
        ours = geobrep.inspect(scene)
        wall_ours = ours.seconds
        try:
            model = geosciences.load_structural_model(str(path))
        except Exception as exc:
            print(f"  {path.name}: OpenGeode cannot load it ({exc})")
            continue
        begin = time.perf_counter()
        result = oi.BRepInspector(model).inspect_brep()
        wall_theirs = time.perf_counter() - begin
        meshes, topology = result.meshes, result.topology
        theirs = {
            "colocation": _nb(meshes.meshes_colocation),
            "degeneration": _nb(meshes.meshes_degenerations),
            "adjacency": _nb(meshes.meshes_adjacencies),
            "manifold": _nb(meshes.meshes_non_manifolds),
            "intersections": _nb(meshes.meshes_intersections),
            "topology": _nb(topology),
        }
        families: dict[str, int] = {}
        for section in ours.sections:
            families[section.family] = families.get(section.family, 0) + section.count
        mine = {k: v for k, v in families.items() if v}
        print(
            f"  {path.name}: geobrep {mine or 'clean'} in {wall_ours:.2f} s; "
            f"OpenGeode {({k: v for k, v in theirs.items() if v}) or 'clean'} in "
            f"{wall_theirs:.2f} s"
        )


def main() -> None:
    n = 120 if QUICK else 354
    scene = Scene(
        entities=[
            with_defects(horizon(n, 0.0, "h1")),
            horizon(n, 100.0, "h2"),
            horizon(n, 200.0, "h3"),
            horizon(n, 300.0, "h4"),
        ]
    )
    report = geobrep_part(scene)
    expected = {
        "colocated_vertices": 10,
        "degenerate_elements": 10,
        "inconsistent_orientation": 10,
        "self_intersections": 5,
    }
    for name, count in expected.items():
        found = report.section(name).count
        print(f"  injected {name}: {count}, found {found}{'' if found == count else '  <-- !'}")
    libraries = _og()
    if libraries is not None:
        opengeode_part(scene, report, libraries)
        models_part(libraries)


if __name__ == "__main__":
    main()
