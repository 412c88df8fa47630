"""Mutated grid and well files (generated: a rotated Voxet with a big-endian float property and
no-data values, a curvilinear SGrid with point, cell and flag files, a deviated well with
markers, a faulted corner-point grid, a deviation table, LAS logs, a GOCAD group holding a
Voxet, an SGrid, a Well and a point set)
read as a scene or fail with the reader's own FormatError, never another exception or
``geobrep.read``'s catch-all ("<format> reader failed: ...")."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_formats_grdecl import faulted_grid

import geobrep
from geobrep import (
    PointSet,
    Property,
    RegularGrid,
    Scene,
    StructuredGrid,
    Well,
    WellLog,
    WellMarker,
    WellZone,
)
from geobrep.geometry.trajectory import minimum_curvature


def _rotated_voxet() -> RegularGrid:
    values = np.linspace(0.0, 1.0, 4 * 3 * 3, dtype=np.float32)
    values[5] = -99999.0
    return RegularGrid(
        name="v",
        origin=[10.0, 20.0, -30.0],
        u=[1.5, 0.5, 0.0],
        v=[-0.5, 1.5, 0.0],
        w=[0.0, 0.25, 2.0],
        counts=(3, 2, 2),
        point_data={"p": Property(values=values, no_data_value=-99999.0)},
    )


def _well() -> Well:
    md = np.arange(0.0, 501.0, 50.0)
    xyz = np.array([1000.0, 2000.0, 50.0]) + minimum_curvature(
        md, np.minimum(md / 10, 30), md * 0 + 120
    )
    return Well(
        name="w",
        head=xyz[0],
        vertices=xyz,
        md=md,
        markers=(WellMarker(name="m", md=275.0),),
        zones=(WellZone(name="z", top_md=100.0, base_md=275.0),),
    )


def _logs() -> dict[str, WellLog]:
    md = np.linspace(100.0, 110.0, 21)
    gr = np.cos(md) * 40.0 + 60.0
    gr[3] = -999.25
    return {"GR": WellLog(md=md, values=gr, unit="API", no_data_value=-999.25)}


def _sgrid() -> StructuredGrid:
    k, j, i = np.meshgrid(np.arange(3), np.arange(3), np.arange(4), indexing="ij")
    points = np.stack([i * 10.0 + j, j * 20.0, k * 5.0 + 0.5 * i], axis=-1).reshape(-1, 3)
    return StructuredGrid(
        name="s",
        counts=(3, 2, 2),
        points=points,
        point_data={
            "phi": Property(values=np.linspace(0, 1, 36, dtype=np.float32), no_data_value=-1.0),
            "sgrid_flags": Property(values=np.arange(36, dtype=np.int32) % 3),
        },
        cell_data={"facies": Property(values=np.arange(12, dtype=np.int16))},
    )


def _files(folder: Path) -> dict[str, list[Path]]:
    """Each generated file and its side files (mutated too)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vo = geobrep.write(Scene(entities=[_rotated_voxet()]), folder / "v.vo")
        wl = geobrep.write(Scene(entities=[_well()]), folder / "w.wl")
        grdecl = geobrep.write(faulted_grid(), folder / "g.grdecl")
        dev = geobrep.write(_well().replace(markers=(), zones=()), folder / "w.dev")
        sg = geobrep.write(_sgrid(), folder / "s.sg")
        las = geobrep.write(_well().replace(logs=_logs()), folder / "w.las")
        members = [_rotated_voxet(), _sgrid(), _well(), PointSet(vertices=[[0.0, 1.0, 2.0]])]
        gp = geobrep.write(Scene(entities=members), folder / "m.gp")
    sides = sorted(folder.glob("s__*@@"))
    return {
        "v.vo": [vo, folder / "v__p@@"],
        "s.sg": [sg, *sides],
        "w.wl": [wl],
        "g.grdecl": [grdecl],
        "w.dev": [dev],
        "w.las": [las],
        "m.gp": [gp, *sorted(folder.glob("m_*@@"))],
    }


@pytest.fixture(scope="module")
def originals(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[str, bytes]]]:
    folder = tmp_path_factory.mktemp("originals")
    return {key: [(p.name, p.read_bytes()) for p in paths] for key, paths in _files(folder).items()}


TOKENS = [b"", b"x", b"-1", b"0", b"1e999", b"nan", b"99999999999", b"/", b"4*", b"*", b'"', b"END"]
mutation = st.one_of(
    st.tuples(st.just("drop line"), st.integers(0, 10_000)),
    st.tuples(st.just("duplicate line"), st.integers(0, 10_000)),
    st.tuples(st.just("token"), st.integers(0, 10_000), st.integers(0, 8), st.sampled_from(TOKENS)),
    st.tuples(st.just("truncate"), st.integers(0, 100_000)),
)


def _mutate(data: bytes, steps: list[tuple[object, ...]]) -> bytes:
    lines = data.split(b"\n")
    for kind, *args in steps:
        if kind == "truncate":
            text = b"\n".join(lines)
            lines = text[: int(args[0]) % (len(text) + 1)].split(b"\n")  # type: ignore[call-overload]
            continue
        at = int(args[0]) % len(lines)  # type: ignore[call-overload]
        if kind == "drop line" and len(lines) > 1:
            del lines[at]
        elif kind == "duplicate line":
            lines.insert(at, lines[at])
        elif kind == "token":
            tokens = lines[at].split(b" ")
            tokens[int(args[1]) % len(tokens)] = args[2]  # type: ignore[call-overload, assignment]
            lines[at] = b" ".join(tokens)
    return b"\n".join(lines)


def _read_or_error(path: Path) -> geobrep.FormatError | None:
    """None when ``path`` reads, else the FormatError raised (any other exception fails)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            geobrep.read(path)
    except geobrep.FormatError as error:
        return error
    return None


@settings(
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    st.sampled_from(["v.vo", "s.sg", "w.wl", "g.grdecl", "w.dev", "w.las", "m.gp"]),
    st.integers(0, 4),
    st.lists(mutation, min_size=1, max_size=4),
)
def test_a_mutated_grid_or_well_reads_or_fails_with_a_format_error(
    originals: dict[str, list[tuple[str, bytes]]],
    tmp_path_factory: pytest.TempPathFactory,
    key: str,
    which: int,
    steps: list[tuple[object, ...]],
) -> None:
    folder = tmp_path_factory.mktemp("mutated")
    files = originals[key]
    target = which % len(files)  # the header, or one of its binary side files
    for index, (name, data) in enumerate(files):
        (folder / name).write_bytes(_mutate(data, steps) if index == target else data)
    error = _read_or_error(folder / files[0][0])
    if error is not None:
        assert " reader failed: " not in error.message, error.message
        assert error.path is not None
