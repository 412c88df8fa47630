"""Fixtures for the pipeline tests: the layer cake and scattered points as input files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep


@pytest.fixture
def cake_file(tmp_path: Path, layer_cake: geobrep.Scene) -> Path:
    """The faulted layer cake in the native format, in ``tmp_path/models``."""
    folder = tmp_path / "models"
    folder.mkdir()
    return geobrep.write(layer_cake, folder / "cake.geobrep")


@pytest.fixture
def points_csv(tmp_path: Path) -> Path:
    """The built-in scattered survey points as ``x,y,z,core`` columns."""
    points = geobrep.datasets.scattered_points()
    table = np.column_stack([points.vertices, points.point_data["core"].values])
    path = tmp_path / "survey.csv"
    np.savetxt(path, table, delimiter=",", header="x,y,z,core", comments="", fmt="%.6f")
    return path
