"""Internal surfaces, dangling patches and bodies floating inside blocks."""

from __future__ import annotations

import numpy as np
import pytest
from blocks_models import box_model, closed_cube, floating_square, vertical_fault

from geobrep import Scene, Surface
from geobrep.errors import TopologyError
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks.report import block_report

TIP = 0.75


def dying_fault_model() -> list[Surface]:
    """Box cut by H1 at z = 0.5 and a fault x = 0.5 rising from the bottom to z = 0.75."""
    return [*box_model(levels=(0.5,), extra_rows=(TIP,)), vertical_fault(0.5, [0, 0.25, 0.5, TIP])]


def test_fault_ending_inside_a_block_is_an_internal_surface() -> None:
    built = build_blocks(Scene(entities=dying_fault_model()))
    assert len(built.blocks) == 3
    upper = built.blocks[0]
    lower = built.blocks[1:]
    assert upper.metadata["volume"] == pytest.approx(0.5, rel=1e-12)
    assert [b.metadata["volume"] for b in lower] == pytest.approx([0.25, 0.25], rel=1e-12)
    fault = built["fault"]
    internal = [p for p in built.patches if p.is_internal]
    assert len(internal) == 1
    assert internal[0].surface == fault.id
    assert internal[0].positive_block == internal[0].negative_block == upper.id
    assert upper.internal_patches == {internal[0].id}
    assert block_report(built).internal_patches == [internal[0].id]
    # The fault's lower patch separates the two lower blocks (normal +x: east on its + side).
    (cut,) = [p for p in built.patches if p.surface == fault.id and not p.is_internal]
    west, east = sorted(lower, key=lambda b: b.metadata["centroid"][0])
    assert (cut.positive_block, cut.negative_block) == (east.id, west.id)
    for block in built.blocks:
        boundary = built.block_mesh(block)
        assert boundary.is_closed
        assert boundary.is_consistently_oriented
    assert built.block_adjacency() == sorted(
        tuple(sorted(p)) for p in [(upper.id, west.id), (upper.id, east.id), (west.id, east.id)]
    )
    # The wall behind the dying fault is one patch with a slit: it appears twice on the arc.
    slit = [a for a in built.topology.arcs if len(set(a.patches)) < len(a.patches)]
    assert slit
    assert all(len(a.patches) == 3 for a in slit)


def test_the_papers_rule_removes_the_dying_fault() -> None:
    built = build_blocks(Scene(entities=dying_fault_model()), free_borders="remove")
    report = block_report(built)
    assert len(built.blocks) == 3
    assert report.internal_patches == []
    (entry,) = report.dangling
    assert (entry.surface, entry.reason, entry.triangles) == ("fault", "free border", 8)
    assert entry.centroid[2] == pytest.approx((0.5 + TIP) / 2)
    fault = built["fault"]
    assert isinstance(fault, Surface)
    assert fault.vertices[:, 2].max() == 0.5
    assert report.passes == 2


def test_free_borders_can_be_an_error() -> None:
    with pytest.raises(TopologyError, match=r"free border.*'fault'.*0\.750"):
        build_blocks(Scene(entities=dying_fault_model()), free_borders="error")


def test_fault_sticking_out_of_the_model_is_trimmed() -> None:
    rows = [0, 0.25, 0.5, 0.75, 1.0, 1.125, 1.25]
    built = build_blocks(Scene(entities=[*box_model(), vertical_fault(0.5, rows)]))
    report = block_report(built)
    assert len(built.blocks) == 4
    assert sorted(b.metadata["volume"] for b in built.blocks) == pytest.approx([0.25] * 4)
    (entry,) = report.dangling
    assert (entry.surface, entry.reason, entry.triangles) == ("fault", "outside the model", 16)
    fault = built["fault"]
    assert isinstance(fault, Surface)
    assert fault.n_faces == 32
    assert fault.vertices[:, 2].max() == 1.0
    assert report.internal_patches == []


def test_floating_sheet_is_removed() -> None:
    built = build_blocks(Scene(entities=[*box_model(), floating_square(0.25)]))
    report = block_report(built)
    assert len(built.blocks) == 2
    assert [(e.surface, e.reason) for e in report.dangling] == [("lens", "bounds no volume")]
    assert report.removed_surfaces == ["lens"]
    assert "lens" not in built


def test_closed_body_inside_a_layer_makes_a_cavity() -> None:
    salt = closed_cube((0.4, 0.4, 0.1), 0.2)
    built = build_blocks(Scene(entities=[*box_model(), salt]))
    assert len(built.blocks) == 3
    volumes = {b.name: b.metadata["volume"] for b in built.blocks}
    by_volume = sorted(built.blocks, key=lambda b: b.metadata["volume"])
    body, host = by_volume[0], by_volume[1]
    assert body.metadata["volume"] == pytest.approx(0.008, rel=1e-12)
    assert host.metadata["volume"] == pytest.approx(0.5 - 0.008, rel=1e-12)
    assert sorted(volumes.values())[-1] == pytest.approx(0.5)
    salt_patches = {p.id for p in built.patches if p.surface == built["salt"].id}
    # Outward normals of the salt point into the host: the host is on their + side.
    assert {(s.patch, s.side) for s in host.sides if s.patch in salt_patches} == {
        (p, 1) for p in salt_patches
    }
    assert {s.patch for s in body.sides} == salt_patches
    boundary = built.block_mesh(host)
    assert boundary.is_closed
    assert boundary.volume == pytest.approx(0.492, rel=1e-12)
    assert block_report(built).nested_bodies == 1
    assert (min(host.id or 0, body.id or 0), max(host.id or 0, body.id or 0)) in (
        built.block_adjacency()
    )


def test_a_model_enclosing_nothing_is_an_error() -> None:
    with pytest.raises(TopologyError, match="no closed block"):
        build_blocks(Scene(entities=[floating_square(0.5)]))
    open_box = [s for s in box_model(levels=()) if s.name != "top"]
    with pytest.raises(TopologyError, match="no closed block"):
        build_blocks(Scene(entities=open_box))


def test_every_patch_has_a_block_on_both_sides() -> None:
    built = build_blocks(Scene(entities=dying_fault_model()))
    ids = {b.id for b in built.of_type(type(built.blocks[0]))}
    for patch in built.patches:
        assert patch.positive_block in ids
        assert patch.negative_block in ids
    assert np.unique([p.surface for p in built.patches]).size == len(built.surfaces)
