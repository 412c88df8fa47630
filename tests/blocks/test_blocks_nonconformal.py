"""Non-conformal input is a TopologyError that says where — never a wrong block set."""

from __future__ import annotations

import math

import numpy as np
import pytest
from blocks_models import box_model, grid_surface, vertical_fault, wedge_model

from geobrep import Scene, Surface
from geobrep.errors import TopologyError
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks._conformity import (
    NonConformalError,
    point_triangle_distance,
    triangles_intersect,
)
from geobrep.plugins.blocks.report import block_report


def horizontal(name: str, z: float, low: float = 0.0, high: float = 1.0) -> Surface:
    side = np.linspace(low, high, 5)
    xs, ys = np.meshgrid(side, side, indexing="ij")
    return grid_surface(np.stack([xs, ys, np.full_like(xs, z)], axis=-1), name, "horizon")


def defects_of(surfaces: list[Surface], **options: object) -> NonConformalError:
    with pytest.raises(NonConformalError) as caught:
        build_blocks(Scene(entities=surfaces), **options)
    assert isinstance(caught.value, TopologyError)
    return caught.value


def test_t_junctions_are_located() -> None:
    # The walls have no row at z = 0.6: the horizon's border lies on their triangles.
    error = defects_of([*box_model(levels=()), horizontal("H", 0.6)])
    assert {d.kind for d in error.defects} == {"T-junction"}
    walls = {"west", "east", "south", "north"}
    assert all("H" in d.surfaces and set(d.surfaces) - {"H"} <= walls for d in error.defects)
    on_border = [d for d in error.defects if d.surfaces[0] == "H"]
    assert on_border
    assert all(d.point[2] == pytest.approx(0.6) for d in on_border)
    assert "T-junction of" in str(error)
    assert "0.600)" in str(error)


def test_crossing_surfaces_are_located() -> None:
    # A fault at x = 0.6 shares no vertex with H1 (whose columns are at multiples of 0.25).
    fault = vertical_fault(0.6, [0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
    error = defects_of([*box_model(levels=(0.5,)), fault])
    crossings = [d for d in error.defects if set(d.surfaces) == {"H1", "fault"}]
    assert crossings
    assert all(d.kind == "crossing" for d in crossings)
    for defect in crossings:
        assert defect.point[2] == pytest.approx(0.5, abs=0.2)
        assert defect.point[0] == pytest.approx(0.6, abs=0.2)
    assert "crossing of 'H1' and 'fault'" in str(error)


def test_gaps_are_located() -> None:
    short = horizontal("H", 0.5, low=0.001, high=0.999)
    error = defects_of([*box_model(levels=(), extra_rows=(0.5,)), short])
    assert {d.kind for d in error.defects} == {"gap"}
    assert all(d.distance == pytest.approx(0.001, rel=1e-6) for d in error.defects)
    assert all(d.surfaces[0] == "H" and d.point[2] == 0.5 for d in error.defects)
    # Without gap detection the short horizon touches nothing: it is dangling.
    built = build_blocks(Scene(entities=[*box_model(levels=()), short]), gap_tolerance=0.0)
    assert len(built.blocks) == 1
    assert [e.reason for e in block_report(built).dangling] == ["bounds no volume"]


def test_near_coplanar_patches_are_sorted() -> None:
    epsilon = 1e-7  # H2 leaves H1 at a tenth of a microradian
    # (the default merge distance, 1e-7 of the diagonal, would weld H2 onto H1: use less)
    built = build_blocks(Scene(entities=wedge_model(epsilon)), tolerance=1e-12)
    assert len(built.blocks) == 3
    wedge = min(built.blocks, key=lambda b: b.metadata["volume"])
    assert wedge.metadata["volume"] == pytest.approx(epsilon / 8, rel=1e-6)
    assert wedge.unit_name == "H2 – H1"
    boundary = built.block_mesh(wedge)
    assert boundary.is_closed
    assert boundary.is_consistently_oriented
    assert block_report(built).retried_arcs > 0  # the sort looked past the first edge


def test_patches_leaving_an_arc_together_are_an_error() -> None:
    with pytest.raises(TopologyError, match="overlapping patches"):
        build_blocks(Scene(entities=wedge_model(1e-12)), tolerance=1e-15)


def test_duplicated_surface_is_an_error() -> None:
    surfaces = box_model(levels=(0.5,))
    twin = surfaces[-1].replace(name="H1 copy")
    with pytest.raises(TopologyError, match="overlapping patches"):
        build_blocks(Scene(entities=[*surfaces, twin]))


def test_triangle_kernels_against_hand_answers() -> None:
    flat = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]], dtype=float)
    through = np.array([[[0.5, 0.5, -1], [0.5, 0.5, 1], [1.0, 0.5, 0]]], dtype=float)
    touching = np.array([[[0.5, 0.5, 0], [0.5, 0.5, 1], [1.0, 0.5, 1]]], dtype=float)
    beside = through + np.array([3.0, 0.0, 0.0])
    coplanar_inside = np.array([[[0.2, 0.2, 0], [0.6, 0.2, 0], [0.2, 0.6, 0]]], dtype=float)
    coplanar_apart = coplanar_inside + np.array([5.0, 5.0, 0.0])
    hits = [
        triangles_intersect(flat, other, 1e-12)[0]
        for other in (through, touching, beside, coplanar_inside, coplanar_apart)
    ]
    assert hits == [True, True, False, True, False]
    a, b, c = (np.repeat(flat[:, k], 3, axis=0) for k in range(3))
    points = np.array([[0.5, 0.5, 2.0], [3.0, 0.0, 0.0], [-1.0, -1.0, 0.0]])
    assert point_triangle_distance(points, a, b, c) == pytest.approx([2.0, 1.0, math.sqrt(2.0)])


def test_checks_can_be_switched_off_for_trusted_input() -> None:
    built = build_blocks(Scene(entities=box_model()), check_conformity=False, validate=False)
    report = block_report(built)
    assert "conformity" not in report.stage_seconds
    assert not report.validated
    assert len(built.blocks) == 2
