"""The facade, the registered builder, its options and its report."""

from __future__ import annotations

import pytest
from blocks_models import box_model

from geobrep import PointSet, Scene
from geobrep.errors import OptionsError, TopologyError
from geobrep.host.registry import UnknownItemError
from geobrep.ops.building import build_blocks
from geobrep.plugins import list_plugins, registries
from geobrep.plugins.blocks.options import BlockBuilderOptions
from geobrep.plugins.blocks.report import REPORT_KEY, BlockReport, block_report


def test_the_builder_is_registered_by_the_blocks_plugin() -> None:
    spec = registries().builders.get("blocks")
    assert spec.plugin == "blocks"
    assert spec.input_types == ("Surface",)
    assert spec.options is BlockBuilderOptions
    (info,) = [p for p in list_plugins() if p.name == "blocks"]
    assert info.status == "loaded"
    assert info.registered["builders"] == ("blocks",)


def test_options_are_validated() -> None:
    scene = Scene(entities=box_model())
    with pytest.raises(OptionsError, match="option 'tolerence': unknown option"):
        build_blocks(scene, tolerence=1e-6)
    with pytest.raises(OptionsError, match="option 'free_borders'"):
        build_blocks(scene, free_borders="ignore")
    with pytest.raises(OptionsError, match="option 'tolerance'"):
        build_blocks(scene, tolerance=-1.0)
    with_points = scene.with_entities(PointSet(vertices=[[0, 0, 0]], name="nothing"))
    with pytest.raises(OptionsError, match=r"PointSet 'nothing'.* is not a Surface"):
        build_blocks(with_points, surfaces=("nothing",))


def test_unknown_builder_and_wrong_input() -> None:
    with pytest.raises(UnknownItemError, match=r"registered builders: .*blocks"):
        build_blocks(Scene(entities=box_model()), builder="no-such-builder")
    with pytest.raises(TopologyError, match="builds from Surface entities"):
        build_blocks(Scene(entities=[PointSet(vertices=[[0, 0, 0]])]))


def test_building_is_deterministic_and_does_not_touch_its_input() -> None:
    scene = Scene(entities=box_model(levels=(0.75, 0.25)))
    before = scene.model_copy()
    first = build_blocks(scene)
    second = build_blocks(scene)
    assert first.replace(metadata={}) == second.replace(metadata={})
    assert scene == before
    assert len(scene.blocks) == 0


def test_report_round_trips_through_the_scene_metadata() -> None:
    built = build_blocks(Scene(entities=box_model()))
    report = block_report(built)
    assert isinstance(built.metadata[REPORT_KEY], dict)
    assert BlockReport.model_validate(report.model_dump(mode="json")) == report
    assert report.blocks == 2
    assert report.adjacency == built.block_adjacency()
    text = report.summary()
    assert "2 blocks + universe" in text
    assert "the sort touched 44 triangles" in text


def test_build_blocks_is_exported_from_the_facade_module() -> None:
    import geobrep.ops.building

    assert geobrep.ops.building.__all__ == ["build_blocks", "demo_stage"]
