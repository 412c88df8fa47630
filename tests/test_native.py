"""The native ``.geobrep`` container: lossless round trips, JSON Schema, atomic writes, errors."""

from __future__ import annotations

import io
import json
import math
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import jsonschema
import numpy as np
import pytest
from pydantic import BaseModel

import geobrep
import geobrep.schemas
from geobrep import (
    CRS,
    Annotation,
    Block,
    FileAccessError,
    FormatError,
    Group,
    LinearOctree,
    NurbsSurface,
    OptionsError,
    PointSet,
    Polygon,
    PolyLine,
    Property,
    Scene,
    Surface,
    TetMesh,
    UnknownFormatError,
)
from geobrep.adapters.native import _container as container


def arrays_of(value: Any, path: str = "") -> Iterator[tuple[str, np.ndarray]]:
    """Every numpy array inside a model, with a path naming where it sits."""
    if isinstance(value, np.ndarray):
        yield path, value
    elif isinstance(value, BaseModel):
        for name in type(value).model_fields:
            yield from arrays_of(getattr(value, name), f"{path}.{name}")
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from arrays_of(item, f"{path}[{key!r}]")
    elif isinstance(value, tuple | list):
        for index, item in enumerate(value):
            yield from arrays_of(item, f"{path}[{index}]")


def assert_bit_identical(a: Scene, b: Scene) -> None:
    left, right = list(arrays_of(a)), list(arrays_of(b))
    assert [p for p, _ in left] == [p for p, _ in right]
    for (where, x), (_, y) in zip(left, right, strict=True):
        assert x.dtype == y.dtype, where
        assert x.shape == y.shape, where
        assert x.tobytes() == y.tobytes(), where
        assert not y.flags.writeable, where


def every_entity_type() -> Scene:
    """One of each entity type, with point and cell properties of many dtypes."""
    utm = np.array([450_000.0, 6_700_000.0, 0.0])
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) + utm
    net = np.zeros((2, 2, 3))
    net[1, :, 0] = 1.0
    net[:, 1, 1] = 1.0
    nodata = Property(values=[1.0, math.nan, -999.0, 2.0], no_data_value=math.nan, unit="m")
    entities = [
        PointSet(
            vertices=square,
            name="wells",
            kind="markers",
            point_data={
                "velocity": Property(values=np.arange(12.0).reshape(4, 3), unit="m/s"),
                "code": np.array([1, -2, 3, 127], dtype=np.int8),
                "flag": np.array([True, False, True, False]),
                "depth": nodata,
                "f32": np.array([0.1, 0.2, 0.3, 0.4], dtype=np.float32),
                "big": np.array([2**62, -(2**62), 0, 1], dtype=np.int64),
            },
            metadata={"source": "survey ✓", "nested": [1, 2.5, {"a": None, "b": True}]},
        ),
        PolyLine.from_parts(
            square,
            [[0, 1, 2, 3], [3, 0]],
            closed=[True, False],
            name="trace",
            cell_data={"segment": np.arange(5, dtype=np.int32)},
        ),
        Polygon.from_rings(square, name="outline", cell_data={"area_class": [1.5]}),
        Surface(
            vertices=square,
            faces=[[0, 1, 2, 3]],
            patch_labels=[0],
            patch_names=("only",),
            name="quad",
            cell_data={"dip": Property(values=[math.nan], no_data_value=-1.0)},
            point_data={"u8": np.array([1, 2, 3, 255], dtype=np.uint8)},
        ),
        Surface(
            vertices=square,
            faces=np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32),
            name="tris",
        ),
        NurbsSurface(
            degree_u=1,
            degree_v=1,
            knots_u=[0, 0, 1, 1],
            knots_v=[0, 0, 1, 1],
            control_points=net,
            weights=[[1, 2], [3, 4]],
            name="nurbs",
            point_data={"w": [1, 2, 3, 4]},
        ),
        Annotation(text="Fault F1 — é", anchor=[1, 2, 3], baseline=[0, 1, 0], name="label"),
        LinearOctree(
            codes=[0, 8],
            levels=[1, 2],
            depth=2,
            origin=[1, 2, 3],
            size=4.0,
            labels=[3, 4],
            name="voxels",
            cell_data={"p": np.array([0.5, 0.25], dtype=np.float32)},
        ),
        Block(sides=[], name="empty block", unit_name="Jurassic"),
        TetMesh(
            vertices=[*square[[0, 1, 3]].tolist(), [450_000.0, 6_700_000.0, 1.0]],
            cells=[[0, 1, 2, 3]],
            region_labels=[0],
            region_names=("unit",),
            name="tets",
            cell_data={"rock": np.array([7], dtype=np.int16)},
        ),
    ]
    return Scene(
        entities=entities,
        name="everything",
        crs=CRS(
            epsg=32631,
            wkt='PROJCS["WGS 84 / UTM zone 31N"]',
            axis_names=("E", "N", "Depth"),
            z_positive="down",
            vertical_datum="MSL",
        ),
        groups=[
            Group(name="points", members=(0,), children=(Group(name="lines", members=(1, 2)),)),
            Group(name="surfaces", kind="horizons", members=(3, 4), metadata={"colour": "red"}),
        ],
        metadata={"project": "test", "version": 3, "ratio": 0.25},
    )


# ----------------------------------------------------------------------------- round trips
class TestRoundTrip:
    def test_layer_cake(self, layer_cake: Scene, tmp_path: Path) -> None:
        path = geobrep.write(layer_cake, tmp_path / "cake.geobrep")
        assert path == tmp_path / "cake.geobrep"
        again = geobrep.read(path)
        assert again == layer_cake
        assert_bit_identical(layer_cake, again)
        assert again.topology == layer_cake.topology
        assert again.block_adjacency() == layer_cake.block_adjacency()

    def test_every_entity_type(self, tmp_path: Path) -> None:
        scene = every_entity_type()
        again = geobrep.read(geobrep.write(scene, tmp_path / "all.geobrep"))
        assert again == scene
        assert_bit_identical(scene, again)
        wells = again["wells"]
        assert math.isnan(wells.point_data["depth"].no_data_value)  # type: ignore[arg-type]
        assert wells.point_data["velocity"].element_size == 3
        assert wells.point_data["flag"].dtype == np.bool_
        assert wells.point_data["code"].dtype == np.int8
        assert wells.metadata["source"] == "survey ✓"
        assert again.crs == scene.crs
        assert again.groups == scene.groups

    @pytest.mark.parametrize("value", [math.inf, -math.inf, -999.0, 0.0])
    def test_special_no_data_values(self, value: float, tmp_path: Path) -> None:
        points = PointSet(
            vertices=np.zeros((2, 3)),
            point_data={"a": Property(values=[1.0, value], no_data_value=value)},
        )
        again = geobrep.read(geobrep.write(points, tmp_path / "p.geobrep"))
        assert again.entities[0].point_data["a"].no_data_value == value

    def test_empty_scene(self, tmp_path: Path) -> None:
        again = geobrep.read(geobrep.write(Scene(), tmp_path / "empty.geobrep"))
        assert again == Scene()
        assert len(again) == 0

    def test_entities_are_wrapped_in_a_scene(self, tmp_path: Path) -> None:
        points = PointSet(vertices=[[1.0, 2.0, 3.0]], name="p")
        one = geobrep.read(geobrep.write(points, tmp_path / "one.geobrep"))
        assert one.entities[0].name == "p"
        assert one.entities[0].id == 0
        two = geobrep.read(
            geobrep.write([points, points.replace(name="q")], tmp_path / "t.geobrep")
        )
        assert [e.name for e in two.entities] == ["p", "q"]

    def test_empty_arrays(self, tmp_path: Path) -> None:
        scene = Scene(
            entities=[
                PointSet(vertices=np.zeros((0, 3))),
                Surface(vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), dtype=np.int64)),
            ]
        )
        again = geobrep.read(geobrep.write(scene, tmp_path / "e.geobrep"))
        assert again == scene
        assert again.entities[1].faces.shape == (0, 3)

    def test_compressed(self, layer_cake: Scene, tmp_path: Path) -> None:
        plain = geobrep.write(layer_cake, tmp_path / "plain.geobrep")
        packed = geobrep.write(layer_cake, tmp_path / "packed.geobrep", compress=True)
        again = geobrep.read(packed)
        assert again == layer_cake
        assert_bit_identical(layer_cake, again)
        with zipfile.ZipFile(packed) as archive:
            arrays = [i for i in archive.infolist() if i.filename.endswith(".npy")]
            assert arrays
            assert all(i.compress_type == zipfile.ZIP_DEFLATED for i in arrays)
        with zipfile.ZipFile(plain) as archive:
            assert all(i.compress_type == zipfile.ZIP_STORED for i in archive.infolist())
        assert packed.stat().st_size < plain.stat().st_size

    def test_format_by_name_and_by_content(self, layer_cake: Scene, tmp_path: Path) -> None:
        path = geobrep.write(layer_cake, tmp_path / "model.dat", format="native")
        assert geobrep.read(path, format="native") == layer_cake
        assert geobrep.read(path) == layer_cake  # recognised from its first bytes

    @pytest.mark.slow
    def test_a_million_triangles(self, tmp_path: Path) -> None:
        nx, ny = 1001, 501
        x, y = np.meshgrid(np.linspace(0, 5000, nx), np.linspace(0, 2500, ny))
        rng = np.random.default_rng(1)
        z = rng.normal(0.0, 30.0, x.shape)
        vertices = np.column_stack([x.ravel() + 450_000, y.ravel() + 6_700_000, z.ravel()])
        i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
        a = (j * nx + i).ravel()
        faces = np.concatenate(
            [np.stack([a, a + 1, a + nx + 1], axis=1), np.stack([a, a + nx + 1, a + nx], axis=1)]
        )
        assert faces.shape == (1_000_000, 3)
        surface = Surface(vertices=vertices, faces=faces, name="big", cell_data={"id": a.repeat(2)})
        again = geobrep.read(geobrep.write(surface, tmp_path / "big.geobrep"))
        big = again["big"]
        assert isinstance(big, Surface)
        assert big.vertices.tobytes() == vertices.tobytes()
        assert big.faces.tobytes() == surface.faces.tobytes()
        assert big == surface.replace(id=0)
        assert again == Scene(entities=[surface])


# ----------------------------------------------------------------------------- container
class TestContainer:
    def test_scene_json_comes_first(self, layer_cake: Scene, tmp_path: Path) -> None:
        path = geobrep.write(layer_cake, tmp_path / "cake.geobrep")
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
            document = json.loads(archive.read("scene.json"))
        assert names[0] == "scene.json"
        assert all(n.startswith("arrays/") and n.endswith(".npy") for n in names[1:])
        assert len(names) == len(set(names))
        assert document["format"] == "geobrep-scene"
        assert document["version"] == 1
        assert document["writer"] == f"geobrep {geobrep.__version__}"
        files = {r["file"] for _, r in records_of(document)}
        assert files == set(names[1:])
        assert container.looks_native(path.read_bytes()[:64])
        assert not container.looks_native(b"PK\x03\x04" + b"\0" * 60)
        assert not container.looks_native(b"")

    def test_scene_json_is_valid_against_the_schema(self, tmp_path: Path) -> None:
        schema = geobrep.schemas.load("scene")
        jsonschema.Draft202012Validator.check_schema(schema)
        validator = jsonschema.Draft202012Validator(schema)
        for scene in (every_entity_type(), geobrep.datasets.faulted_layer_cake(), Scene()):
            path = geobrep.write(scene, tmp_path / "s.geobrep")
            with zipfile.ZipFile(path) as archive:
                document = json.loads(archive.read("scene.json"))
            errors = sorted(validator.iter_errors(document), key=str)
            assert not errors, errors[0]
            broken = {**document, "version": 2}
            assert list(validator.iter_errors(broken))
            broken = {**document, "scene": {**document["scene"], "surprise": 1}}
            assert list(validator.iter_errors(broken))

    def test_stored_schema_is_up_to_date(self) -> None:
        stored = Path(geobrep.schemas.__file__).parent / "scene.schema.json"
        generated = geobrep.schemas.render(geobrep.schemas.generate()["scene"])
        assert generated == stored.read_text(encoding="utf-8"), (
            "schemas/scene.schema.json is stale: run `make schemas`"
        )

    def test_schema_loader(self) -> None:
        assert geobrep.schemas.load("scene")["title"] == "geobrep scene document"
        with pytest.raises(KeyError, match="unknown schema 'nope'"):
            geobrep.schemas.load("nope")


def records_of(value: Any, path: str = "") -> Iterator[tuple[str, dict[str, Any]]]:
    """Every ``{"dtype", "shape", "file"}`` array record in a scene.json document."""
    if isinstance(value, dict):
        if "file" in value and "dtype" in value:
            yield path, value
            return
        for key, item in value.items():
            yield from records_of(item, f"{path}.{key}")
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from records_of(item, f"{path}[{index}]")


# ----------------------------------------------------------------------------- atomic writes
class TestAtomicWrite:
    @pytest.fixture
    def failing_arrays(self, monkeypatch: pytest.MonkeyPatch) -> None:
        """The third array written raises, after the zip already has members."""
        real = np.lib.format.write_array
        calls = {"n": 0}

        def write_array(*args: Any, **kwargs: Any) -> None:
            calls["n"] += 1
            if calls["n"] == 3:
                raise OSError("disk full")
            real(*args, **kwargs)

        monkeypatch.setattr(container.np.lib.format, "write_array", write_array)

    def test_failure_leaves_nothing(
        self, layer_cake: Scene, tmp_path: Path, failing_arrays: None
    ) -> None:
        target = tmp_path / "cake.geobrep"
        with pytest.raises(FormatError, match="native writer failed: OSError: disk full") as info:
            geobrep.write(layer_cake, target)
        assert info.value.path == target
        assert isinstance(info.value.__cause__, OSError)
        assert list(tmp_path.iterdir()) == []

    def test_failure_keeps_the_old_file(self, layer_cake: Scene, tmp_path: Path) -> None:
        target = tmp_path / "cake.geobrep"
        small = Scene(entities=[PointSet(vertices=[[1.0, 2.0, 3.0]])])
        geobrep.write(small, target)
        before = target.read_bytes()
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(
                container.np.lib.format,
                "write_array",
                lambda *a, **k: (_ for _ in ()).throw(RuntimeError("boom")),
            )
            with pytest.raises(FormatError, match="boom"):
                geobrep.write(layer_cake, target)
        assert target.read_bytes() == before
        assert [p.name for p in tmp_path.iterdir()] == ["cake.geobrep"]
        assert geobrep.read(target) == small

    def test_overwrite(self, tmp_path: Path) -> None:
        target = tmp_path / "p.geobrep"
        geobrep.write(PointSet(vertices=[[0.0, 0.0, 0.0]]), target)
        geobrep.write(PointSet(vertices=[[1.0, 1.0, 1.0]]), target)
        assert geobrep.read(target).entities[0].vertices.tolist() == [[1.0, 1.0, 1.0]]
        assert [p.name for p in tmp_path.iterdir()] == ["p.geobrep"]

    def test_missing_output_folder(self, tmp_path: Path) -> None:
        with pytest.raises(FileAccessError, match="output folder does not exist"):
            geobrep.write(Scene(), tmp_path / "nowhere" / "x.geobrep")


# ----------------------------------------------------------------------------- errors
def rebuild(
    source: Path,
    target: Path,
    *,
    document: Any = None,
    text: str | None = None,
    drop: str | None = None,
    replace: dict[str, bytes] | None = None,
) -> Path:
    """A copy of a container with scene.json changed, or a member dropped or replaced."""
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(target, "w") as new:
        for info in old.infolist():
            if info.filename == drop:
                continue
            data = old.read(info.filename)
            if info.filename == "scene.json":
                if text is not None:
                    data = text.encode()
                elif document is not None:
                    data = json.dumps(document(json.loads(data))).encode()
            if replace and info.filename in replace:
                data = replace[info.filename]
            new.writestr(info.filename, data)
    return target


@pytest.fixture
def cake_file(layer_cake: Scene, tmp_path: Path) -> Path:
    return geobrep.write(layer_cake, tmp_path / "cake.geobrep")


class TestErrors:
    def test_missing_file(self, tmp_path: Path) -> None:
        path = tmp_path / "nope.geobrep"
        with pytest.raises(FileAccessError) as info:
            geobrep.read(path)
        assert isinstance(info.value, OSError)
        assert str(info.value) == f"{path}: no such file"
        assert info.value.path == path

    def test_directory(self, tmp_path: Path) -> None:
        with pytest.raises(FileAccessError, match="is a directory"):
            geobrep.read(tmp_path)

    def test_unknown_extension(self, tmp_path: Path) -> None:
        path = tmp_path / "model.foo"
        path.write_text("hello")
        with pytest.raises(UnknownFormatError) as info:
            geobrep.read(path)
        message = str(info.value)
        assert message.startswith(f"{path}: no installed format can read this file")
        assert "extension .foo" in message
        assert "native (.geobrep" in message
        assert isinstance(info.value, FormatError)
        with pytest.raises(
            UnknownFormatError, match=r"formats that can write: .*native \(.geobrep"
        ):
            geobrep.write(Scene(), tmp_path / "out.foo")
        assert not (tmp_path / "out.foo").exists()

    def test_unknown_format_name(self, cake_file: Path) -> None:
        with pytest.raises(UnknownFormatError, match=r"unknown format 'nope'.*native"):
            geobrep.read(cake_file, format="nope")

    def test_not_a_zip(self, tmp_path: Path) -> None:
        path = tmp_path / "bad.geobrep"
        path.write_bytes(b"garbage" * 100)
        with pytest.raises(FormatError) as info:
            geobrep.read(path)
        assert str(info.value).startswith(f"{path}: not a readable .geobrep container")
        assert info.value.path == path

    @pytest.mark.parametrize("keep", [0.5, 0.95])
    def test_truncated(self, cake_file: Path, tmp_path: Path, keep: float) -> None:
        data = cake_file.read_bytes()
        path = tmp_path / "cut.geobrep"
        path.write_bytes(data[: int(len(data) * keep)])
        with pytest.raises(FormatError, match=str(path)):
            geobrep.read(path)

    def test_empty_file(self, tmp_path: Path) -> None:
        path = tmp_path / "zero.geobrep"
        path.write_bytes(b"")
        with pytest.raises(FormatError, match=str(path)):
            geobrep.read(path)

    def test_missing_array_member(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(cake_file, tmp_path / "m.geobrep", drop="arrays/000003.npy")
        with pytest.raises(FormatError) as info:
            geobrep.read(path)
        message = str(info.value)
        assert message.startswith(f"{path}: scene.json:")
        assert "'arrays/000003.npy' is missing" in message

    def test_corrupt_array_member(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(
            cake_file, tmp_path / "c.geobrep", replace={"arrays/000002.npy": b"\x93NUMPY junk"}
        )
        with pytest.raises(FormatError, match=r"'arrays/000002\.npy' is corrupt"):
            geobrep.read(path)

    def test_array_member_disagrees_with_record(self, cake_file: Path, tmp_path: Path) -> None:

        buffer = io.BytesIO()
        np.lib.format.write_array(buffer, np.zeros((2, 3), dtype=np.float32))
        path = rebuild(
            cake_file, tmp_path / "d.geobrep", replace={"arrays/000000.npy": buffer.getvalue()}
        )
        with pytest.raises(FormatError, match="record says"):
            geobrep.read(path)

    def test_missing_scene_json(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(cake_file, tmp_path / "n.dat", drop="scene.json")
        with pytest.raises(FormatError, match=r"has no scene\.json"):
            geobrep.read(path, format="native")

    def test_wrong_version(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(cake_file, tmp_path / "v.geobrep", document=lambda d: {**d, "version": 2})
        with pytest.raises(FormatError) as info:
            geobrep.read(path)
        assert str(info.value) == (
            f"{path}: container version 2 is not supported (this geobrep reads version 1)"
        )

    def test_not_a_scene_document(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(cake_file, tmp_path / "f.geobrep", document=lambda d: {**d, "format": "x"})
        with pytest.raises(FormatError, match="is not a geobrep-scene document"):
            geobrep.read(path)

    def test_invalid_json(self, cake_file: Path, tmp_path: Path) -> None:
        path = rebuild(cake_file, tmp_path / "j.geobrep", text='{\n"format": ')
        with pytest.raises(FormatError) as info:
            geobrep.read(path)
        assert info.value.line == 2
        assert str(info.value).startswith(f"{path}:2: scene.json: invalid JSON")

    def test_invalid_content(self, cake_file: Path, tmp_path: Path) -> None:
        def rename(document: dict[str, Any]) -> dict[str, Any]:
            document["scene"]["entities"][0]["name"] = 5
            return document

        path = rebuild(cake_file, tmp_path / "b.geobrep", document=rename)
        with pytest.raises(FormatError, match=r"Surface #0: name: Input should be a valid string"):
            geobrep.read(path)

    def test_bad_faces_in_file(self, tmp_path: Path) -> None:
        surface = Surface(vertices=np.eye(3), faces=[[0, 1, 2]], name="top")
        good = geobrep.write(surface, tmp_path / "s.geobrep")
        buffer = io.BytesIO()
        np.lib.format.write_array(buffer, np.array([[0, 1, 7]]))
        with zipfile.ZipFile(good) as archive:
            document = json.loads(archive.read("scene.json"))
        faces_file = document["scene"]["entities"][0]["faces"]["file"]
        path = rebuild(good, tmp_path / "bad.geobrep", replace={faces_file: buffer.getvalue()})
        with pytest.raises(FormatError, match=r"Surface 'top': faces: face 0 refers to vertex 7"):
            geobrep.read(path)

    def test_unknown_option(self, cake_file: Path, tmp_path: Path) -> None:
        with pytest.raises(OptionsError, match=r"option 'bogus': unknown option.*compress"):
            geobrep.write(Scene(), tmp_path / "o.geobrep", bogus=True)
        with pytest.raises(OptionsError, match="option 'bogus'"):
            geobrep.read(cake_file, bogus=1)
        with pytest.raises(OptionsError, match="option 'compress'"):
            geobrep.write(Scene(), tmp_path / "o.geobrep", compress="maybe")
        assert not (tmp_path / "o.geobrep").exists()

    def test_unwritable_metadata(self, tmp_path: Path) -> None:
        points = PointSet(vertices=[[0.0, 0.0, 0.0]], metadata={"x": math.nan})
        with pytest.raises(FormatError, match="not JSON compliant"):
            geobrep.write(points, tmp_path / "m.geobrep")
        assert list(tmp_path.iterdir()) == []
