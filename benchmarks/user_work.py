"""The work users feel (issue 17): every row with geobrep's figure, the anchor's and the ratio.

Run: ``.venv/bin/python benchmarks/user_work.py [--repeat 5] [--only startup,model3d,...]
[--big 10000000]`` (``make bench`` runs it first). Sections: ``startup``, ``model3d``,
``blocks``, ``batch``, ``memory``.

Definitions (the issue's): a **whole-process** time is the median of ``--repeat`` runs of a
command after one warm-up run; **warm** is the median of ``--repeat`` calls in one process after
a first call; **cold** is the first call in a fresh process after ``import geobrep`` (the
import excluded). Ratios are geobrep ÷ anchor in the same run, best and median. The anchors
come from the ``bench`` extra: meshio, OpenGeode-GeosciencesIO (run in a child process, which
a crash of it cannot take down), libigl (GPL: a comparison only) and dask[distributed].
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DATA = ROOT / "tests" / "data" / "gocad"
BIN = Path(sys.executable).parent
# _inputs.py lives beside this file (no script here is named after a standard module, so the
# folder may stand anywhere on sys.path)
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != HERE]
sys.path.append(str(HERE))

Times = list[float]


# --------------------------------------------------------------------------- reporting
def row(
    work: str, ours: Times | None, anchor_name: str, theirs: Times | None, note: str = ""
) -> None:
    """One line: geobrep best/median, the anchor's, and both ratios."""

    def figure(times: Times | None) -> str:
        if not times:
            return "            —        "
        return f"{_ms(min(times))} / {_ms(statistics.median(times))}"

    ratio = "   —   "
    if ours and theirs:
        best = min(ours) / min(theirs)
        median = statistics.median(ours) / statistics.median(theirs)
        ratio = f"{best:5.2f}× / {median:5.2f}×"
    print(f"  {work:<52} {figure(ours)}  {anchor_name:<30} {figure(theirs)}  {ratio}  {note}")


def header(title: str) -> None:
    print(f"\n{title}")
    print(
        f"  {'work':<52} {'geobrep best / median':<21}  {'anchor':<30} "
        f"{'best / median':<21}  ratio best / median"
    )


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:8.1f} ms" if seconds < 10 else f"{seconds:8.2f} s "


def calls(function: Callable[[], Any], repeat: int, warm_up: bool = True) -> Times:
    """Wall-clock seconds of ``repeat`` calls (after one uncounted call when ``warm_up``)."""
    if warm_up:
        function()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return times


def interleaved(
    functions: dict[str, Callable[[], Any]], repeat: int, cpu: dict[str, Times] | None = None
) -> dict[str, Times]:
    """Wall-clock seconds of ``repeat`` rounds that call each function once, in turn (after
    one uncounted call of each): a shared machine's load falls on all of them alike. ``cpu``,
    when given, receives the CPU seconds of the same calls."""
    for function in functions.values():
        function()
    times: dict[str, Times] = {name: [] for name in functions}
    for _ in range(repeat):
        for name, function in functions.items():
            start, cpu_start = time.perf_counter(), time.process_time()
            function()
            times[name].append(time.perf_counter() - start)
            if cpu is not None:
                cpu.setdefault(name, []).append(time.process_time() - cpu_start)
    return times


#: The environment of the measured commands: bytecode is written (the warm-up run caches the
#: .pyc files an installed package has; PYTHONDONTWRITEBYTECODE would recompile every run).
ENV = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}


def whole_process(command: Sequence[str], repeat: int) -> Times:
    """Seconds of ``repeat`` runs of ``command`` after one warm-up run (output discarded)."""

    def run() -> None:
        subprocess.run(
            command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV
        )

    return calls(run, repeat)


def child(code: str, *args: str) -> Any:
    """Run ``code`` in a fresh interpreter; it prints one JSON value last. None if it died.
    It runs in :data:`ENV` (bytecode written), as an installed package would: with
    PYTHONDONTWRITEBYTECODE a module edited since its .pyc was written is compiled again in
    every process, which a first read would be charged for."""
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code), *args],
        capture_output=True,
        text=True,
        check=False,
        env=ENV,
    )
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        return None
    return json.loads(lines[-1])


# --------------------------------------------------------------------------- 1. start-up
#: A whole process that imports numpy and pydantic and validates one model: the floor under any
#: ``geobrep info`` (the scene graph is pydantic models), run in the same environment.
_FLOOR_PROCESS = """import numpy, pydantic
class Probe(pydantic.BaseModel):
    value: int
Probe(value=1)
"""


def startup(repeat: int, folder: Path) -> None:
    import meshio
    import numpy as np

    header("1. start-up (whole process)")
    vtu = folder / "three.vtu"
    meshio.write(
        vtu,
        meshio.Mesh(
            np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), [("triangle", np.array([[0, 1, 2]]))]
        ),
    )
    python = [sys.executable, "-c"]
    meshio_info = whole_process([str(BIN / "meshio"), "info", str(vtu)], repeat)
    row(
        "python -c 'import geobrep'",
        whole_process([*python, "import geobrep"], repeat),
        "python -c 'import meshio'",
        whole_process([*python, "import meshio"], repeat),
    )
    row(
        "geobrep info (3-vertex .vtu)",
        whole_process([str(BIN / "geobrep"), "info", str(vtu)], repeat),
        "meshio info (same .vtu)",
        meshio_info,
    )
    row(
        "geobrep --help",
        whole_process([str(BIN / "geobrep"), "--help"], repeat),
        "meshio info (same .vtu)",
        meshio_info,
    )
    floor = folder / "floor.py"
    floor.write_text(_FLOOR_PROCESS)
    row(
        "floor: python + numpy + pydantic + one model",
        whole_process([sys.executable, str(floor)], repeat),
        "meshio info (same .vtu)",
        meshio_info,
        "(what any geobrep read pays first)",
    )
    row(
        "python + numpy + pydantic's BaseModel, imported",
        whole_process([*python, "import numpy; from pydantic import BaseModel"], repeat),
        "meshio info (same .vtu)",
        meshio_info,
        "(the imports alone, no model)",
    )
    ts = DATA / "2triangles.ts"
    row(
        "geobrep info (2-triangle .ts)",
        whole_process([str(BIN / "geobrep"), "info", str(ts)], repeat),
        "meshio info (3-vertex .vtu)",
        meshio_info,
    )
    loaded = child(
        """
        import json, sys, warnings
        warnings.simplefilter("ignore")
        import geobrep
        geobrep.read(sys.argv[1])
        heavy = ("geobrep.plugins.blocks._builder", "geobrep.plugins.clip._", "scipy", "pyproj",
                 "geobrep.model.entities.nurbs", "geobrep.model.entities.octree")
        print(json.dumps([h for h in heavy if any(m.startswith(h) for m in sys.modules)]))
        """,
        str(ts),
    )
    print(f"  reading a .ts loads: {', '.join(loaded or []) or 'none of the heavy modules'}")


# --------------------------------------------------------------------------- 2. Model3d
_GEOBREP_TIMES = """
    import json, sys, time, warnings
    warnings.simplefilter("ignore")
    import geobrep
    path, repeat = sys.argv[1], int(sys.argv[2])
    start, cpu = time.perf_counter(), time.process_time()
    geobrep.read(path)
    cold, cold_cpu = time.perf_counter() - start, time.process_time() - cpu
    warm, warm_cpu = [], []
    for _ in range(repeat):
        start, cpu = time.perf_counter(), time.process_time()
        geobrep.read(path)
        warm.append(time.perf_counter() - start); warm_cpu.append(time.process_time() - cpu)
    print(json.dumps({"cold": cold, "warm": warm, "cold_cpu": cold_cpu, "warm_cpu": warm_cpu}))
"""

#: What any first read pays before geobrep's own work: numpy, pydantic, and pydantic's first
#: schema (which imports importlib.metadata to look for pydantic plugins).
_FLOOR_TIMES = """
    import json, time
    import geobrep
    start, cpu = time.perf_counter(), time.process_time()
    import numpy, pydantic
    class Probe(pydantic.BaseModel):
        value: int
    Probe(value=1)
    print(json.dumps({"cold": time.perf_counter() - start, "cold_cpu": time.process_time() - cpu}))
"""

_OPENGEODE_TIMES = """
    import json, sys, time
    import opengeode, opengeode_geosciences, opengeode_geosciencesio
    opengeode_geosciencesio.OpenGeodeGeosciencesIOModelLibrary.initialize()
    opengeode.Logger.set_level(opengeode.Logger.LEVEL.critical)
    path, repeat = sys.argv[1], int(sys.argv[2])
    start = time.perf_counter(); opengeode_geosciences.load_structural_model(path)
    cold = time.perf_counter() - start
    warm = []
    for _ in range(repeat):
        start = time.perf_counter(); opengeode_geosciences.load_structural_model(path)
        warm.append(time.perf_counter() - start)
    print(json.dumps({"cold": cold, "warm": warm}))
"""


def model3d(repeat: int, folder: Path) -> None:
    from _inputs import model3d_files

    header("2. Model3d reads (warm: one process; cold: first read in a fresh process − warm)")
    files = [DATA / "modelA1.ml", DATA / "modelA4.ml", *model3d_files(folder)]
    child(_FLOOR_TIMES)  # writes the .pyc files a first run after an edit lacks
    floors = [child(_FLOOR_TIMES) for _ in range(repeat)]
    if all(floors):
        print(
            "      floor of any first read (numpy, pydantic, a first model): "
            f"{_best_median([f['cold'] for f in floors])} wall, "
            f"{_best_median([f['cold_cpu'] for f in floors])} CPU"
        )
    for path in files:
        scene = _quiet_read(path)
        label = f"{path.name} ({path.stat().st_size / 1e6:.1f} MB, {len(scene.patches)} patches)"
        child(_GEOBREP_TIMES, str(path), "1")  # writes the .pyc files, uncounted
        runs = [child(_GEOBREP_TIMES, str(path), str(repeat)) for _ in range(repeat)]
        ours = runs[0] if all(runs) else None
        theirs = child(_OPENGEODE_TIMES, str(path), str(repeat))
        note = "" if theirs else "(OpenGeode failed or crashed on this file)"
        row(
            f"warm read {label}",
            ours and ours["warm"],
            "OpenGeode-GeosciencesIO",
            theirs and theirs["warm"],
            note,
        )
        if ours:
            wall = [r["cold"] - statistics.median(r["warm"]) for r in runs]
            cpu = [r["cold_cpu"] - statistics.median(r["warm_cpu"]) for r in runs]
            print(
                f"      cold over warm ({len(runs)} fresh processes): {_best_median(wall)} wall, "
                f"{_best_median(cpu)} CPU (target ≤ 0.2 s)"
            )


def _best_median(times: Times) -> str:
    return f"{min(times):.3f} / {statistics.median(times):.3f} s"


def _quiet_read(path: Path) -> Any:
    import geobrep

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.read(path)


# --------------------------------------------------------------------------- 3. blocks
def blocks(repeat: int, quick: bool) -> None:
    import numpy as np
    from blocks import welded_soup

    import geobrep

    header("3. build_blocks (geobrep: surfaces as they come; libigl: consistently oriented soup)")
    try:
        from igl.copyleft import cgal
    except ImportError:
        cgal = None
    rng = np.random.default_rng(17)
    cases = [("~20k", 23.0), ("~100k", 10.0), ("~1M", 3.2 * np.sqrt(927_872 / 1_000_000))]
    for label, resolution in cases[:1] if quick else cases:
        truth = geobrep.datasets.faulted_layer_cake(n_horizons=2, resolution=resolution)
        # As they come: about half the surfaces reversed, as a modeller's export leaves them.
        surfaces = [
            s.replace(faces=s.faces[:, ::-1].copy()) if rng.random() < 0.5 else s
            for s in truth.surfaces
        ]
        as_they_come = geobrep.Scene(entities=surfaces, crs=truth.crs)
        oriented = geobrep.Scene(entities=truth.surfaces, crs=truth.crs)
        n = sum(s.n_faces for s in surfaces)
        runs = repeat if n < 500_000 else max(5, repeat // 2)
        work: dict[str, Callable[[], Any]] = {
            "default": lambda s=as_they_come: geobrep.build_blocks(s),
            "bare": lambda s=as_they_come: geobrep.build_blocks(
                s, check_conformity=False, validate=False
            ),
        }
        if cgal is not None:
            vertices, welded = welded_soup(oriented)
            work["anchor"] = lambda v=vertices, w=welded: cgal.extract_cells(v, w)
        cpu: dict[str, Times] = {}
        times = interleaved(work, runs, cpu)
        for clock, measured in (("wall", times), ("CPU", cpu)):
            default, bare, anchor = measured["default"], measured["bare"], measured.get("anchor")
            row(
                f"build_blocks default, {label} ({n:,} tri), {clock}",
                default,
                "libigl extract_cells",
                anchor,
            )
            row(
                f"build_blocks bare (checks off), {label}, {clock}",
                bare,
                "libigl extract_cells",
                anchor,
            )


# --------------------------------------------------------------------------- 4. batches
def batch(count: int, folder: Path) -> None:
    import meshio
    from _inputs import small_gocad_files

    import geobrep

    header(f"4. batch: {count} small GOCAD files (1–100 kB) → .vtu (files/s; higher is better)")
    ts_files, vtu_files = small_gocad_files(folder / "small", count)
    out = folder / "out"

    def cpu_of_children() -> float:
        usage = os.times()
        return usage.children_user + usage.children_system

    def convert(jobs: int, files: list[Path]) -> tuple[float, float]:
        target = out / f"jobs{jobs}_{len(files)}"
        target.mkdir(parents=True, exist_ok=True)
        command = [
            str(BIN / "geobrep"),
            "convert",
            *map(str, files),
            "--to",
            "vtu",
            "-o",
            str(target),
            "--jobs",
            str(jobs),
            "--no-progress",
            "-q",
        ]
        cpu, start = cpu_of_children(), time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, env=ENV)
        return time.perf_counter() - start, cpu_of_children() - cpu

    def loop(
        read: Callable[[Path], Any],
        write: Callable[[Any, Path], None],
        files: list[Path],
        suffix: str,
    ) -> tuple[float, float]:
        target = out / f"loop{suffix}"
        target.mkdir(parents=True, exist_ok=True)
        cpu, start = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for path in files:
                write(read(path), target / f"{path.stem}.vtu")
        return time.perf_counter() - start, time.process_time() - cpu

    def dask_cluster() -> float | None:
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            return None
        target = out / "dask"
        with (
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster,
            Client(cluster) as client,
        ):
            geobrep.convert(ts_files[:4], to="vtu", out_dir=target, client=client)  # warm-up
            start = time.perf_counter()
            geobrep.convert(ts_files, to="vtu", out_dir=target, client=client)
            return time.perf_counter() - start

    convert(2, ts_files)  # warm-up (page cache, .pyc)
    wall2, cpu2 = convert(2, ts_files)
    wall1, cpu1 = convert(1, ts_files)
    few = 20  # the fixed cost (start-up, plugin discovery) of a run, to take off per file
    _, fixed_cpu = convert(1, ts_files[:few])
    per_file = (cpu1 - fixed_cpu) / (count - few)
    meshio_wall, _ = loop(meshio.read, lambda m, p: meshio.write(p, m), vtu_files, "meshio")
    format_wall, format_cpu = loop(geobrep.read, geobrep.write, ts_files, "geobrep")
    dask_wall = dask_cluster()
    executor = _executor_overhead(ts_files[:200], out / "executor")
    rate = lambda wall: f"{count / wall:8.0f} files/s"  # noqa: E731
    print(f"  geobrep convert --jobs 2            {rate(wall2)}  ({wall2:.2f} s, {cpu2:.2f} s CPU)")
    print(f"  geobrep convert --jobs 1            {rate(wall1)}  ({wall1:.2f} s, {cpu1:.2f} s CPU)")
    print(f"  plain loop: meshio read → write     {rate(meshio_wall)}  (.vtu inputs, one process)")
    print(
        f"  plain loop: geobrep read → write    {rate(format_wall)}  "
        f"(the format work, {format_cpu:.2f} s CPU)"
    )
    if dask_wall is not None:
        print(f"  geobrep.convert on a Dask LocalCluster (2 workers) {rate(dask_wall)}")
    print(
        f"  files/s, convert --jobs 2 ÷ meshio loop: {meshio_wall / wall2:5.2f}× "
        f"(--jobs 1: {meshio_wall / wall1:5.2f}×); CPU per file: convert --jobs 1 "
        f"{per_file * 1e3:.2f} ms (a {few}-file run's {fixed_cpu:.2f} s start-up taken off), "
        f"the format work {format_cpu / count * 1e3:.2f} ms: overhead "
        f"{100 * (per_file * count / format_cpu - 1):+.0f} % (target ≤ 20 %)"
    )
    best, median = executor
    print(
        f"  executor overhead in one process (geobrep.convert ÷ a geobrep read → write loop, "
        f"{len(ts_files[:200])} files, CPU, 5 runs each, alternating): best {best:+.0f} %, "
        f"median {median:+.0f} % (target ≤ 20 %)"
    )


def _executor_overhead(files: list[Path], target: Path) -> tuple[float, float]:
    """CPU of ``geobrep.convert`` over a plain read → write loop of the same files, in this
    process (no start-up, no worker): best and median of 5 alternating runs, in per cent."""
    import geobrep

    target.mkdir(parents=True, exist_ok=True)

    def loop() -> None:
        for path in files:
            geobrep.write(geobrep.read(path), target / f"{path.stem}.vtu")

    def convert() -> None:
        geobrep.convert(files, to="vtu", out_dir=target / "convert")

    plain: Times = []
    executor: Times = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loop(), convert()
        for _ in range(5):
            for work, times in ((loop, plain), (convert, executor)):
                start = time.process_time()
                work()
                times.append(time.process_time() - start)
    return (
        100 * (min(executor) / min(plain) - 1),
        100 * (statistics.median(executor) / statistics.median(plain) - 1),
    )


# --------------------------------------------------------------------------- 5. memory
_MEMORY = """
    import json, sys, time, warnings
    from pathlib import Path
    warnings.simplefilter("ignore")
    import geobrep

    def rss(field):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(field):
                return int(line.split()[1]) * 1024
        return 0

    path, work, out = sys.argv[1], sys.argv[2], sys.argv[3]
    if work == "convert":
        import geobrep.adapters.meshio, geobrep.adapters.native, meshio  # imports are not the work
        scene = None
    else:
        scene = geobrep.read(path)
    Path("/proc/self/clear_refs").write_text("5")  # the peak starts again from here
    base = rss("VmRSS:")
    start = time.perf_counter()
    if work == "clip":
        geobrep.clip(scene, geobrep.Plane(1.0, 0.2, 0.1, -100.0))
    elif work == "voxelize":
        geobrep.voxelize(scene, depth=9)
    else:
        geobrep.convert(path, out)
    seconds = time.perf_counter() - start
    print(json.dumps({"seconds": seconds, "base": base, "peak": rss("VmHWM:")}))
"""


def memory(n_triangles: int, folder: Path) -> None:
    from _inputs import big_surface

    import geobrep

    surface = big_surface(n_triangles)
    size = surface.vertices.nbytes + surface.faces.nbytes
    path = folder / "big.geobrep"
    geobrep.write(geobrep.Scene(entities=[surface]), path)
    del surface
    print(
        f"\n5. memory: {n_triangles:,}-triangle surface from .geobrep (input arrays "
        f"{size / 1e6:,.0f} MB); peak RSS over the RSS after loading (convert: before the call)"
    )
    for work in ("clip", "convert", "voxelize"):
        found = child(_MEMORY, str(path), work, str(folder / "big.vtu"))
        if found is None:
            print(f"  {work:<9} failed")
            continue
        over = (found["peak"] - found["base"]) / size
        print(
            f"  {work:<9} {found['seconds']:7.2f} s   peak over base "
            f"{(found['peak'] - found['base']) / 1e6:8,.0f} MB = {over:4.2f}× the input "
            "(target ≤ 3×)"
        )


# --------------------------------------------------------------------------- main
SECTIONS = ("startup", "model3d", "blocks", "batch", "memory")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per figure (≥ 5)")
    parser.add_argument("--only", default=",".join(SECTIONS), help="comma-separated sections")
    parser.add_argument("--files", type=int, default=2000, help="files in the batch")
    parser.add_argument("--big", type=int, default=10_000_000, help="triangles of the memory run")
    parser.add_argument("--quick", action="store_true", help="the smallest block case only")
    args = parser.parse_args()
    wanted = set(args.only.split(","))
    folder = Path(os.environ.get("GEOBREP_BENCH_DIR") or tempfile.mkdtemp(prefix="geobrep-bench-"))
    folder.mkdir(parents=True, exist_ok=True)
    print(f"issue 17 figures, {args.repeat} runs each (inputs in {folder})")
    if "startup" in wanted:
        startup(args.repeat, folder)
    if "model3d" in wanted:
        model3d(args.repeat, folder)
    if "blocks" in wanted:
        blocks(args.repeat, args.quick)
    if "batch" in wanted:
        batch(args.files, folder)
    if "memory" in wanted:
        memory(args.big, folder)


if __name__ == "__main__":
    main()
