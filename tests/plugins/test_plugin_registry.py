"""Registered items, option validation, registries and reader/writer choice."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from pydantic import BaseModel, ConfigDict, ValidationError

from geobrep.errors import GeobrepError, OptionsError, PluginError, UnknownFormatError
from geobrep.host.registry import (
    SNIFF_BYTES,
    BuilderSpec,
    ClipperRegistry,
    ClipperSpec,
    FitterSpec,
    FormatCapabilities,
    FormatRegistry,
    FormatSpec,
    GeobrepPluginWarning,
    NoOptions,
    Registries,
    UnknownItemError,
)


def read(path: Path, options: Any) -> None:
    return None


def write(scene: Any, path: Path, options: Any) -> None:
    return None


class PrecisionOptions(BaseModel):
    model_config = ConfigDict(extra="forbid")
    precision: int = 6
    units: str = "m"


class LaxOptions(BaseModel):  # forgot extra="forbid"
    precision: int = 6


# --- items ---------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["xyz", "surface.plane", "gocad-ts", "a_1", "3d"])
def test_valid_names(name: str) -> None:
    assert FitterSpec(name=name, function=print).name == name


@pytest.mark.parametrize("name", ["", "XYZ", "has space", "_private", ".dot", "é"])
def test_invalid_names_are_rejected(name: str) -> None:
    with pytest.raises(ValidationError, match="fitter name"):
        FitterSpec(name=name, function=print)


def test_items_are_frozen() -> None:
    spec = ClipperSpec(name="surface", entity_type="Surface", function=print)
    with pytest.raises(ValidationError):
        spec.name = "other"  # type: ignore[misc]


def test_extensions_are_normalised() -> None:
    spec = FormatSpec(name="f", extensions=("XYZ", ".Tar.GZ", " .xyz "), reader=read)
    assert spec.extensions == (".xyz", ".tar.gz")
    assert FormatSpec(name="g", extensions=".TS", reader=read).extensions == (".ts",)


@pytest.mark.parametrize("bad", ["", ".", "a b", "x/y"])
def test_bad_extensions_are_rejected(bad: str) -> None:
    with pytest.raises(ValidationError, match="extension"):
        FormatSpec(name="f", extensions=(bad,), reader=read)


def test_format_needs_reader_or_writer() -> None:
    with pytest.raises(ValidationError, match="format 'nothing' needs a reader, a writer"):
        FormatSpec(name="nothing", extensions=(".n",))
    reader_only = FormatSpec(name="r", reader=read)
    writer_only = FormatSpec(name="w", writer=write)
    assert (reader_only.can_read, reader_only.can_write) == (True, False)
    assert (writer_only.can_read, writer_only.can_write) == (False, True)


def test_reader_must_be_callable() -> None:
    with pytest.raises(ValidationError):
        FormatSpec(name="r", reader="not callable")


def test_capabilities_default_to_nothing() -> None:
    caps = FormatSpec(name="r", reader=read).capabilities
    assert caps == FormatCapabilities()
    assert caps.entity_types == frozenset()
    flags = [caps.point_data, caps.cell_data, caps.names, caps.ids, caps.topology, caps.crs]
    assert not any([*flags, caps.multiple_entities])
    with pytest.raises(ValidationError):
        FormatCapabilities(point_dta=True)  # type: ignore[call-arg]


def test_default_options_model_is_empty_and_strict() -> None:
    spec = BuilderSpec(name="blocks", function=print)
    assert spec.options is NoOptions
    assert spec.validate_options() == NoOptions()
    with pytest.raises(OptionsError, match=r"builder 'blocks': option 'speed': unknown option"):
        spec.validate_options(speed=3)


# --- options -------------------------------------------------------------------------------


@pytest.fixture
def xyz() -> FormatSpec:
    return FormatSpec(name="xyz", reader=read, options=PrecisionOptions)


def test_options_from_mapping_keywords_and_model(xyz: FormatSpec) -> None:
    assert xyz.validate_options({"precision": 3}) == PrecisionOptions(precision=3)
    assert xyz.validate_options(precision="4") == PrecisionOptions(precision=4)
    expected = PrecisionOptions(precision=3, units="ft")
    assert xyz.validate_options({"precision": 3}, units="ft") == expected
    given = PrecisionOptions(precision=2)
    assert xyz.validate_options(given) is given
    assert xyz.validate_options(given, units="ft") == PrecisionOptions(precision=2, units="ft")
    assert xyz.validate_options(None) == PrecisionOptions()


def test_options_error_names_item_and_option(xyz: FormatSpec) -> None:
    with pytest.raises(OptionsError) as caught:
        xyz.validate_options({"precision": "many"})
    assert str(caught.value) == (
        "format 'xyz': option 'precision': Input should be a valid integer, "
        "unable to parse string as an integer"
    )
    assert isinstance(caught.value, ValueError)
    assert isinstance(caught.value.__cause__, ValidationError)


def test_options_error_lists_every_bad_option(xyz: FormatSpec) -> None:
    with pytest.raises(OptionsError) as caught:
        xyz.validate_options(precision=[], units=5, colour="red")
    message = str(caught.value)
    assert message.startswith("format 'xyz': ")
    assert "option 'precision': Input should be a valid integer" in message
    assert "option 'units': Input should be a valid string" in message
    assert "option 'colour': unknown option (valid options: precision, units)" in message


def test_unknown_option_rejected_even_if_model_ignores_extras() -> None:
    spec = FitterSpec(name="lax", function=print, options=LaxOptions)
    with pytest.raises(OptionsError, match=r"fitter 'lax': option 'precison': unknown option"):
        spec.validate_options(precison=3)


def test_option_given_twice(xyz: FormatSpec) -> None:
    with pytest.raises(OptionsError, match="option 'precision' given twice"):
        xyz.validate_options({"precision": 1}, precision=2)


def test_options_of_the_wrong_type(xyz: FormatSpec) -> None:
    with pytest.raises(OptionsError, match="must be a PrecisionOptions"):
        xyz.validate_options(LaxOptions())
    with pytest.raises(OptionsError, match="must be a mapping"):
        xyz.validate_options([("precision", 1)])  # type: ignore[arg-type]


# --- registries ----------------------------------------------------------------------------


def clipper(name: str, plugin: str = "") -> ClipperSpec:
    return ClipperSpec(name=name, entity_type="Surface", function=print, plugin=plugin)


def test_registry_basics() -> None:
    registry = ClipperRegistry([clipper("surface"), clipper("pointset")])
    assert len(registry) == 2
    assert "surface" in registry
    assert "polyline" not in registry
    assert registry.names() == ["pointset", "surface"]
    assert [item.name for item in registry] == ["pointset", "surface"]
    assert registry.get("surface").entity_type == "Surface"
    assert registry.for_entity_type("Surface") == list(registry)
    assert repr(registry) == "ClipperRegistry(['pointset', 'surface'])"


def test_unknown_name_lists_what_is_registered() -> None:
    registry = ClipperRegistry([clipper("surface"), clipper("pointset")])
    with pytest.raises(UnknownItemError) as caught:
        registry.get("polyline")
    assert str(caught.value) == "unknown clipper 'polyline'; registered clippers: pointset, surface"
    assert isinstance(caught.value, KeyError)
    assert isinstance(caught.value, GeobrepError)
    with pytest.raises(KeyError, match="no clippers are registered"):
        ClipperRegistry().get("surface")


def test_duplicate_from_another_plugin_warns_and_first_wins() -> None:
    registry = ClipperRegistry()
    first = registry.add(clipper("surface", plugin="a"))
    with pytest.warns(GeobrepPluginWarning, match="clipper 'surface' from plugin 'b' ignored"):
        kept = registry.add(clipper("surface", plugin="b"))
    assert kept is first
    assert registry.get("surface").plugin == "a"


def test_duplicate_from_the_same_plugin_is_an_error() -> None:
    registry = ClipperRegistry(plugin="a")
    registry.add(clipper("surface"))
    with pytest.raises(PluginError, match="clipper 'surface' registered twice by plugin 'a'"):
        registry.add(clipper("surface"))


def test_staging_registry_stamps_the_plugin() -> None:
    registry = ClipperRegistry(plugin="mine")
    stored = registry.add(clipper("surface", plugin="someone-else"))
    assert stored.plugin == "mine"


def test_registry_rejects_items_of_the_wrong_kind() -> None:
    with pytest.raises(PluginError, match=r"FormatRegistry.add\(\) takes a FormatSpec"):
        FormatRegistry().add(clipper("surface"))  # type: ignore[arg-type]


def test_registries_container() -> None:
    registries = Registries()
    assert set(registries.by_kind()) == {
        "formats",
        "clippers",
        "fitters",
        "builders",
        "voxelizers",
        "checks",
        "operations",
    }
    assert registries.by_kind()["formats"] is registries.formats
    with pytest.raises(AttributeError):
        registries.formats = FormatRegistry()  # type: ignore[misc]
    staged = Registries.staging("p")
    assert all(registry.plugin == "p" for registry in staged.by_kind().values())


# --- choosing readers and writers ----------------------------------------------------------


def sniffer(magic: bytes) -> Any:
    return lambda head: head.startswith(magic)


@pytest.fixture
def formats() -> FormatRegistry:
    return FormatRegistry(
        [
            FormatSpec(name="ts", extensions=(".ts",), reader=read, writer=write),
            FormatSpec(name="gz", extensions=(".gz",), reader=read),
            FormatSpec(name="targz", extensions=(".tar.gz",), reader=read, writer=write),
            FormatSpec(name="alpha", extensions=(".dat",), reader=read, sniff=sniffer(b"ALPHA")),
            FormatSpec(name="beta", extensions=(".dat",), reader=read, sniff=sniffer(b"BETA")),
            FormatSpec(name="magic", extensions=(".mgc",), reader=read, sniff=sniffer(b"MAGIC")),
            FormatSpec(name="outonly", extensions=(".out", ".dat"), writer=write),
        ]
    )


def test_lookup_by_extension(formats: FormatRegistry) -> None:
    assert [f.name for f in formats.for_extension("DAT")] == ["alpha", "beta", "outonly"]
    assert [f.name for f in formats.for_extension(".tar.gz")] == ["targz"]
    assert "outonly" not in [f.name for f in formats.readers()]
    assert [f.name for f in formats.writers()] == ["outonly", "targz", "ts"]


def test_choose_reader_by_extension(formats: FormatRegistry, tmp_path: Path) -> None:
    assert formats.choose_reader(tmp_path / "model.TS").name == "ts"
    assert formats.choose_reader("archive.tar.gz").name == "targz"  # longest suffix wins
    assert formats.choose_reader("data.gz").name == "gz"


def test_choose_reader_sniffs_between_formats_sharing_an_extension(
    formats: FormatRegistry, tmp_path: Path
) -> None:
    path = tmp_path / "x.dat"
    path.write_bytes(b"BETA 1 2 3")
    assert formats.choose_reader(path).name == "beta"
    path.write_bytes(b"ALPHA")
    assert formats.choose_reader(path).name == "alpha"


def test_choose_reader_sniffs_when_no_extension_matches(
    formats: FormatRegistry, tmp_path: Path
) -> None:
    path = tmp_path / "mystery.bin"
    path.write_bytes(b"MAGIC" + b"\0" * 10_000)
    assert formats.choose_reader(path).name == "magic"


def test_sniff_gets_at_most_the_first_bytes(tmp_path: Path) -> None:
    seen: list[int] = []

    def sniff(head: bytes) -> bool:
        seen.append(len(head))
        return True

    registry = FormatRegistry([FormatSpec(name="any", reader=read, sniff=sniff)])
    path = tmp_path / "big"
    path.write_bytes(b"x" * (3 * SNIFF_BYTES))
    assert registry.choose_reader(path).name == "any"
    assert seen == [SNIFF_BYTES]


def test_explicit_format_wins(formats: FormatRegistry, tmp_path: Path) -> None:
    assert formats.choose_reader(tmp_path / "model.ts", format="gz").name == "gz"
    assert formats.choose_writer(tmp_path / "model.ts", format="targz").name == "targz"


def test_explicit_unknown_format(formats: FormatRegistry) -> None:
    with pytest.raises(UnknownFormatError, match="unknown format 'nope'; formats that can read: "):
        formats.choose_reader("a.ts", format="nope")
    with pytest.raises(UnknownFormatError, match="format 'outonly' cannot read"):
        formats.choose_reader("a.out", format="outonly")
    with pytest.raises(UnknownFormatError, match="format 'gz' cannot write"):
        formats.choose_writer("a.gz", format="gz")


def test_no_reader_lists_installed_formats(formats: FormatRegistry, tmp_path: Path) -> None:
    path = tmp_path / "points.abc"
    path.write_text("nothing anyone knows")
    with pytest.raises(UnknownFormatError) as caught:
        formats.choose_reader(path)
    error = caught.value
    assert error.path == path
    message = str(error)
    assert message.startswith(f"{path}: no installed format can read this file")
    assert "ts (.ts)" in message
    assert "targz (.tar.gz)" in message
    assert "alpha (.dat)" in message
    assert "outonly" not in message


def test_ambiguous_reader_lists_candidates(formats: FormatRegistry, tmp_path: Path) -> None:
    path = tmp_path / "x.dat"
    path.write_bytes(b"GAMMA")  # neither alpha nor beta recognises it
    with pytest.raises(UnknownFormatError) as caught:
        formats.choose_reader(path)
    message = str(caught.value)
    assert "several formats can read this file: alpha (.dat); beta (.dat)" in message
    assert "pass format='<name>'" in message


def test_several_sniffers_agreeing_is_ambiguous(tmp_path: Path) -> None:
    registry = FormatRegistry(
        [
            FormatSpec(name="one", reader=read, sniff=sniffer(b"")),
            FormatSpec(name="two", reader=read, sniff=sniffer(b"")),
        ]
    )
    path = tmp_path / "anything"
    path.write_bytes(b"data")
    with pytest.raises(UnknownFormatError, match="several formats can read this file: one"):
        registry.choose_reader(path)


def test_unreadable_paths_are_treated_as_no_content(
    formats: FormatRegistry, tmp_path: Path
) -> None:
    folder = tmp_path / "folder.dat"
    folder.mkdir()
    with pytest.raises(UnknownFormatError, match="several formats can read"):
        formats.choose_reader(folder)
    with pytest.raises(UnknownFormatError, match="no installed format can read"):
        formats.choose_reader(tmp_path / "missing.bin")
    assert formats.choose_reader(tmp_path / "missing.ts").name == "ts"


def test_sniff_that_raises_is_a_warning_and_no_match(tmp_path: Path) -> None:
    def broken(head: bytes) -> bool:
        raise ValueError("bad sniff")

    registry = FormatRegistry(
        [
            FormatSpec(name="broken", reader=read, sniff=broken, plugin="p"),
            FormatSpec(name="good", reader=read, sniff=sniffer(b"G")),
        ]
    )
    path = tmp_path / "file"
    path.write_bytes(b"G")
    with pytest.warns(GeobrepPluginWarning, match="format 'broken' from plugin 'p': sniff raised"):
        assert registry.choose_reader(path).name == "good"


def test_choose_writer(formats: FormatRegistry, tmp_path: Path) -> None:
    assert formats.choose_writer(tmp_path / "out.ts").name == "ts"
    assert formats.choose_writer(tmp_path / "a.tar.gz").name == "targz"
    assert formats.choose_writer(tmp_path / "a.dat").name == "outonly"  # the only .dat writer
    with pytest.raises(UnknownFormatError, match=r"no installed format writes extension \.gz"):
        formats.choose_writer(tmp_path / "a.gz")


def test_choose_writer_ambiguous(tmp_path: Path) -> None:
    registry = FormatRegistry(
        [
            FormatSpec(name="one", extensions=(".x",), writer=write),
            FormatSpec(name="two", extensions=(".x",), writer=write),
        ]
    )
    with pytest.raises(UnknownFormatError, match=r"several formats can write.*one \(\.x\)"):
        registry.choose_writer(tmp_path / "a.x")
