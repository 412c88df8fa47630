"""The quirks of real GOCAD files: recovered with a warning, or a FormatError with path:line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.adapters.gocad import looks_like_gocad
from geobrep.adapters.gocad._parser import GocadWarning


def write(tmp_path: Path, text: str, name: str = "x.ts", crlf: bool = False) -> Path:
    path = tmp_path / name
    data = text.strip("\n") + "\n"
    path.write_bytes(data.replace("\n", "\r\n").encode() if crlf else data.encode())
    return path


TSURF = """
GOCAD TSurf 1
HEADER {
name: plate
}
TFACE
VRTX 10 0 0 0
VRTX 20 1 0 0
VRTX 30 1 1 0
TRGL 10 20 30
END
"""


def test_crlf_tabs_and_repeated_spaces(tmp_path: Path) -> None:
    text = TSURF.replace("VRTX 20 1 0 0", "VRTX\t20  1\t0   0  ").replace("TRGL 10", "TRGL  10")
    scene = geobrep.read(write(tmp_path, text, crlf=True))
    surface = scene.surfaces[0]
    assert surface.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [1, 1, 0]]
    assert surface.faces.tolist() == [[0, 1, 2]]


def test_bulk_runs_with_quirks_fall_back_to_exact_line_parsing(tmp_path: Path) -> None:
    rows = "\n".join(f"VRTX {k + 1} {k}.5 {2 * k} -{k}e+2  " for k in range(50))
    rows = rows.replace("VRTX 7 6.5", "VRTX 7 6.5000")
    trgl = "\n".join(f"TRGL {k + 1} {k + 2} {k + 3}" for k in range(48))
    text = f"GOCAD TSurf 1\nHEADER {{ name: strip }}\nTFACE\n{rows}\n{trgl}\nEND"
    surface = geobrep.read(write(tmp_path, text)).surfaces[0]
    k = np.arange(50)
    assert np.array_equal(surface.vertices, np.column_stack([k + 0.5, 2.0 * k, -100.0 * k]))
    assert surface.faces[-1].tolist() == [47, 48, 49]


def test_infinities_and_msvc_spellings(tmp_path: Path) -> None:
    text = """
GOCAD VSet 1
HEADER {
name: odd values
}
PROPERTIES a b
NO_DATA_VALUES 1e+38 -1.#INF
ESIZES 1 1
PVRTX 1 0 0 0 1.#INF 2
PVRTX 2 1 0 0 -inf 1e+38
PVRTX 3 2 0 0 nan 3 CNXYZ
END
"""
    with pytest.warns(GocadWarning, match="'a': 3 non-finite value"):
        points = geobrep.read(write(tmp_path, text, "p.vs")).point_sets[0]
    a = points.point_data["a"].values
    assert a.tolist() == [1e38, 1e38, 1e38]  # inf, -inf, nan: no data (the spellings parse)
    assert points.point_data["a"].no_data_value == 1e38
    assert points.point_data["b"].no_data_value == -math.inf
    assert points.point_data["gocad_vertex_flag"].values.tolist() == [0, 0, 1]
    back = geobrep.read(geobrep.write(points, tmp_path / "again.vs"))
    assert np.array_equal(back.point_sets[0].point_data["a"].values, a)


def test_missing_header_tface_and_end_are_recovered(tmp_path: Path) -> None:
    text = "GOCAD TSurf 1\nVRTX 1 0 0 0\nVRTX 2 1 0 0\nVRTX 3 0 1 0\nTRGL 1 2 3"
    with pytest.warns(GocadWarning) as caught:
        scene = geobrep.read(write(tmp_path, text))
    messages = " ".join(str(w.message) for w in caught)
    assert "before any TFACE" in messages
    assert "has no END" in messages
    assert scene.surfaces[0].n_faces == 1


def test_unclosed_header_and_wrapped_values(tmp_path: Path) -> None:
    text = """
GOCAD TSurf 1
HEADER {
name: wrapped
*colormap*colors: 0 0 0 1
 85 0 1 1
TFACE
VRTX 1 0 0 0
VRTX 2 1 0 0
VRTX 3 0 1 0
TRGL 1 2 3
END
"""
    with pytest.warns(GocadWarning) as caught:
        surface = geobrep.read(write(tmp_path, text)).surfaces[0]
    messages = " ".join(str(w.message) for w in caught)
    assert "not closed" in messages
    assert "continues on this line" in messages
    header = dict(surface.metadata["gocad"]["header"])
    assert header["*colormap*colors"] == "0 0 0 1\n85 0 1 1"
    assert surface.name == "wrapped"


def test_atoms_chains_and_vertices_of_earlier_tfaces(tmp_path: Path) -> None:
    text = """
GOCAD TSurf 1
HEADER {
name: parts
}
TFACE
VRTX 5 0 0 0
VRTX 7 1 0 0
VRTX 9 0 1 0
TRGL 5 7 9
TFACE
ATOM 11 7
ATOM 12 11
VRTX 13 1 1 0
TRGL 9 12 13
END
"""
    surface = geobrep.read(write(tmp_path, text)).surfaces[0]
    assert surface.vertices[3].tolist() == [1, 0, 0]
    assert surface.vertices[4].tolist() == [1, 0, 0]
    assert surface.faces.tolist() == [[0, 1, 2], [2, 4, 5]]  # TRGL uses 9 from the first TFACE
    assert surface.patch_labels.tolist() == [0, 1]


def test_quoted_names_in_model3d(tmp_path: Path) -> None:
    text = """
GOCAD Model3d 1
HEADER {
name: quoted
}
TSURF my top
TFACE 1 top my top
  0 0 0
  1 0 0
  0 1 0
REGION 2 "Upper unit"
  +1 0
END
GOCAD TSurf 1
HEADER {
name: my top
name_in_model_list: my top
}
TFACE
VRTX 1 0 0 0
VRTX 2 1 0 0
VRTX 3 0 1 0
TRGL 1 2 3
END
"""
    scene = geobrep.read(write(tmp_path, text, "q.ml"))
    (block,) = scene.blocks
    assert block.name == "Upper unit"
    assert scene["my top"].kind == "horizon"
    assert scene.patches[0].positive_block == block.id


def test_tsolid_comment_lines_are_data(tmp_path: Path) -> None:
    text = """
GOCAD TSolid 1
HEADER {
name: two
}
# a real comment
TVOLUME lower
VRTX 1 0 0 0
VRTX 2 1 0 0
VRTX 3 0 1 0
VRTX 4 0 0 1
TETRA 1 2 3 4
# CTETRA lower none +fault none -base
END
"""
    tets = geobrep.read(write(tmp_path, text, "t.so")).tet_meshes[0]
    codes = tets.cell_data["gocad_ctetra_faces"]
    assert codes.values.tolist() == [[0, 1, 0, -2]]
    assert codes.metadata["gocad"]["surfaces"] == ["fault", "base"]


@pytest.mark.parametrize(
    ("body", "message", "line"),
    [
        ("TRGL 10 20 98", "TRGL refers to vertex 98 which is not defined", 10),
        ("TRGL 10 20", "TRGL needs 3 vertex ids, found 2 entries", 10),
        ("VRTX 40 1 x 0", "VRTX: 'x' is not a number", 10),
        ("ATOM 41 99", "ATOM 41 refers to vertex 99 which is not defined before it", 10),
        ("VRTX 20 5 5 5", "vertex id 20 is already defined on line 7", 10),
        ("BSTONE 77", "BSTONE refers to vertex 77 which is not defined", 10),
    ],
)
def test_errors_name_the_file_and_line(tmp_path: Path, body: str, message: str, line: int) -> None:
    text = TSURF.replace("TRGL 10 20 30", f"TRGL 10 20 30\n{body}")
    path = write(tmp_path, text)
    with pytest.raises(geobrep.FormatError) as caught:
        geobrep.read(path)
    assert caught.value.line == line
    assert caught.value.path == path
    assert str(caught.value) == f"{path}:{line}: {message}"


def test_bulk_errors_point_at_the_line(tmp_path: Path) -> None:
    rows = "\n".join(f"VRTX {k + 1} {k} 0 0" for k in range(1000))
    trgl = "\n".join(f"TRGL {k + 1} {k + 2} {k + 3}" for k in range(998))
    trgl = trgl.replace("TRGL 501 502 503", "TRGL 501 502 5030")
    path = write(tmp_path, f"GOCAD TSurf 1\nTFACE\n{rows}\n{trgl}\nEND")
    with pytest.raises(geobrep.FormatError, match=r"x.ts:1503: TRGL refers to vertex 5030"):
        geobrep.read(path)


def test_sniffing_and_unknown_content(tmp_path: Path) -> None:
    assert looks_like_gocad(b"GOCAD TSurf 1\nHEADER {")
    assert looks_like_gocad(b"\xef\xbb\xbf\r\nGOCAD Model3d 1")
    assert not looks_like_gocad(b"ply\nformat ascii 1.0")
    path = write(tmp_path, TSURF, "no_extension")
    assert geobrep.read(path).surfaces[0].name == "plate"  # found by content
    with pytest.raises(geobrep.FormatError, match="expected 'GOCAD <type>'"):
        geobrep.read(write(tmp_path, "hello\nworld", "bad.ts"))


def test_light_tsolid_shared_vertices(tmp_path: Path) -> None:
    text = """
GOCAD LightTSolid 1
HEADER {
name: light
}
VRTX 1 0 0 0
VRTX 2 1 0 0
VRTX 3 0 1 0
VRTX 4 0 0 1
SHAREDVRTX 5 4
VRTX 6 1 1 1
TETRA 1 2 3 4
TETRA 2 3 5 6
END
"""
    tets = geobrep.read(write(tmp_path, text, "light.so")).tet_meshes[0]
    assert tets.vertices[4].tolist() == [0, 0, 1]
    assert tets.cells.tolist() == [[0, 1, 2, 3], [1, 2, 4, 5]]
    assert tets.metadata["gocad"]["type"] == "LightTSolid"


GROUP = """
GOCAD HeterogeneousGroup 1
HEADER {
name: project
}
BEGIN_MEMBERS
GOCAD VSet 1
HEADER {
name: wells
}
VRTX 1 5 5 5
END
GOCAD HomogeneousGroup 1
HEADER {
name: faults
}
TYPE TSurf
BEGIN_MEMBERS
GOCAD TSurf 1
HEADER {
name: f1
}
TFACE
VRTX 1 0 0 0
VRTX 2 1 0 0
VRTX 3 0 1 0
TRGL 1 2 3
END
END_MEMBERS
END
GOCAD PLine 1
HEADER {
name: trace
}
ILINE
VRTX 1 0 0 0
VRTX 2 2 0 0
SEG 1 2
END
END_MEMBERS
END
"""


def test_groups_nest_and_round_trip(tmp_path: Path) -> None:
    scene = geobrep.read(write(tmp_path, GROUP, "project.gp"))
    assert [type(e).__name__ for e in scene.entities] == ["PointSet", "Surface", "PolyLine"]
    (root,) = scene.groups
    assert root.name == "project"
    assert root.kind == "HeterogeneousGroup"
    assert root.members == (0, 2)
    (child,) = root.children
    assert child.name == "faults"
    assert child.kind == "HomogeneousGroup"
    assert child.members == (1,)
    assert child.metadata["gocad"]["member_type"] == "TSurf"
    again = geobrep.read(geobrep.write(scene, tmp_path / "again.gp"))
    assert again == scene


def test_garbled_bulk_values_never_parse_silently(tmp_path: Path) -> None:
    rows = "\n".join(f"PVRTX {k + 1} {k} 0 0 {k}" for k in range(100))
    for bad in ("3X", "3e", "3-", "1.2.3", "--3", "3P4", "0x10"):
        text = f"GOCAD VSet 1\nPROPERTIES a\nESIZES 1\n{rows.replace(' 0 0 7', f' 0 0 {bad}')}\nEND"
        with pytest.raises(geobrep.FormatError, match=r":11: PVRTX: .* is not a number"):
            geobrep.read(write(tmp_path, text, "bad.vs"))


def test_bulk_runs_reject_what_a_number_parser_would_misread(tmp_path: Path) -> None:
    vrtx = "\n".join(f"VRTX {k + 1} {k} 0 0" for k in range(10))
    trgl = [f"TRGL {k + 1} {k + 2} {k + 3}" for k in range(8)]

    def read(lines: list[str]) -> geobrep.Scene:
        body = "\n".join(lines)
        return geobrep.read(write(tmp_path, f"GOCAD TSurf 1\nTFACE\n{vrtx}\n{body}\nEND"))

    for bad, token in (("TRGL 4 5 -", "-"), ("TRGL 4 5 true", "true")):  # numpy reads "-" as 0
        with pytest.raises(geobrep.FormatError, match=f":16: TRGL: '{token}' is not an integer"):
            read([*trgl[:3], bad, *trgl[4:]])
    # One line too long, the next too short: the numbers are never shifted silently.
    too_few = ":17: TRGL needs 3 vertex ids, found 2"
    with (
        pytest.warns(GocadWarning, match="extra entries"),
        pytest.raises(geobrep.FormatError, match=too_few),
    ):
        read([*trgl[:3], "TRGL 4 5 6 7", "TRGL 5 6", *trgl[5:]])
    spaced = "\n".join(f"VRTX  {k + 1}\t{k}.25  0 0 " for k in range(10))  # every line odd
    text = f"GOCAD TSurf 1\nTFACE\n{spaced}\n" + "\n".join(trgl) + "\nEND"
    surface = geobrep.read(write(tmp_path, text)).surfaces[0]
    assert surface.vertices[:, 0].tolist() == [k + 0.25 for k in range(10)]
