"""SKUA horizon stacks (.xml): the stratigraphic column of the reference file (4 horizons and 5
units, checked against the file's own elements and against OpenGeode-GeosciencesIO when it is
installed), byte-exact writing, generated columns read back, mutated files, hostile XML, and the
format's place in the registry, ``geobrep info``, ``convert`` and pipelines."""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from xml.etree import ElementTree

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import geobrep
from geobrep import FormatError, Scene
from geobrep.adapters.gocad import _safe_xml
from geobrep.adapters.gocad._horizons_stack import horizons_stack_text
from geobrep.cli import main
from geobrep.errors import EntityValidationError
from geobrep.host import registries
from geobrep.host.capabilities import SKIPPED_ON_READ, format_losses
from geobrep.model.scene import STRATIGRAPHIC_COLUMN, Group

STACK = (
    Path(__file__).resolve().parent.parent / "data" / "opengeode" / "test_skua_horizons_stack.xml"
)
HORIZONS = ["model_erosion", "model_horizon_h1", "model_horizon_h2", "model_horizon_h3"]
UNITS = [
    "above_model_erosion",
    "eroded_unit",
    "model_horizon_u1",
    "model_horizon_u2",
    "model_horizon_u3",
]


def _parts(column: Group) -> tuple[list[Group], list[Group]]:
    parts = {c.kind: list(c.children) for c in column.children}
    return parts["horizons"], parts["stratigraphic_units"]


def test_the_reference_stack_reads_as_four_horizons_and_five_units() -> None:
    scene = geobrep.read(STACK)
    assert scene.entities == ()
    assert len(scene.stratigraphic_columns) == 1
    column = scene.stratigraphic_columns[0]
    assert column.name == "skua_model"
    assert column.kind == STRATIGRAPHIC_COLUMN
    horizons, units = _parts(column)
    assert [h.name for h in horizons] == HORIZONS
    assert [u.name for u in units] == UNITS
    # against the file itself: the units in file order, the horizons their tops and bases name
    root = ElementTree.parse(STACK).getroot()
    file_units = root.findall("./LocalStratigraphicColumn/units/unit")
    assert [u.findtext("name") for u in file_units] == UNITS
    named = [u.findtext(f"{side}/name") for u in file_units for side in ("top", "base")]
    assert list(dict.fromkeys(n for n in named if n)) == HORIZONS
    erosion = units[1].metadata
    assert erosion["top"] == {
        "horizon": "model_erosion",
        "relation": "structural",
        "color": [1.0, 0.270588, 0.0, 1.0],
    }
    assert units[0].metadata["color"] == [0.827451, 0.827451, 0.827451, 1.0]
    assert "top" not in units[0].metadata
    assert "base" not in units[-1].metadata
    assert column.metadata["skua"] == {
        "attributes": {"version": "2.0"},
        "classification_type": "chronostratigraphy",
        "rank_names": ["Eon"],
        "units_attributes": {"use_base_names": "false"},
    }
    # consecutive units share their boundary: the base of one is the top of the next
    for upper, lower in itertools.pairwise(units):
        assert upper.metadata["base"]["horizon"] == lower.metadata["top"]["horizon"]


def test_writing_what_was_read_gives_the_same_bytes(tmp_path: Path) -> None:
    scene = geobrep.read(STACK)
    out = geobrep.write(scene, tmp_path / "again.xml")
    assert out.read_bytes() == STACK.read_bytes()
    assert geobrep.read(out).groups == scene.groups
    native = geobrep.write(scene, tmp_path / "stack.geobrep")
    assert geobrep.read(native).groups == scene.groups


def test_the_reference_reader_agrees(tmp_path: Path) -> None:
    og = pytest.importorskip("opengeode")
    ogg = pytest.importorskip("opengeode_geosciences")
    pytest.importorskip("opengeode_geosciencesio").OpenGeodeGeosciencesIOModelLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)
    column = geobrep.read(STACK).stratigraphic_columns[0]
    renamed = column.model_copy(update={"name": "renamed"})
    path = geobrep.write(Scene(groups=[renamed]), tmp_path / "renamed.xml")
    for source in (STACK, path):
        stack = ogg.load_horizons_stack3D(str(source))
        assert stack.nb_horizons() == 4
        assert stack.nb_stratigraphic_units() == 5
        assert [h.name() for h in stack.top_to_bottom_horizons()] == HORIZONS
        assert [u.name() for u in stack.top_to_bottom_units()] == UNITS


_NAMES = st.text(
    st.characters(codec="utf-8", exclude_categories=("Cs", "Cc", "Zs", "Zl", "Zp")),
    min_size=1,
    max_size=12,
)
_COLORS = st.none() | st.lists(st.floats(0.0, 1.0, allow_subnormal=False), min_size=3, max_size=4)


@st.composite
def _columns(draw: st.DrawFn) -> Group:
    """A column of distinct units between distinct horizons, as SKUA stacks them."""
    horizons = draw(st.lists(_NAMES, min_size=1, max_size=6, unique=True))
    units = draw(st.lists(_NAMES, min_size=len(horizons) + 1, max_size=len(horizons) + 1))
    colors = {h: draw(_COLORS) for h in horizons}
    relations = st.sampled_from(["stratigraphic", "structural", "erosion & <onlap>"])
    unit_groups = []
    for index, name in enumerate(units):
        metadata: dict[str, object] = {}
        color = draw(_COLORS)
        if color is not None:
            metadata["color"] = color
        for side, at in (("top", index - 1), ("base", index)):
            if 0 <= at < len(horizons):
                boundary: dict[str, object] = {"horizon": horizons[at]}
                boundary["relation"] = draw(relations)
                if colors[horizons[at]] is not None:
                    boundary["color"] = colors[horizons[at]]
                metadata[side] = boundary
        unit_groups.append(Group(name=name, kind="stratigraphic_unit", metadata=metadata))
    horizon_groups = [
        Group(name=h, kind="horizon", metadata={} if c is None else {"color": c})
        for h, c in colors.items()
    ]
    return Group(
        name=draw(_NAMES),
        kind=STRATIGRAPHIC_COLUMN,
        metadata={"skua": {"attributes": {"version": "2.0"}, "units_attributes": {}}},
        children=(
            Group(name="horizons", kind="horizons", children=tuple(horizon_groups)),
            Group(name="units", kind="stratigraphic_units", children=tuple(unit_groups)),
        ),
    )


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(columns=st.lists(_columns(), min_size=1, max_size=3))
def test_generated_columns_read_back_exactly(tmp_path: Path, columns: list[Group]) -> None:
    scene = Scene(groups=columns)
    back = geobrep.read(geobrep.write(scene, tmp_path / "gen.xml"))
    assert back.groups == scene.groups
    assert SKIPPED_ON_READ not in back.metadata


def _mutate(data: bytes, where: int, how: int, byte: int) -> bytes:
    at = where % (len(data) + 1)
    if how == 0:
        return data[:at] + data[at + 1 :]
    if how == 1:
        return data[:at] + bytes([byte]) + data[at:]
    if how == 2:
        return data[:at] + bytes([byte]) + data[at + 1 :]
    return data[:at]  # truncated


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    edits=st.lists(
        st.tuples(st.integers(0, 4000), st.integers(0, 3), st.integers(0, 255)),
        min_size=1,
        max_size=4,
    )
)
@example(edits=[(STACK.read_bytes().index(b"0.827451"), 1, ord("x"))])  # a colour not a number
@example(edits=[(STACK.read_bytes().index(b"</unit>"), 1, ord("<"))])  # not well-formed
def test_mutated_stacks_read_or_fail_with_a_format_error(
    tmp_path: Path, edits: list[tuple[int, int, int]]
) -> None:
    data = STACK.read_bytes()
    for where, how, byte in edits:
        data = _mutate(data, where, how, byte)
    path = tmp_path / "mutated.xml"
    path.write_bytes(data)
    try:
        scene = geobrep.read(path, format="skua")
    except FormatError as error:
        failure: str | None = str(error)
    else:
        failure = None
    if failure is not None:
        assert "reader failed" not in failure
        return
    assert scene.stratigraphic_columns
    again = geobrep.read(geobrep.write(scene, tmp_path / "again.xml"))
    assert again.groups == scene.groups


@pytest.mark.parametrize(
    ("text", "message", "line"),
    [
        (
            '<?xml version="1.0"?>\n<!DOCTYPE l [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>\n'
            "<UserObjects>&b;</UserObjects>",
            "a <!DOCTYPE> is refused",
            2,
        ),
        (
            '<!DOCTYPE u [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<UserObjects>&x;</UserObjects>',
            "a <!DOCTYPE> is refused",
            1,
        ),
        ("<UserObjects>&x;</UserObjects>", "not well-formed XML: undefined entity", 1),
        ("<UserObjects>\n<a>" * 2, "not well-formed XML", 3),
        ("<UserObjects>" + "<a>" * 100 + "</a>" * 100 + "</UserObjects>", "nested more than 64", 1),
        ("<Other/>", "the root element is <Other>, not <UserObjects>", 1),
        ("<UserObjects>\n</UserObjects>", "holds no <LocalStratigraphicColumn>", 1),
        (
            "<UserObjects><LocalStratigraphicColumn><name>c</name><units>\n<unit>"
            "<name>u</name><color>0.1 red 0.3</color></unit></units>"
            "</LocalStratigraphicColumn></UserObjects>",
            "<color> '0.1 red 0.3' is not numbers",
            2,
        ),
        (
            "<UserObjects><LocalStratigraphicColumn><name>c</name><units><unit>\n"
            "<name>u</name><top><relation>s</relation></top></unit></units>"
            "</LocalStratigraphicColumn></UserObjects>",
            "<top> has no <name>",
            2,
        ),
        (
            "<UserObjects><LocalStratigraphicColumn><name>c</name>\n"
            "</LocalStratigraphicColumn></UserObjects>",
            "a column has 0 <units> elements, not 1",
            1,
        ),
    ],
)
def test_hostile_and_broken_xml_is_a_format_error_at_its_line(
    tmp_path: Path, text: str, message: str, line: int
) -> None:
    path = tmp_path / "bad.xml"
    path.write_text(text)
    with pytest.raises(FormatError) as caught:
        geobrep.read(path, format="skua")
    assert message in caught.value.message
    assert caught.value.line == line
    assert caught.value.path == path


def test_a_file_larger_than_the_limit_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(_safe_xml, "MAX_XML_BYTES", 1000)
    with pytest.raises(FormatError, match="more than the 1000 B an XML file may be"):
        geobrep.read(STACK)


def test_unknown_elements_are_reported_as_skipped(tmp_path: Path) -> None:
    text = STACK.read_text().replace(
        "<name>eroded_unit</name>", "<name>eroded_unit</name>\n    <age>12 Ma</age>"
    )
    path = tmp_path / "extra.xml"
    path.write_text(text)
    scene = geobrep.read(path)
    assert scene.metadata[SKIPPED_ON_READ] == ["<age> of <unit> (line 20)"]
    spec = registries().formats.get("skua")
    assert format_losses(scene, spec, tmp_path / "x.xml")[0].startswith("skipped on read: <age>")


def test_the_format_is_chosen_by_its_root_element(tmp_path: Path) -> None:
    formats = registries().formats
    assert formats.choose_reader(STACK).name == "skua"
    assert formats.choose_writer(tmp_path / "out.xml").name == "skua"
    head = STACK.read_bytes()
    spec = formats.get("skua")
    assert spec.sniff is not None
    assert spec.sniff(head)
    assert spec.sniff(b'\xef\xbb\xbf<?xml version="1.0"?>\n<!-- SKUA -->\n<UserObjects>')
    assert not spec.sniff(b"<VTKFile type='UnstructuredGrid'>")
    stack = tmp_path / "noext"
    stack.write_bytes(head)
    assert formats.choose_reader(stack).name == "skua"


def test_writing_needs_a_column_and_reports_what_it_drops(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="no stratigraphic column"):
        geobrep.write(Scene(entities=[geobrep.PointSet(vertices=[[0, 0, 0]])]), tmp_path / "a.xml")
    column = geobrep.read(STACK).groups[0]
    points = geobrep.PointSet(vertices=[[0, 0, 0]], name="p", id=0)
    scene = Scene(entities=[points], groups=[column, Group(name="wells", members=(0,))])
    spec = registries().formats.get("skua")
    assert format_losses(scene, spec, tmp_path / "a.xml") == [
        "1 PointSet entities dropped (format holds no entities)",
        "1 groups other than stratigraphic columns dropped",
    ]
    out = geobrep.write(scene, tmp_path / "a.xml")
    assert out.read_bytes() == STACK.read_bytes()


def test_a_column_the_xml_cannot_hold_is_refused_by_name(tmp_path: Path) -> None:
    column = geobrep.read(STACK).groups[0]
    units = column.children[1]
    bad = units.children[0].model_copy(update={"name": "bell\x07"})
    broken = column.model_copy(
        update={"children": (column.children[0], units.model_copy(update={"children": (bad,)}))}
    )
    with pytest.raises(EntityValidationError, match=r"groups\['bell\\x07'\]\.name"):
        geobrep.write(Scene(groups=[broken]), tmp_path / "bad.xml")
    assert not (tmp_path / "bad.xml").exists()


def test_info_convert_and_pipelines_see_the_stack(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    source = tmp_path / "stack.xml"
    source.write_bytes(STACK.read_bytes())
    assert main(["info", "stack.xml", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["stratigraphic_columns"] == [
        {"name": "skua_model", "horizons": HORIZONS, "units": UNITS}
    ]
    assert main(["info", "stack.xml"]) == 0
    out = capsys.readouterr().out
    assert "stratigraphic column 'skua_model': 4 horizons, 5 units (top down)" in out
    assert main(["convert", "stack.xml", "stack.geobrep"]) == 0
    assert main(["convert", "stack.geobrep", "back.xml"]) == 0
    assert "nothing read" not in capsys.readouterr().err
    assert (tmp_path / "back.xml").read_bytes() == STACK.read_bytes()
    pipeline = geobrep.Pipeline.from_data(
        {"steps": [{"read": {}}, {"write": {"format": "skua", "name": "{stem}_out.xml"}}]}
    )
    summary = geobrep.run_pipeline(pipeline, inputs=[source], output=tmp_path / "out")
    assert summary.ok, summary.reports
    assert (tmp_path / "out" / "stack_out.xml").read_bytes() == STACK.read_bytes()


def test_the_text_of_a_column_is_the_file() -> None:
    assert horizons_stack_text(geobrep.read(STACK)) == STACK.read_text()
