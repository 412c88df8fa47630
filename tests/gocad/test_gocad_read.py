"""Reading every real GOCAD file: counts, conventions, metadata."""

from __future__ import annotations

import collections
import warnings

import numpy as np
import pytest
from gocad_files import DATA, FILES, read_quietly

import geobrep
from geobrep import Block, PointSet, PolyLine, Scene, Surface, TetMesh
from geobrep.adapters.gocad._parser import GocadWarning
from geobrep.model.arcs import build_corners_and_arcs
from geobrep.model.topology import Topology

#: file -> (entity type counts, total patches in the topology, blocks besides the universe)
EXPECTED = {
    "2triangles.ts": ({"Surface": 1}, 0, 0),
    "Fault_without_crs.ts": ({"Surface": 1}, 0, 0),
    "cube_model_equi.so": ({"TetMesh": 1, "Surface": 7}, 0, 0),
    "modelA1.ml": ({"Surface": 9, "Block": 5}, 21, 4),
    "modelA4.ml": ({"Surface": 11, "Block": 9}, 55, 8),
    "non_split_cube.ml": ({"Surface": 2, "Block": 2}, 2, 1),
    "normal_lines.pl": ({"PolyLine": 1}, 0, 0),
    "not_sealed_cube.ml": ({"Surface": 6, "Block": 1}, 6, 0),
    "points.vs": ({"PointSet": 1}, 0, 0),
    "sgrid_tsurf.ts": ({"Surface": 1}, 1, 0),
    "solid_surf_inside.so": ({"TetMesh": 1, "Surface": 7}, 0, 0),
    "split_cube.ml": ({"Surface": 2, "Block": 3}, 3, 2),
    "surf2d.ts": ({"Surface": 1}, 3, 0),
    "surf2d_multi.ts": ({"Surface": 2}, 6, 0),
    "ts-2props.ts": ({"Surface": 1}, 1, 0),
    "header_only_fault.ts": ({"Surface": 2}, 0, 0),  # F3_fault: a header, no vertices
    "voxet_and_tsurf.gp": ({"RegularGrid": 1, "Surface": 1}, 0, 0),  # + porosity_grid@@
}


def test_every_test_file_has_expectations() -> None:
    assert sorted(EXPECTED) == FILES


@pytest.mark.parametrize("name", FILES)
def test_every_file_reads(name: str) -> None:
    scene = read_quietly(DATA / name)
    types, patches, blocks = EXPECTED[name]
    counts = collections.Counter(type(e).__name__ for e in scene.entities)
    assert dict(counts) == types
    assert len(scene.topology.patches) == patches
    assert len(scene.blocks) == blocks
    for entity in scene.entities:
        if hasattr(entity, "vertices"):
            assert entity.vertices.dtype == np.float64
            assert np.isfinite(entity.vertices).all()


def test_zero_based_ids_are_labels() -> None:
    surface = read_quietly(DATA / "2triangles.ts").surfaces[0]
    assert surface.faces.tolist() == [[0, 1, 2], [1, 2, 3]]
    assert surface.vertices[0].tolist() == [1066960.43428972, 6894769.78384417, -2238.04224665696]


def test_file_without_crs_and_indented_header() -> None:
    scene = read_quietly(DATA / "Fault_without_crs.ts")
    fault = scene.surfaces[0]
    assert scene.crs is None
    assert fault.name == "Fault"
    assert (fault.n_vertices, fault.n_faces) == (189, 324)


def test_depth_is_negated_and_winding_kept() -> None:
    scene = read_quietly(DATA / "ts-2props.ts")
    surface = scene.surfaces[0]
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"
    assert scene.crs.name == " Pdgm_Epic Local"
    assert surface.vertices[0].tolist() == [-745925.546875, -2618524.8125, 44070.2578125]
    assert surface.faces.tolist() == [[2, 1, 0], [3, 1, 2]]  # TRGL 3 2 1, TRGL 4 2 3


def test_quoted_property_names_no_data_and_flags() -> None:
    surface = read_quietly(DATA / "ts-2props.ts").surfaces[0]
    assert list(surface.point_data) == [" default property", "def-prop", "gocad_vertex_flag"]
    prop = surface.point_data[" default property"]
    assert prop.no_data_value == -99999.0
    assert prop.values.tolist() == [-99999.0] * 4
    assert prop.metadata["gocad"]["kind"] == " Real Number"
    assert surface.point_data["gocad_vertex_flag"].values.tolist() == [1, 1, 1, 1]  # CNXYZ
    assert surface.metadata["color"] == [1.0, 0.447059, 0.337255, 1.0]
    header = dict(surface.metadata["gocad"]["header"])
    assert header["mesh"] == "on"
    assert header["cn"] == "on"


def test_vector_property_with_linearfunction_subclass() -> None:
    scene = read_quietly(DATA / "points.vs")
    points = scene.point_sets[0]
    assert isinstance(points, PointSet)
    assert points.n_points == 6
    normal = points.point_data["normal"]
    assert normal.shape == (6, 3)
    assert normal.element_size == 3
    assert normal.unit == "m"
    assert normal.no_data_value == -99999.0
    assert normal.metadata["gocad"]["subclass"] == ["LINEARFUNCTION", "Float", "1", "0"]
    assert normal.metadata["gocad"]["class"] == "vector3d"
    assert scene.crs is not None
    assert scene.crs.axis_names == ("U", "V", "W")
    assert points.metadata["gocad"]["geology"]["GEOLOGICAL_FEATURE"] == "Top_S1"


def test_tfaces_and_borders() -> None:
    scene = read_quietly(DATA / "surf2d.ts")
    surface = scene.surfaces[0]
    assert surface.n_patches == 3
    assert np.bincount(surface.patch_labels).tolist() == [13, 14, 19]
    gocad = surface.metadata["gocad"]
    assert gocad["bstones"] == [12, 23, 43]  # BSTONE 13 24 44
    assert gocad["borders"] == [[12, 10], [23, 21], [43, 42]]
    corner_points = {tuple(c.point.tolist()) for c in scene.topology.corners}
    for vertex in gocad["bstones"]:
        assert tuple(surface.vertices[vertex].tolist()) in corner_points


def test_several_objects_in_one_file() -> None:
    scene = read_quietly(DATA / "surf2d_multi.ts")
    first, second = scene.surfaces
    assert first.name == second.name == "section1"
    assert np.array_equal(first.vertices, second.vertices)
    assert first.id != second.id


def test_unknown_object_type_is_skipped_with_a_warning() -> None:
    with pytest.warns(GocadWarning, match="skipping GOCAD SGrid object"):
        scene = geobrep.read(DATA / "sgrid_tsurf.ts")
    (surface,) = scene.surfaces
    assert surface.name == "FractureSet_N20_1fract_visualisation"
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"


def test_pline_parts_per_iline() -> None:
    line = read_quietly(DATA / "normal_lines.pl").polylines[0]
    assert isinstance(line, PolyLine)
    assert (line.n_parts, line.n_points, line.n_cells) == (17, 11391, 11374)
    assert not line.closed.any()
    assert line.metadata["gocad"]["class_headers"]["Z"]["kind"] == "Depth"


def test_tsolid_regions_atoms_and_ctetra() -> None:
    scene = read_quietly(DATA / "cube_model_equi.so")
    (tets,) = scene.tet_meshes
    assert isinstance(tets, TetMesh)
    assert tets.n_cells == 112
    assert tets.n_points == 69
    assert tets.region_names == ("Region_1", "Region_2")
    assert np.bincount(tets.region_labels).tolist() == [55, 57]
    codes = tets.cell_data["gocad_ctetra_faces"]
    surfaces = codes.metadata["gocad"]["surfaces"]
    assert set(surfaces) == {"surf", "surf2", "surf3", "surf_E", "surf_N", "surf_S", "surf_W"}
    assert int((np.asarray(codes) != 0).sum()) == 130
    assert tets.metadata["gocad"]["model_regions"] == [["Region_1", 1], ["Region_2", -2]]
    model_surfaces = [s for s in scene.surfaces if s.metadata["gocad"]["type"] == "TSolid.SURFACE"]
    assert sum(s.n_patches for s in model_surfaces) == 11
    assert sum(s.n_faces for s in model_surfaces) == 116
    # every model triangle is a face of a tetrahedron
    tet_faces = {
        tuple(sorted(map(tuple, tets.vertices[c].tolist())))
        for cell in tets.cells
        for c in (cell[[0, 1, 2]], cell[[0, 1, 3]], cell[[0, 2, 3]], cell[[1, 2, 3]])
    }
    for surface in model_surfaces:
        for face in surface.faces:
            assert tuple(sorted(map(tuple, surface.vertices[face].tolist()))) in tet_faces


def test_model3d_counts_of_model_a4() -> None:
    scene = read_quietly(DATA / "modelA4.ml")
    assert len(scene.patches) == 55
    assert len(scene.blocks) == 8
    assert scene.universe is not None
    kinds = collections.Counter(s.kind for s in scene.surfaces)
    assert kinds == {"fault": 2, "horizon": 3, "boundary": 6}
    layers = [g for g in scene.groups if g.kind == "layer"]
    assert len(layers) == 4
    assert {g.name for g in scene.groups if g.kind == "fault_block"} == {"no_fault_block_name"}
    assert {b.unit_name for b in scene.blocks} == {"H1b", "H2b", "H3b", "model3b_boundary"}
    fault = scene["F1fault"]
    assert fault.metadata["gocad"]["geology"]["GEOLOGICAL_TYPE"] == "normal_fault"
    assert len(fault.point_data) == 5
    assert fault.point_data["model3b_skua_model_H2b_t_throw"].unit == "m"


def test_model3d_lines_and_corners_rebuilt_from_patches() -> None:
    scene = read_quietly(DATA / "modelA4.ml")
    patches = tuple(p.model_copy(update={"arcs": ()}) for p in scene.patches)
    bare = scene.replace(topology=Topology(patches=patches))
    rebuilt = build_corners_and_arcs(bare)
    assert (len(rebuilt.arcs), len(rebuilt.corners)) == (98, 52)
    # the reader's own topology (BSTONEs as corner hints) agrees
    assert (len(scene.topology.arcs), len(scene.topology.corners)) == (98, 52)


def test_key_triangles_are_found_even_when_not_first() -> None:
    scene = read_quietly(DATA / "modelA4.ml")
    not_first = 0
    for patch in scene.patches:
        surface = scene[patch.surface]
        assert isinstance(surface, Surface)
        key = patch.metadata["gocad"]["key_triangle"]
        faces = surface.patch_faces(patch.label)
        assert key in set(faces.tolist())
        not_first += key != faces[0]
    assert not_first == 14  # 41 of 55 keys are the first triangle (reference notes §1.10)


def test_internal_surface_and_unsealed_universe() -> None:
    inside = read_quietly(DATA / "non_split_cube.ml")
    (top,) = inside.blocks
    assert top.name == "Top"
    assert top.internal_patches == frozenset({2})
    unsealed = read_quietly(DATA / "not_sealed_cube.ml")
    universe = unsealed.universe
    assert universe is not None
    assert len(universe.sides) == 12
    assert universe.internal_patches == frozenset(range(1, 7))


def test_vertex_ids_option() -> None:
    surface = read_quietly(DATA / "2triangles.ts", vertex_ids=True).surfaces[0]
    assert surface.point_data["gocad_vertex_id"].values.tolist() == [0, 1, 2, 3]


def test_read_is_deterministic_and_warning_free_for_clean_files() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", GocadWarning)
        first = geobrep.read(DATA / "modelA1.ml")
    assert first == geobrep.read(DATA / "modelA1.ml")
    assert isinstance(first, Scene)
    assert all(isinstance(b, Block) for b in first.of_type(Block))
