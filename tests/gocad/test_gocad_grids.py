"""GOCAD Voxet (.vo + property files) and Well (.wl): the reference files' counts, values read
from the files by hand, exact round trips and FormatErrors that name the missing file."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import CRS, FormatError, Property, RegularGrid, Scene, Well, WellMarker, WellZone
from geobrep.model.entities import WellLog

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def rotated_voxet() -> RegularGrid:
    """A rotated, sheared grid with a float32 property holding NaN and no-data values."""
    counts = (5, 4, 3)
    n = 6 * 5 * 4
    values = np.linspace(-1.5, 7.25, n, dtype=np.float32)
    values[[3, 17]] = -99999.0
    labels = (np.arange(n) % 7).astype(np.int16) - 3
    return RegularGrid(
        name="rotated voxet",
        origin=[451_234.5, 6_702_345.25, -1500.0],
        u=[17.320508075688775, 10.0, 0.0],
        v=[-5.0, 8.660254037844387, 0.0],
        w=[0.25, -0.5, 4.0],
        counts=counts,
        point_data={
            "porosity": Property(values=values, unit="%", no_data_value=-99999.0),
            "facies": Property(values=labels),
        },
    )


class TestVoxet:
    def test_reference_file_reads_its_nodes(self) -> None:
        scene = geobrep.read(OPENGEODE / "test.vo")
        grid = scene.entities[0]
        assert isinstance(grid, RegularGrid)
        # AXIS_N 10 10 10 nodes: 1000 values (OpenGeode's "1000 cells" are one cell per node)
        assert grid.n_points == 1000
        assert grid.counts == (9, 9, 9)
        np.testing.assert_array_equal(grid.u, [100.0, 0.0, 0.0])  # AXIS_U 900 over 9 steps
        values = np.asarray(grid.point_data["random"].values)
        # rows "0 0 0 6.48414", "1 0 0 4.57474", "0 1 0 2.17284" of test__ascii@@
        assert values[0] == 6.48414
        assert values[1] == 4.57474
        assert values[10] == 2.17284
        # PROP_SAMPLE_STATS 1 1000 6.05339 ... 2.03609 9.99882 (count, mean, ..., min, max)
        assert values.mean() == pytest.approx(6.05339, abs=5e-6)
        assert (values.min(), values.max()) == (2.03609, 9.99882)
        assert grid.point_data["random"].no_data_value == -99999.0
        assert scene.crs is not None
        assert scene.crs.name == "SKUA Local"

    def test_reference_file_round_trip(self, tmp_path: Path) -> None:
        scene = geobrep.read(OPENGEODE / "test.vo")
        out = geobrep.write(scene, tmp_path / "copy.vo")
        assert (tmp_path / "copy__random@@").stat().st_size == 1000 * 8
        assert geobrep.read(out).entities[0] == scene.entities[0]

    def test_generated_rotated_voxet_round_trip(self, tmp_path: Path) -> None:
        grid = rotated_voxet()
        scene = Scene(entities=[grid.replace(id=0)], crs=CRS(name="local", z_positive="down"))
        out = geobrep.write(scene, tmp_path / "rot.vo")
        back = geobrep.read(out)
        assert back.entities[0].replace(metadata={}) == scene.entities[0]
        assert back.crs is not None
        assert back.crs.z_positive == "down"
        header = out.read_text()
        assert "PROP_ESIZE 1 4" in header
        assert "PROP_SIGNED 2 1" in header
        # the property file is raw big-endian float32, AXIS_O is written as depth
        raw = np.fromfile(tmp_path / "rot__porosity@@", dtype=">f4")
        np.testing.assert_array_equal(raw, grid.point_data["porosity"].values)
        assert "AXIS_O 451234.5 6702345.25 1500.0" in header

    def test_binary_property_layout_from_the_header(self, tmp_path: Path) -> None:
        values = (np.arange(8) * 1000 + 7).astype(">u2")
        (tmp_path / "g_v@@").write_bytes(b"\x00" * 6 + values.tobytes())
        (tmp_path / "g.vo").write_text(
            "GOCAD Voxet 1\nHEADER {\nname:g\n}\nAXIS_O 0 0 0\nAXIS_U 1 0 0\nAXIS_V 0 2 0\n"
            "AXIS_W 0 0 3\nAXIS_MIN 0 0 0\nAXIS_MAX 1 1 1\nAXIS_N 2 2 2\nPROPERTY 1 v\n"
            "PROP_ESIZE 1 2\nPROP_ETYPE 1 Octet\nPROP_SIGNED 1 0\nPROP_OFFSET 1 6\n"
            "PROP_NO_DATA_VALUE 1 7\nPROP_FILE 1 g_v@@\nEND\n"
        )
        grid = geobrep.read(tmp_path / "g.vo").entities[0]
        assert isinstance(grid, RegularGrid)
        prop = grid.point_data["v"]
        assert prop.values.dtype == np.uint16
        np.testing.assert_array_equal(prop.values, values)
        assert prop.no_data_value == 7.0
        assert grid.volume == pytest.approx(6.0)

    @pytest.mark.parametrize("size", [None, 10])
    def test_missing_or_short_property_file_names_it(
        self, tmp_path: Path, size: int | None
    ) -> None:
        out = geobrep.write(rotated_voxet(), tmp_path / "v.vo")
        side = tmp_path / "v__porosity@@"
        if size is None:
            side.unlink()
        else:
            side.write_bytes(side.read_bytes()[:size])
        with pytest.raises(FormatError, match="v__porosity@@") as info:
            geobrep.read(out)
        assert info.value.path == out  # the header, whose PROP_FILE line names the file
        assert str(side) in str(info.value)

    def test_a_property_file_outside_the_folder_is_refused(self, tmp_path: Path) -> None:
        out = geobrep.write(rotated_voxet(), tmp_path / "v.vo")
        out.write_text(out.read_text().replace("PROP_FILE 1 v__", "PROP_FILE 1 ../v__"))
        with pytest.raises(FormatError, match="not a file beside the header"):
            geobrep.read(out)

    def test_ascii_data_file_round_trip(self, tmp_path: Path) -> None:
        grid = rotated_voxet()
        out = geobrep.write(grid, tmp_path / "a.vo", voxet_ascii=True)
        assert "ASCII_DATA_FILE a__ascii@@" in out.read_text()
        back = geobrep.read(out).entities[0]
        assert isinstance(back, RegularGrid)
        for name, prop in grid.point_data.items():  # exact values, read back as float64
            np.testing.assert_array_equal(back.point_data[name].values, prop.values)
            assert back.point_data[name].no_data_value == prop.no_data_value

    @pytest.mark.parametrize("newline", ["\n", "\r\n"])
    def test_ascii_comment_lines_anywhere_are_skipped(self, tmp_path: Path, newline: str) -> None:
        grid = rotated_voxet()
        out = geobrep.write(grid, tmp_path / "a.vo", voxet_ascii=True)
        table = tmp_path / "a__ascii@@"
        lines = table.read_text().split("\n")
        edited = ["", "# made by hand", *lines[:10], "* a comment between rows", "", *lines[10:]]
        table.write_bytes(newline.join(edited).encode())
        back = geobrep.read(out).entities[0]
        assert isinstance(back, RegularGrid)
        for name, prop in grid.point_data.items():
            np.testing.assert_array_equal(back.point_data[name].values, prop.values)
        table.write_text("\n".join([*lines[:10], "12 x 0 0.5", *lines[10:]]))
        with pytest.raises(FormatError, match="ASCII data file: 'x' is not a number"):
            geobrep.read(out)

    def test_cell_data_is_written_at_the_cell_centres(self, tmp_path: Path) -> None:
        grid = rotated_voxet()
        cells = grid.replace(point_data={}, cell_data={"k": np.arange(60, dtype=np.float64)})
        back = geobrep.read(geobrep.write(cells, tmp_path / "c.vo")).entities[0]
        assert isinstance(back, RegularGrid)
        np.testing.assert_allclose(back.points(), cells.cell_centers(), atol=1e-6)
        np.testing.assert_array_equal(back.point_data["k"].values, np.arange(60))


def deviated_well() -> Well:
    md = np.array([0.0, 120.0, 250.0, 400.0, 575.5])
    xyz = np.array(
        [
            [1005111.0, 2451215.75, 35.0],
            [1005111.0, 2451215.75, -85.0],
            [1005120.25, 2451230.5, -212.5],
            [1005160.0, 2451290.0, -340.0],
            [1005230.5, 2451380.125, -470.0],
        ]
    )
    return Well(
        name="W 2",
        head=xyz[0],
        vertices=xyz,
        md=md,
        datum="KellyBushing",
        datum_elevation=35.0,
        markers=(WellMarker(name="H1", md=200.0), WellMarker(name="H2", md=512.75)),
        zones=(WellZone(name="U1", top_md=200.0, base_md=512.75),),
        logs={
            "GR": WellLog(
                md=[10.0, 20.0, 30.5],
                values=[55.5, -999.25, 61.0],
                unit="API",
                no_data_value=-999.25,
            )
        },
    )


class TestWell:
    def test_reference_file_counts_and_depth_sign(self) -> None:
        scene = geobrep.read(OPENGEODE / "test.wl")
        well = scene.entities[0]
        assert isinstance(well, Well)
        assert (well.n_stations, well.n_cells) == (55, 54)
        # WREF 1005111 2451215.75 -167.9 in a ZPOSITIVE Depth file: 167.9 m above the datum
        np.testing.assert_allclose(well.head, [1005111.0, 2451215.75, 167.89999389648438])
        # "PATH 53.2997971 -114.60023498535156 -0.0625 0": MD, depth, dX, dY
        np.testing.assert_allclose(well.vertices[1], [1005110.9375, 2451215.75, 114.60023498535156])
        assert well.md[1] == 53.2997971
        assert (well.datum, well.datum_elevation) == ("KellyBushing", 0.0)
        # MD grows at least as fast as the distance between stations (to the file's ~1e-4 m
        # float32 rounding)
        chords = np.linalg.norm(np.diff(well.vertices, axis=0), axis=1)
        assert np.all(chords <= np.diff(well.md) + 1e-3)
        assert scene.crs is not None
        assert scene.crs.z_positive == "down"

    def test_reference_file_round_trip(self, tmp_path: Path) -> None:
        scene = geobrep.read(OPENGEODE / "test.wl")
        back = geobrep.read(geobrep.write(scene, tmp_path / "copy.wl"))
        assert back.entities[0] == scene.entities[0]

    def test_generated_well_round_trip(self, tmp_path: Path) -> None:
        well = deviated_well()
        scene = Scene(entities=[well.replace(id=0)], crs=CRS(name="local"))
        back = geobrep.read(geobrep.write(scene, tmp_path / "w.wl"))
        assert back.entities[0].replace(metadata={}) == scene.entities[0]

    def test_marker_and_zone_names_with_spaces_survive(self, tmp_path: Path) -> None:
        well = deviated_well().replace(
            id=0,
            markers=(WellMarker(name="top A", md=200.0), WellMarker(name=" base  B", md=512.75)),
            zones=(WellZone(name="unit one", top_md=200.0, base_md=512.75),),
        )
        scene = Scene(entities=[well], crs=CRS(name="local"))
        back = geobrep.read(geobrep.write(scene, tmp_path / "w.wl")).entities[0]
        assert isinstance(back, Well)
        assert [m.name for m in back.markers] == ["top A", " base  B"]
        assert [z.name for z in back.zones] == ["unit one"]

    def test_marker_surfaces_are_reported_lost(self, tmp_path: Path) -> None:
        well = deviated_well()
        hit = well.replace(markers=(WellMarker(name="H1", md=200.0, surface="top"),))
        from geobrep.batch.conversion import convert_file

        report = convert_file(_native(hit, tmp_path), tmp_path / "w.wl")
        assert report.error is None
        assert any("surfaces its markers hit" in loss for loss in report.lost)

    def test_a_broken_station_line_names_its_line(self, tmp_path: Path) -> None:
        path = tmp_path / "bad.wl"
        path.write_text(
            "GOCAD Well 1\nHEADER {\nname:b\n}\nWREF 0 0 0\nPATH 0 0 0 0\nPATH 10 x 0 0\nEND\n"
        )
        with pytest.raises(FormatError, match="PATH") as info:
            geobrep.read(path)
        assert info.value.line == 7


def _native(entity: Well, folder: Path) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.write(entity, folder / "w.geobrep")


class TestOctreeVoxet:
    def test_a_voxelized_model_survives_a_voxet(self, tmp_path: Path) -> None:
        octree = geobrep.voxelize(geobrep.datasets.faulted_layer_cake(), depth=5)
        grid = RegularGrid.from_octree(octree)
        assert grid.counts == (32, 32, 32)
        labels = np.asarray(grid.cell_data["label"].values)
        # every finest cell of a leaf carries the leaf's label: volumes per label agree
        cell = grid.cell_volume
        for label, volume in octree.label_volumes().items():
            assert np.count_nonzero(labels == label) * cell == pytest.approx(volume, rel=1e-12)
        back = geobrep.read(geobrep.write(grid, tmp_path / "cake.vo")).entities[0]
        assert isinstance(back, RegularGrid)
        assert back.n_points == 32**3  # one node per voxel, at its centre
        again = back.to_octree()
        np.testing.assert_array_equal(again.codes, octree.codes)  # merged back into its leaves
        np.testing.assert_array_equal(again.levels, octree.levels)
        np.testing.assert_array_equal(again.labels, octree.labels)
        np.testing.assert_array_equal(again.origin, octree.origin)
        assert again.size == octree.size
        assert again.label_volumes() == octree.label_volumes()

    def test_only_full_same_label_families_merge(self) -> None:
        tree = geobrep.LinearOctree(
            codes=[0, 8, 9, 16, 24],
            levels=[1, 2, 2, 1, 1],
            depth=2,
            origin=[10, 20, 30],
            size=4.0,
            labels=[7, 9, 9, 3, 3],
        )
        grid = RegularGrid.from_octree(tree)
        assert np.bincount(np.asarray(grid.cell_data["label"].values) + 1).tolist() == [
            38,
            0,
            0,
            0,
            16,
            0,
            0,
            0,
            8,
            0,
            2,
        ]
        assert grid.to_octree() == tree.replace(name="")

    def test_a_rotated_grid_is_refused(self) -> None:
        with pytest.raises(geobrep.EntityValidationError, match="axis-aligned"):
            rotated_voxet().to_octree("facies")
