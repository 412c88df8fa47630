"""The clipping facade: arguments, errors, options, and the registered clippers."""

from __future__ import annotations

import pytest
from shapes import make_cube

from geobrep import Block, Plane, TetMesh
from geobrep.errors import (
    DegenerateGeometryError,
    EntityValidationError,
    GeobrepError,
    OptionsError,
)
from geobrep.ops.clipping import box_planes, clip, clip_box, section
from geobrep.plugins import list_plugins, registries

EXPECTED = {
    "PointSet",
    "PolyLine",
    "Polygon",
    "Surface",
    "Block",
    "Annotation",
    "NurbsSurface",
    "LinearOctree",
    "RegularGrid",
    "StructuredGrid",
    "Well",
}


def test_one_clipper_per_entity_kind_from_the_clip_plugin() -> None:
    clippers = registries().clippers
    assert {spec.entity_type for spec in clippers if spec.plugin == "clip"} == EXPECTED
    info = next(p for p in list_plugins() if p.name == "clip")
    assert info.status == "loaded"
    for spec in clippers:
        assert spec.options.model_config.get("extra") == "forbid"


def test_plane_keep_and_options_are_checked() -> None:
    cube = make_cube()
    assert clip(cube, (1, 0, 0, -0.5)).volume == pytest.approx(0.5)
    with pytest.raises(DegenerateGeometryError, match="four numbers"):
        clip(cube, (1, 0, 0))
    with pytest.raises(DegenerateGeometryError, match="zero vector"):
        clip(cube, (0, 0, 0, 1))
    with pytest.raises(OptionsError, match="keep must be one of"):
        clip(cube, Plane.x(0.5), keep="left")  # type: ignore[arg-type]
    with pytest.raises(OptionsError, match="unknown clipper"):
        clip(cube, Plane.x(0.5), options={"surfaces": {}})
    with pytest.raises(OptionsError, match="option 'cap'"):
        clip(cube, Plane.x(0.5), options={"surface": {"cap": "never"}})
    with pytest.raises(OptionsError, match="tolerance"):
        clip(cube, Plane.x(0.5), tolerance=-1.0)


def test_blocks_need_their_scene_and_unknown_types_are_errors() -> None:
    with pytest.raises(EntityValidationError, match="with its scene"):
        clip(Block(sides=[(0, 1)], name="B"), Plane.x(0.0))
    tets = TetMesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], cells=[[0, 1, 2, 3]])
    with pytest.raises(GeobrepError, match="no clipper is registered for TetMesh"):
        clip(tets, Plane.x(0.5))
    with pytest.raises(EntityValidationError, match="entity or a Scene"):
        clip(42, Plane.x(0.5))  # type: ignore[arg-type]


def test_clippers_can_be_chosen_by_name() -> None:
    cube = make_cube()
    assert clip(cube, Plane.x(0.5), clippers={"Surface": "surface"}).volume == pytest.approx(0.5)
    with pytest.raises(OptionsError, match="cuts PointSet"):
        clip(cube, Plane.x(0.5), clippers={"Surface": "pointset"})


def test_clip_box_with_planes_and_bounds() -> None:
    cube = make_cube()
    inner = clip_box(cube, (0.25, 0.75, 0.0, 1.0, 0.0, 1.0))
    assert inner.volume == pytest.approx(0.5)
    assert inner.is_closed
    corner = clip_box(cube, [Plane(1, 1, 1, -1.0)])
    assert corner.volume == pytest.approx(1 / 6)
    assert clip_box(cube, (2, 3, 2, 3, 2, 3)) is None
    with pytest.raises(EntityValidationError, match="xmin"):
        box_planes((1, 0, 0, 1, 0, 1))


def test_section_of_entities() -> None:
    cube = make_cube()
    square = section(cube, Plane.z(0.25))
    assert square.area == pytest.approx(1.0)
    assert section(cube, Plane.z(3.0)) is None
    with pytest.raises(EntityValidationError, match="with its scene"):
        section(Block(sides=[(0, 1)]), Plane.x(0.0))
