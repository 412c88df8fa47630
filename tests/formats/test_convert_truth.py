"""Conversion summaries tell the truth: every file of tests/data, every format, read back.

For every file under tests/data that a reader accepts (discovered, not listed: others add files)
and every writable, readable format that can hold something of it, the file is converted with
:func:`geobrep.convert` and the result read back. What the summary does not list as lost must be
there (entity count and types, vertex and cell counts, names, ids, property names, blocks); what
it lists as lost is the only thing missing.
"""

from __future__ import annotations

import re
import time
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from geobrep.batch.conversion import convert
from geobrep.errors import GeobrepError
from geobrep.host.capabilities import has_geometry
from geobrep.host.registry import FormatCapabilities
from geobrep.model.entities import Entity
from geobrep.model.scene import Scene
from geobrep.ops.io import read
from geobrep.plugins import registries

DATA = Path(__file__).resolve().parents[1] / "data"

#: The GOCAD format writes one object type per extension: each is a target of its own.
GOCAD_TARGETS = {
    ".ts": {"Surface"},
    ".pl": {"PolyLine"},
    ".vs": {"PointSet"},
    ".so": {"TetMesh"},
    ".ml": {"Surface"},
    ".gp": {"Surface", "PolyLine", "PointSet", "TetMesh", "RegularGrid", "StructuredGrid", "Well"},
}

#: Files with this many vertices or more go to a subset of the formats (the whole test < 60 s).
BIG = 200_000
#: The formats of a big file: the exact whole-scene ones (the others write the same arrays).
BIG_FORMATS = {"vtu", "native", "gocad"}


@dataclass
class Tally:
    """What the test did: pairs converted, read back, and the mismatches found."""

    converted: int = 0
    read_back: int = 0
    failed: list[str] = field(default_factory=list)
    mismatches: list[str] = field(default_factory=list)


def _sources() -> list[tuple[Path, Scene]]:
    found = []
    for path in sorted(p for p in DATA.rglob("*") if p.is_file()):
        if path.suffix.lower() in (".md", ".txt") or path.name.startswith("."):
            continue
        if path.relative_to(DATA).parts[0] == "reliability":
            continue  # attack and fuzz reproducers: tests/reliability holds them to their own rules
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                scene = read(path)
        except GeobrepError:
            continue  # not a file any reader accepts (a sidecar, a raw grid)
        found.append((path, scene))
    return found


def _targets(scene: Scene) -> list[tuple[str, str, FormatCapabilities]]:
    """(format, extension, capabilities) of every target that holds something of ``scene``."""
    types = {e.type for e in scene.entities}
    targets = []
    for spec in registries().formats:
        if not (spec.can_write and spec.can_read):
            continue  # a picture cannot be read back
        if spec.name == "gocad":
            for ext, held in GOCAD_TARGETS.items():
                if types & held:
                    also = {".ml": {"Block"}, ".so": {"Surface"}}.get(ext, set())
                    kinds = frozenset(held | also)  # .so: the SURFACEs of a TSolid's MODEL
                    caps = spec.capabilities.model_copy(update={"entity_types": kinds})
                    targets.append((spec.name, ext, caps))
        elif types & spec.capabilities.entity_types:
            targets.append((spec.name, spec.extensions[0], spec.capabilities))
    return targets


def _cells(entity: Entity) -> int:
    for name in ("faces", "cells", "segments"):
        if hasattr(entity, name):
            return int(getattr(entity, name).shape[0])
    return 0


def _said(lost: tuple[str, ...], pattern: str) -> bool:
    return any(re.search(pattern, item) for item in lost)


def check(source: Scene, back: Scene, lost: tuple[str, ...], caps: FormatCapabilities) -> list[str]:
    """What ``back`` lacks (or has more) that ``lost`` does not explain; empty when truthful."""
    problems: list[str] = []
    kept: list[Entity] = []
    for entity in source.entities:
        if entity.type not in caps.entity_types:
            continue
        if not has_geometry(entity) and _said(lost, f"without geometry dropped: .*{entity.label}"):
            continue  # said dropped: must not come back (checked by the counts below)
        if _said(lost, rf"^{re.escape(entity.label)}: only the first well is written$"):
            continue  # a format of one well: the others are said not written
        kept.append(entity)
    types = Counter(e.type for e in source.entities)
    for type_name, count in types.items():
        if type_name not in caps.entity_types:
            if not _said(lost, rf"{count} {type_name} entities dropped"):
                problems.append(f"{count} {type_name} dropped, not reported")
            if any(e.type == type_name for e in back.entities):
                problems.append(f"{type_name} said dropped but read back")
    for item in source.metadata.get("skipped_on_read", ()):
        if not _said(lost, re.escape(str(item))):
            problems.append(f"skipped on read, not reported: {item}")
    if _said(lost, "merged into one"):
        if len(back.entities) != 1:
            problems.append(f"merged: {len(back.entities)} entities came back")
        cells = sum(_cells(e) for e in kept)
        if back.entities and _cells(back.entities[0]) != cells:
            problems.append(f"merged: {_cells(back.entities[0])} cells, expected {cells}")
        return problems
    mesh_back = [e for e in back.entities if e.type in caps.entity_types]
    extra = [e.label for e in back.entities if e.type not in caps.entity_types]
    if extra:
        problems.append(f"entities not in the source came back: {extra}")
    got = [(e.type) for e in mesh_back]
    want = [(e.type) for e in kept]
    if sorted(got) != sorted(want):
        problems.append(f"entities {Counter(got)} came back, expected {Counter(want)}")
        return problems
    order = {t: [e for e in mesh_back if e.type == t] for t in set(got)}
    names_lost = _said(lost, "names of")
    ids_lost = _said(lost, "ids of")
    point_lost = _said(lost, "point properties dropped")
    cell_lost = _said(lost, "cell properties dropped")
    seen: Counter[str] = Counter()
    for entity in kept:
        other = order[entity.type][seen[entity.type]]
        seen[entity.type] += 1
        where = entity.label
        if entity.type != "Block":
            if other.n_points != entity.n_points and not _said(
                lost, rf"^{re.escape(where)}: .*\b{other.n_points} points read back\b"
            ):
                problems.append(f"{where}: {other.n_points} points, expected {entity.n_points}")
            if _cells(other) != _cells(entity):
                problems.append(f"{where}: {_cells(other)} cells, expected {_cells(entity)}")
        if not names_lost and other.name != entity.name:
            problems.append(f"{where}: came back named {other.name!r}")
        if not ids_lost and other.id != entity.id:
            problems.append(f"{where}: came back with id {other.id}")
        for kind, dropped in (("point_data", point_lost), ("cell_data", cell_lost)):
            want_names = set(getattr(entity, kind))
            got_names = set(getattr(other, kind))
            missing = [n for n in want_names - got_names if not _said(lost, re.escape(repr(n)))]
            missing = [n for n in missing if not _said(lost, rf"propert.*\b{re.escape(n)}\b")]
            if not dropped and missing:
                problems.append(f"{where}: {kind} {sorted(missing)} missing")
    topology = caps.topology and source.patches and not _said(lost, "topology")
    if topology and len(back.patches) != len(source.patches):
        problems.append(f"{len(back.patches)} patches came back of {len(source.patches)}")
    return problems


def run_all(out: Path) -> Tally:
    """Convert every source to every target that holds something of it; check each."""
    tally = Tally()
    for path, scene in _sources():
        big = sum(e.n_points for e in scene.entities) >= BIG
        for name, ext, caps in _targets(scene):
            if big and name not in BIG_FORMATS:
                continue
            target = out / f"{path.parent.name}_{path.name}{ext}"
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = convert(path, target, verify=True).reports[0]
            pair = f"{path.relative_to(DATA)} -> {name} ({ext})"
            if report.status == "failed":
                tally.failed.append(f"{pair}: {report.error}")
                continue
            tally.converted += 1
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    back = read(target)
            except GeobrepError as exc:
                tally.mismatches.append(f"{pair}: said converted, cannot be read back: {exc}")
                continue
            tally.read_back += 1
            for problem in check(scene, back, report.lost, caps):
                tally.mismatches.append(f"{pair}: {problem}")
    return tally


def test_every_file_to_every_format_reads_back_as_the_summary_says(tmp_path: Path) -> None:
    started = time.perf_counter()
    tally = run_all(tmp_path)
    seconds = time.perf_counter() - started
    summary = (
        f"{tally.converted} converted, {tally.read_back} read back, "
        f"{len(tally.mismatches)} mismatches, {len(tally.failed)} failed, {seconds:.1f} s"
    )
    assert tally.converted > 50, summary
    assert not [f for f in tally.failed if "verify" in f], "\n".join(tally.failed)
    assert not tally.mismatches, summary + "\n" + "\n".join(tally.mismatches)


GOCAD = DATA / "gocad"


def test_a_header_only_fault_is_reported_lost_and_the_vtu_reads_back(tmp_path: Path) -> None:
    source = read(GOCAD / "header_only_fault.ts")
    assert [e.n_points for e in source.surfaces] == [0, 4]  # F3_fault has no vertices
    report = convert(GOCAD / "header_only_fault.ts", tmp_path / "f.vtu").reports[0]
    assert report.status == "converted"
    assert any("without geometry" in s and "'F3_fault'" in s for s in report.lost), report.lost
    back = read(tmp_path / "f.vtu")  # was: meshio could not read this file: IndexError
    assert [(s.name, s.n_points, s.n_faces) for s in back.surfaces] == [("H1_top", 4, 2)]


def test_a_header_only_fault_is_kept_where_the_format_holds_it(tmp_path: Path) -> None:
    for name in ("f.geobrep", "f.ts"):
        report = convert(GOCAD / "header_only_fault.ts", tmp_path / name, verify=True).reports[0]
        assert report.status == "converted", report
        assert not [s for s in report.lost if "geometry" in s], report.lost
        back = read(tmp_path / name)
        assert [(s.name, s.n_points) for s in back.surfaces] == [("F3_fault", 0), ("H1_top", 4)]


def _unreadable_member(folder: Path) -> Path:
    """voxet_and_tsurf.gp with its Voxet made a GSurf, an object type geobrep has no reader for."""
    path = folder / "gsurf_and_tsurf.gp"
    text = (GOCAD / "voxet_and_tsurf.gp").read_text()
    path.write_text(text.replace("GOCAD Voxet 1", "GOCAD GSurf 1"))
    return path


def test_an_object_the_reader_skips_is_reported_lost(tmp_path: Path) -> None:
    source = _unreadable_member(tmp_path)
    with pytest.warns(UserWarning, match="GSurf"):
        scene = read(source)
    assert scene.metadata["skipped_on_read"] == [
        "GOCAD GSurf 'porosity_grid' (line 6): no reader for this type"
    ]
    for name in ("g.vtu", "g.geobrep"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            report = convert(source, tmp_path / name).reports[0]
        assert report.lost[0] == (
            "skipped on read: GOCAD GSurf 'porosity_grid' (line 6): no reader for this type"
        )
        back = read(tmp_path / name)
        assert [s.name for s in back.surfaces] == ["top"]
        assert "skipped_on_read" not in back.metadata  # it described the source, not this file


def test_a_group_of_unreadable_objects_only_is_an_error_not_an_unreadable_file(
    tmp_path: Path,
) -> None:
    text = _unreadable_member(tmp_path).read_text()
    only = tmp_path / "grids.gp"
    only.write_text(text[: text.index("GOCAD TSurf")] + text[text.index("END_MEMBERS") :])
    for name in ("grids.vtu", "grids.vtk", "grids.msh"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            report = convert(only, tmp_path / name).reports[0]
        assert report.status == "failed", report
        assert "nothing to write" in (report.error or ""), report
        assert not (tmp_path / name).exists()


def test_verify_fails_a_file_whose_report_hides_a_loss(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import geobrep.batch.conversion

    source = GOCAD / "split_cube.ml"
    honest = convert(source, tmp_path / "a.ts", verify=True).reports[0]
    assert honest.status == "converted"
    assert "3 Block entities dropped (a GOCAD TSurf file holds Surface)" in honest.lost
    monkeypatch.setattr(geobrep.batch.conversion, "format_losses", lambda *args: [])
    silent = convert(source, tmp_path / "b.ts").reports[0]
    assert silent.status == "converted"  # without --verify the lie goes unnoticed
    caught = convert(source, tmp_path / "c.ts", verify=True).reports[0]
    assert caught.status == "failed"
    assert "0 Block entities read, 3 written" in (caught.error or ""), caught.error


def test_cli_convert_verify(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from geobrep.cli.main import main

    code = main(["convert", str(GOCAD / "modelA1.ml"), str(tmp_path / "m.vtu"), "--verify"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "5 Block entities dropped" in out


def test_a_pipeline_reports_what_its_reader_skipped_and_its_target_drops(tmp_path: Path) -> None:
    from geobrep.batch.pipeline_run import run_pipeline

    pipeline = {
        "version": 1,
        "inputs": [str(_unreadable_member(tmp_path)), str(GOCAD / "split_cube.ml")],
        "output": str(tmp_path),
        "steps": [{"read": {}}, {"write": {"format": "gocad", "name": "{stem}.ts"}}],
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = run_pipeline(pipeline)
    assert summary.ok, summary
    voxet, cube = (report.lost for report in summary.reports)
    assert "skipped on read: GOCAD GSurf 'porosity_grid'" in " ".join(voxet)
    assert any("3 Block entities dropped (a GOCAD TSurf file" in s for s in cube), cube


if __name__ == "__main__":  # a measurement: python tests/formats/test_convert_truth.py
    import sys
    import tempfile

    tally = run_all(Path(tempfile.mkdtemp()))
    print("\n".join(tally.mismatches))
    print("\n".join("FAILED " + f for f in tally.failed))
    print(
        f"{tally.converted} converted, {tally.read_back} read back, "
        f"{len(tally.mismatches)} mismatches, {len(tally.failed)} failed",
        file=sys.stderr,
    )
