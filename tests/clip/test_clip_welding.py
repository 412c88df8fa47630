"""A surface closed only once its seams are welded is clipped without caps, with a warning
(issue 15 item 10)."""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
import pytest

import geobrep
from geobrep import Surface
from geobrep.geometry import mesh
from geobrep.plugins.clip._welding import UnweldedSurfaceWarning, closed_once_welded

CORNERS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float
)
FACES = np.array(
    [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
     [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
)  # fmt: skip
PLANE = [0.0, 0.0, 1.0, -0.5]  # z = 0.5


def _seamed_cube() -> Surface:
    """The unit cube whose top face has its own copies of the top corners (1e-13 apart)."""
    vertices = np.vstack([CORNERS, CORNERS[4:] + 1e-13])
    faces = FACES.copy()
    faces[2:4] += 4
    return Surface(vertices=vertices, faces=faces, name="seamed")


def _sliver_cube() -> Surface:
    """The unit cube with a near-duplicate of corner 6 and a sliver face joining the two."""
    vertices = np.vstack([CORNERS, CORNERS[6] + 1e-13])
    faces = FACES.copy()
    faces[3] = [4, 8, 7]  # the top's second triangle uses the copy of 6 ...
    sliver = np.array([[4, 6, 8]])  # ... and a zero-area face closes the gap
    return Surface(vertices=vertices, faces=np.vstack([faces, sliver]), name="sliver")


def test_the_test_surfaces_are_open_as_given() -> None:
    assert Surface(vertices=CORNERS, faces=FACES).is_closed
    assert not _seamed_cube().is_closed
    assert not _sliver_cube().is_closed


@pytest.mark.parametrize(("make", "welded"), [(_seamed_cube, (4, 0)), (_sliver_cube, (1, 1))])
def test_closed_once_welded_counts_welds_and_collapsed_faces(
    make: Callable[[], Surface], welded: tuple[int, int]
) -> None:
    assert closed_once_welded(make(), 1e-9) == welded
    assert closed_once_welded(make(), 1e-15) is None  # the copies are farther than that


@pytest.mark.parametrize("make", [_seamed_cube, _sliver_cube])
def test_clipping_an_unwelded_closed_surface_warns_and_says_how(
    make: Callable[[], Surface],
) -> None:
    with pytest.warns(UnweldedSurfaceWarning, match="closed once .* welded.* not capped"):
        halves = geobrep.clip(make(), PLANE, keep="both")
    assert all(not half.is_closed for half in halves)  # what the warning is about


def test_welded_surface_is_capped_without_warning() -> None:
    seamed = _seamed_cube()
    vertices, inverse = mesh.merge_close_vertices(seamed.vertices, 1e-9)
    welded = Surface(vertices=vertices, faces=inverse[seamed.faces])
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnweldedSurfaceWarning)
        lower, upper = geobrep.clip(welded, PLANE, keep="both")
    assert lower.is_closed
    assert upper.is_closed
    assert mesh.signed_volume(lower.vertices, lower.faces) == pytest.approx(0.5, abs=1e-12)


def test_open_surfaces_and_misses_do_not_warn() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnweldedSurfaceWarning)
        geobrep.clip(Surface(vertices=CORNERS, faces=FACES[2:]), PLANE, keep="both")  # open box
        geobrep.clip(_seamed_cube(), [0.0, 0.0, 1.0, -5.0], keep="both")  # plane misses it
        geobrep.clip(_seamed_cube(), PLANE, keep="both", options={"surface": {"caps": "never"}})
