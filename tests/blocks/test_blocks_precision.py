"""The default tolerance follows the precision the coordinates carry (issue 12, item 5).

Real exports round coordinates (float32, a few decimals). The model here is the sample model
scaled to 20 km, at UTM or local coordinates, with one vertex the horizon H2 does not have
inserted on the line where H2 meets the south wall and sealed by a sliver triangle — a conformal
mesh — then rounded to float32 or to centimetres, which moves that vertex off the line by
0.1–1.2 mm. The previous default (1e-7 of the diagonal, 2.9 mm) called it a T-junction of 'H2'
and 'south' and refused the model.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

import geobrep
from geobrep import Scene, Surface
from geobrep.errors import TopologyError
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks.precision import (
    CEILING,
    FLOOR,
    QUANTA,
    measure_precision,
)
from geobrep.plugins.blocks.report import block_report

FloatArray = NDArray[np.float64]
UTM = (450_000.0, 6_700_000.0, 0.0)
LOCAL = (0.0, 0.0, 0.0)


def scaled_sample(origin: tuple[float, float, float], scale: float = 20.0) -> list[Surface]:
    """The sample model's bare surfaces, scaled about their lower corner and moved there."""
    sample = geobrep.datasets.faulted_layer_cake()
    low = np.concatenate([s.vertices for s in sample.surfaces]).min(axis=0)
    return [
        Surface(
            vertices=(s.vertices - low) * scale + np.asarray(origin),
            faces=s.faces,
            name=s.name,
            kind=s.kind,
        )
        for s in sample.surfaces
    ]


def seal_vertex(wall: Surface, other: Surface) -> tuple[Surface, tuple[int, int, int]]:
    """``wall`` with a vertex V on one of its edges P→Q shared with ``other`` (the middle one
    of those), sealed by the sliver (P, Q, V) and fanned with two inner points over the
    triangle (P, Q, X) it replaces; returns the surface and the vertex indices of P, Q, V."""
    shared = {tuple(p) for p in other.vertices.tolist()}
    on_other = np.array([tuple(p) in shared for p in wall.vertices.tolist()])
    faces = wall.faces
    hits = [
        (f, int(faces[f, k]), int(faces[f, (k + 1) % 3]), int(faces[f, (k + 2) % 3]))
        for f in range(faces.shape[0])
        for k in range(3)
        if on_other[faces[f, k]]
        and on_other[faces[f, (k + 1) % 3]]
        and not on_other[faces[f, (k + 2) % 3]]
    ]
    face, p, q, x = hits[len(hits) // 2]
    big_p, big_q, big_x = wall.vertices[[p, q, x]]
    n = wall.n_vertices
    v, w1, w2 = n, n + 1, n + 2
    added = [
        0.55 * big_p + 0.45 * big_q,
        0.5 * big_p + 0.2 * big_q + 0.3 * big_x,
        0.2 * big_p + 0.5 * big_q + 0.3 * big_x,
    ]
    fan = [(p, q, v), (p, v, w1), (w1, v, w2), (w2, v, q), (w2, q, x), (w1, w2, x), (p, w1, x)]
    sealed = Surface(
        vertices=np.concatenate([wall.vertices, added]),
        faces=np.concatenate([np.delete(faces, face, axis=0), np.array(fan)]),
        name=wall.name,
        kind=wall.kind,
    )
    return sealed, (p, q, v)


def sealed_model(origin: tuple[float, float, float]) -> tuple[list[Surface], tuple[int, ...]]:
    surfaces = scaled_sample(origin)
    names = [s.name for s in surfaces]
    south, h2 = names.index("south"), names.index("H2")
    surfaces[south], corners = seal_vertex(surfaces[south], surfaces[h2])
    return surfaces, (south, *corners)


def rounded(surfaces: list[Surface], how: str) -> list[Surface]:
    def move(v: FloatArray) -> FloatArray:
        if how == "float32":
            return v.astype(np.float32).astype(np.float64)
        return np.round(v, 2)

    return [s.replace(vertices=move(s.vertices)) for s in surfaces]


def off_line(surface: Surface, p: int, q: int, v: int) -> float:
    big_p, big_q, big_v = surface.vertices[[p, q, v]]
    d = big_q - big_p
    foot = big_p + d * np.dot(big_v - big_p, d) / np.dot(d, d)
    return float(np.linalg.norm(big_v - foot))


def diagonal(surfaces: list[Surface]) -> float:
    points = np.concatenate([s.vertices for s in surfaces])
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


@pytest.mark.parametrize("origin", [UTM, LOCAL], ids=["utm", "local"])
@pytest.mark.parametrize("how", ["float32", "cm"])
def test_rounded_export_rebuilds_with_defaults(
    origin: tuple[float, float, float], how: str
) -> None:
    exact, (south, p, q, v) = sealed_model(origin)
    model = rounded(exact, how)
    # The rounding moved the sealed vertex off the line by under the previous default
    # tolerance (1e-7 of the diagonal), which called it a T-junction.
    gap = off_line(model[south], p, q, v)
    assert 1e-5 < gap < 1e-7 * diagonal(model)
    built = build_blocks(Scene(entities=model))
    truth = build_blocks(Scene(entities=scaled_sample(origin)))
    assert len(built.blocks) == len(truth.blocks) == 6
    report = block_report(built)
    assert report.tolerance_source == "precision"
    assert report.precision_source is not None
    # Each block's volume is that of the unrounded model, within what moving its boundary by
    # the largest rounding displacement can change (2 × boundary area × displacement).
    shift = max(
        float(np.linalg.norm(r.vertices - e.vertices, axis=1).max())
        for r, e in zip(model, exact, strict=True)
    )
    assert shift > 0.0
    expected = {b.name: b for b in truth.blocks}
    for block in built.blocks:
        want = truth.block_mesh(expected[block.name])
        got = built.block_mesh(block).volume
        assert block.unit_name == expected[block.name].unit_name
        assert abs(got - want.volume) <= 2.0 * want.area * shift
        assert abs(got - want.volume) / want.volume < 1e-4


def test_local_float32_volumes_are_tight() -> None:
    # At local coordinates float32 rounding moves vertices by under a millimetre.
    exact, _ = sealed_model(LOCAL)
    built = build_blocks(Scene(entities=rounded(exact, "float32")))
    truth = build_blocks(Scene(entities=scaled_sample(LOCAL)))
    expected = {b.name: truth.block_mesh(b).volume for b in truth.blocks}
    worst = max(
        abs(b.metadata["volume"] - expected[b.name]) / expected[b.name] for b in built.blocks
    )
    assert worst < 1e-6


def test_the_unrounded_sealed_model_is_conformal() -> None:
    # The sliver seals the extra vertex: the mesh is conformal and gives the sample's blocks.
    exact, _ = sealed_model(UTM)
    assert len(build_blocks(Scene(entities=exact)).blocks) == 6


@pytest.mark.parametrize(
    ("origin", "lift"), [(LOCAL, 0.1), (UTM, 10.0)], ids=["local-10cm", "utm-10m"]
)
def test_a_moved_surface_is_still_a_defect_naming_the_options(
    origin: tuple[float, float, float], lift: float
) -> None:
    exact, _ = sealed_model(origin)
    h2 = next(k for k, s in enumerate(exact) if s.name == "H2")
    exact[h2] = exact[h2].replace(vertices=exact[h2].vertices + np.array([0.0, 0.0, lift]))
    with pytest.raises(TopologyError) as caught:
        build_blocks(Scene(entities=rounded(exact, "float32")))
    message = str(caught.value)
    assert "'H2'" in message
    assert "relative_tolerance=" in message
    assert "--relative-tolerance" in message
    assert "from float32 coordinates" in message
    defects = caught.value.defects  # type: ignore[attr-defined]
    assert defects
    assert all("H2" in d.surfaces for d in defects)


def test_a_one_metre_gap_is_a_defect() -> None:
    surfaces = rounded(scaled_sample(LOCAL), "float32")
    h1 = next(k for k, s in enumerate(surfaces) if s.name == "H1")
    points = surfaces[h1].vertices
    centre = points.mean(axis=0)
    horizontal = np.array([1.0, 1.0, 0.0])
    # Shrink H1 towards its centre by 1 m at its border along x and y (20 km wide).
    span = points.max(axis=0) - points.min(axis=0)
    factor = 1.0 - 2.0 / span
    moved = centre + (points - centre) * np.where(horizontal > 0, factor, 1.0)
    surfaces[h1] = surfaces[h1].replace(vertices=moved)
    with pytest.raises(TopologyError, match="--gap-tolerance"):
        build_blocks(Scene(entities=surfaces))


def test_float64_detail_below_the_old_default_is_not_a_contact() -> None:
    # A floating lens whose top comes within 1 mm of H1 without touching it, in a 20 km box:
    # float64 coordinates resolve that, so it is geometry, not a T-junction (the previous
    # default, 1e-7 of the diagonal = 3.5 mm, said it was).
    from blocks_models import box_model, grid_surface

    box = box_model(levels=(10e3,), size=20e3)
    side = np.linspace(7e3, 13e3, 4) + np.pi
    xs, ys = np.meshgrid(side, side, indexing="ij")
    top = np.stack([xs, ys, np.full_like(xs, 10e3 - 1e-3)], axis=-1)
    lens = grid_surface(top, "lens", "horizon")
    # (its border is 1 mm from H1: the gap test, off here, would call that a gap)
    built = build_blocks(Scene(entities=[*box, lens]), gap_tolerance=0.0)
    assert block_report(built).precision_source == "float64"
    assert [e.surface for e in block_report(built).dangling] == ["lens"]
    with pytest.raises(TopologyError, match="T-junction of 'H1' and 'lens'"):
        build_blocks(Scene(entities=[*box, lens]), relative_tolerance=1e-7, gap_tolerance=0.0)


def test_measured_precision() -> None:
    rng = np.random.default_rng(7)
    points = rng.random((5000, 3)) * [20e3, 16e3, -12e3] + [450e3, 6700e3, 0.0]
    assert measure_precision(points).source == "float64"
    as32 = measure_precision(points.astype(np.float32).astype(np.float64))
    assert (as32.source, as32.quantum) == ("float32", 0.5)  # spacing at 6.7e6
    assert measure_precision(np.round(points, 3)).quantum == pytest.approx(1e-3)
    # Eight significant digits: a tenth of a metre at the northings.
    printed = np.array([float(f"{value:.8g}") for value in points.ravel()])
    digits = measure_precision(printed)
    assert (digits.source, digits.quantum) == ("8 significant digits", pytest.approx(0.1))


def test_coarse_grids_stay_within_the_ceiling() -> None:
    # Integer coordinates look like metre rounding; the tolerance stays at 1e-4 of the diagonal.
    from blocks_models import box_model

    box = box_model(levels=(40.0,), size=100.0, origin=(450_000.0, 6_700_000.0, 0.0))
    report = block_report(build_blocks(Scene(entities=box)))
    assert report.precision_source is not None
    assert report.precision is not None
    assert QUANTA * report.precision > report.tolerance
    assert report.tolerance == pytest.approx(CEILING * diagonal(box))
    assert FLOOR < CEILING


def test_explicit_options_keep_their_meaning() -> None:
    model = scaled_sample(UTM)
    report = block_report(build_blocks(Scene(entities=model), relative_tolerance=1e-7))
    assert report.tolerance_source == "relative_tolerance"
    assert report.tolerance == pytest.approx(1e-7 * diagonal(model))
    assert report.precision is None
    report = block_report(build_blocks(Scene(entities=model), tolerance=0.01))
    assert (report.tolerance, report.tolerance_source) == (0.01, "tolerance")
