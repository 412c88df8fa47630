"""GeoTIFF / DEM rasters (rasterio): cea.tiff's 514 x 515 pixels in the three layouts, a DEM
made here with no-data holes and a rotated transform checked value by value, the CRS kept,
exact round trips, and mutated files that read or fail with a FormatError."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import geobrep
from geobrep import CRS, FormatError, Property, RegularGrid, Scene, Surface

rasterio = pytest.importorskip("rasterio")

CEA = Path(__file__).resolve().parent.parent / "data" / "opengeode" / "cea.tiff"


def _pixels() -> np.ndarray:
    with rasterio.open(CEA) as dataset:
        return dataset.read(1)


def test_cea_as_a_dem_sampled_at_pixel_centres() -> None:
    scene = geobrep.read(CEA)
    (surface,) = scene.surfaces
    # 514 x 515 pixels: a vertex per pixel centre, 513 x 514 squares of 2 triangles
    assert surface.n_vertices == 514 * 515 == 264_710
    assert surface.n_faces == 2 * 513 * 514 == 527_364
    pixels = _pixels()
    # pixel (row 0, col 0) centre: the transform's origin plus half a pixel each way
    step = 60.02213698319374
    np.testing.assert_allclose(
        surface.vertices[0], [-28493.166784412522 + step / 2, 4255884.5438021915 - step / 2, 0.0]
    )
    np.testing.assert_array_equal(surface.vertices[:, 2], pixels.ravel().astype(float))
    band = surface.point_data["band_1"].values
    assert band.dtype == np.uint8
    np.testing.assert_array_equal(band, pixels.ravel())
    # every triangle faces up (counter-clockwise seen from above)
    v = surface.vertices[surface.faces]
    cross = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    assert (cross[:, 2] > 0).all()
    # the triangles tile the map area of the centres' lattice once
    np.testing.assert_allclose((cross[:, 2] / 2).sum(), 513 * 514 * step**2)


def test_cea_as_the_reference_readers_pixel_quads() -> None:
    (surface,) = geobrep.read(CEA, raster_as="pixels").surfaces
    # OpenGeode-GeosciencesIO: 265,740 vertices, 264,710 quads (one polygon per pixel)
    assert (surface.n_vertices, surface.n_faces) == (265_740, 264_710)
    assert surface.faces.shape[1] == 4
    np.testing.assert_array_equal(surface.cell_data["band_1"].values, _pixels().ravel())


def test_cea_as_a_one_layer_grid_keeps_its_crs() -> None:
    scene = geobrep.read(CEA, raster_as="grid")
    (grid,) = scene.regular_grids
    assert grid.counts == (514, 515, 1)
    np.testing.assert_array_equal(grid.cell_data["band_1"].values, _pixels().ravel())
    assert scene.crs is not None
    assert scene.crs.wkt is not None
    assert "Cylindrical_Equal_Area" in scene.crs.wkt


def _dem(folder: Path) -> tuple[Path, np.ndarray]:
    """A rotated float32 DEM with a no-data hole, two bands, EPSG:32631."""
    rows, cols = 6, 7
    r, c = np.mgrid[0:rows, 0:cols]
    height = (100.0 + 3.0 * c - 2.0 * r + 0.25 * r * c).astype(np.float32)
    height[2:4, 3] = -9999.0
    slope = np.hypot(3.0, 2.0) * np.ones((rows, cols), dtype=np.float32)
    slope[2:4, 3] = -9999.0  # the hole in every band (a surface keeps the valid pixels of z)
    path = folder / "dem.tif"
    angle = np.radians(20.0)
    transform = rasterio.Affine(
        25.0 * np.cos(angle), 25.0 * np.sin(angle), 450_000.0,
        25.0 * np.sin(angle), -25.0 * np.cos(angle), 6_700_000.0,
    )  # fmt: skip
    with rasterio.open(
        path, "w", driver="GTiff", width=cols, height=rows, count=2, dtype="float32",
        crs="EPSG:32631", transform=transform, nodata=-9999.0,
    ) as dataset:  # fmt: skip
        dataset.write(height, 1)
        dataset.write(slope, 2)
        dataset.set_band_description(1, "height")
    return path, height


def test_a_dem_with_a_hole_and_a_rotated_transform(tmp_path: Path) -> None:
    path, height = _dem(tmp_path)
    scene = geobrep.read(path)
    assert scene.crs is not None
    assert scene.crs.epsg == 32631
    (surface,) = scene.surfaces
    valid = height != -9999.0
    assert surface.n_vertices == valid.sum() == 40
    # squares whose four centres are valid give 2 triangles; those missing one corner, 1
    corners = np.stack([valid[:-1, :-1], valid[:-1, 1:], valid[1:, :-1], valid[1:, 1:]])
    tl, tr, bl, br = corners
    expected = (tl & bl & br).sum() + (tl & br & tr).sum()
    assert surface.n_faces == expected
    assert set(surface.point_data) == {"height", "band_2"}
    rows, cols = np.nonzero(valid)
    t = rasterio.Affine(*[float(x) for x in surface.metadata["raster"]["transform"]])
    x, y = t @ (cols + 0.5, rows + 0.5)
    np.testing.assert_allclose(surface.vertices[:, 0], x, rtol=0, atol=1e-6)
    np.testing.assert_allclose(surface.vertices[:, 1], y, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(surface.vertices[:, 2], height[valid])
    assert surface.point_data["height"].no_data_value == -9999.0
    # the hole is open: its boundary edges are used by one triangle only
    assert not surface.is_closed


def test_other_bands_at_pixels_without_z_are_reported(tmp_path: Path) -> None:
    path, _height = _dem(tmp_path)
    with rasterio.open(path, "r+") as dataset:
        slope = dataset.read(2)
        slope[2, 3] = 1.5
        dataset.write(slope, 2)
    with pytest.warns(UserWarning, match="band_2: 1 value at pixels where band 1 is no-data"):
        geobrep.read(path)


@pytest.mark.parametrize("raster_as", ["surface", "pixels", "grid"])
def test_read_write_read_is_exact(tmp_path: Path, raster_as: str) -> None:
    path, _ = _dem(tmp_path)
    first = geobrep.read(path, raster_as=raster_as)
    copy = geobrep.write(first, tmp_path / f"copy_{raster_as}.tif")
    with rasterio.open(path) as a, rasterio.open(copy) as b:
        np.testing.assert_array_equal(a.read(), b.read())
        assert a.transform == b.transform
        assert a.crs == b.crs
        assert a.nodata == b.nodata
    again = geobrep.read(copy, raster_as=raster_as)
    one, two = first.entities[0], again.entities[0]
    assert type(one) is type(two)
    for name in ("point_data", "cell_data"):
        left, right = getattr(one, name), getattr(two, name)
        assert set(left) == set(right)
        for key in left:
            np.testing.assert_array_equal(left[key].values, right[key].values)
    if isinstance(one, Surface):
        assert isinstance(two, Surface)
        np.testing.assert_array_equal(one.vertices, two.vertices)
        np.testing.assert_array_equal(one.faces, two.faces)


def test_a_generated_grid_is_written_pixel_by_pixel(tmp_path: Path) -> None:
    values = np.arange(12, dtype=np.int16).reshape(3, 4)
    grid = RegularGrid(
        name="g",
        origin=[100.0, 200.0, 0.0],
        u=[10.0, 0.0, 0.0],
        v=[0.0, -10.0, 0.0],
        w=[0.0, 0.0, 1.0],
        counts=(4, 3, 1),
        cell_data={"code": Property(values=values.ravel(), no_data_value=-1.0)},
    )
    path = geobrep.write(Scene(entities=[grid], crs=CRS(epsg=2154)), tmp_path / "g.tif")
    with rasterio.open(path) as dataset:
        np.testing.assert_array_equal(dataset.read(1), values)
        assert dataset.transform == rasterio.Affine(10.0, 0.0, 100.0, 0.0, -10.0, 200.0)
        assert dataset.crs.to_epsg() == 2154
        assert dataset.nodata == -1.0
        assert dataset.descriptions == ("code",)


def test_a_surface_not_read_from_a_raster_is_refused(tmp_path: Path) -> None:
    surface = Surface(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]])
    with pytest.raises(FormatError, match="was not read from a raster"):
        geobrep.write(surface, tmp_path / "s.tif")


def test_not_a_tiff_is_a_format_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.tif"
    path.write_bytes(b"II*\0" + b"\0" * 20)
    with pytest.raises(FormatError, match="not a raster GDAL can read"):
        geobrep.read(path)


def _read_or_error(path: Path, raster_as: str) -> FormatError | None:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            geobrep.read(path, raster_as=raster_as)
    except FormatError as error:
        return error
    return None


@pytest.fixture(scope="module")
def dem_bytes(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    path, _ = _dem(tmp_path_factory.mktemp("dem"))
    return path.read_bytes()


@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 255)), min_size=1, max_size=6),
    st.integers(0, 10_000),
    st.sampled_from(["surface", "pixels", "grid"]),
)
def test_a_mutated_geotiff_reads_or_fails_with_a_format_error(
    dem_bytes: bytes,
    tmp_path_factory: pytest.TempPathFactory,
    edits: list[tuple[int, int]],
    cut: int,
    raster_as: str,
) -> None:
    data = bytearray(dem_bytes)
    for at, value in edits:
        data[at % len(data)] = value
    data = data[: max(8, len(data) - cut % len(data))]
    path = tmp_path_factory.mktemp("mutated") / "m.tif"
    path.write_bytes(bytes(data))
    error = _read_or_error(path, raster_as)
    if error is not None:
        assert " reader failed: " not in error.message, error.message
