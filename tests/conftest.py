"""Shared fixtures: small geometries whose answers are known by hand, and the sample model.

* ``unit_cube`` — the cube [0, 1]³ as 12 outward triangles (volume 1, area 6);
  ``unit_cube_at(origin)`` builds the same cube shifted, e.g. to UTM coordinates.
* ``tetra`` — the corner tetrahedron (0, e_x, e_y, e_z), outward (volume 1/6).
* ``layer_cake`` — ``geobrep.datasets.faulted_layer_cake()``, built once per session.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import pytest
from hypothesis import HealthCheck, settings
from shapes import TETRA_FACES, TETRA_VERTICES, make_cube

import geobrep
from geobrep import Scene, Surface

# The suite's property tests draw the same examples on every machine (``derandomize``), so a
# clean-clone run reproduces exactly what passed here; ``make fuzz-properties`` explores with fresh
# random examples (``geobrep-explore``, GEOBREP_EXAMPLES per test) and hypothesis prints the
# ``@reproduce_failure`` line of anything it finds, to be kept as an ``@example``.
settings.register_profile(
    "geobrep",
    deadline=None,
    max_examples=50,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("geobrep-thorough", deadline=None, max_examples=500)
settings.register_profile(
    "geobrep-explore",
    deadline=None,
    max_examples=int(os.environ.get("GEOBREP_EXAMPLES", "2000")),
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("geobrep")


@pytest.fixture
def unit_cube() -> Surface:
    """The cube [0, 1]³: 8 vertices, 12 outward triangles, volume 1, area 6."""
    return make_cube()


@pytest.fixture
def unit_cube_at() -> Callable[..., Surface]:
    """Factory: ``unit_cube_at(UTM_ORIGIN)`` is the unit cube shifted to UTM coordinates."""
    return make_cube


@pytest.fixture
def tetra() -> Surface:
    """The tetrahedron (0, e_x, e_y, e_z): volume 1/6, outward faces."""
    return Surface(vertices=TETRA_VERTICES, faces=TETRA_FACES, name="tetra")


@pytest.fixture(scope="session")
def layer_cake() -> Scene:
    """The built-in faulted layer cake (9 surfaces, 6 blocks + universe, 31 patches)."""
    return geobrep.datasets.faulted_layer_cake()
