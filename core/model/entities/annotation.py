"""Text placed in 3D: labels of units, faults and wells, at a position and orientation."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from geobrep.geometry.bbox import BoundingBox
from geobrep.model.arrays import Vector3
from geobrep.model.entities.base import Entity

__all__ = ["Annotation"]


class Annotation(Entity):
    """A text string drawn from ``anchor`` along ``baseline``, with glyphs rising along ``up``.

    ``height`` is the character height in model units.

    >>> Annotation(text="Fault F1", anchor=[450000.0, 6700000.0, 10.0], height=25).text
    'Fault F1'
    """

    type: Literal["Annotation"] = "Annotation"
    kind: str | None = "annotation"
    text: str
    anchor: Vector3
    baseline: Vector3 = Field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    up: Vector3 = Field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    height: float = Field(default=1.0, gt=0, allow_inf_nan=False)
    font: str = "sans-serif"

    @property
    def bounds(self) -> BoundingBox | None:
        """The box of the anchor point (the extent of the glyphs depends on the font)."""
        return BoundingBox.from_points(self.anchor.reshape(1, 3))

    def _check(self) -> None:
        base, up = self.baseline, self.up
        if not np.linalg.norm(base) > 0:
            raise self.fail("baseline", "must be a non-zero vector")
        if not np.linalg.norm(up) > 0:
            raise self.fail("up", "must be a non-zero vector")
        sine = np.linalg.norm(np.cross(base, up)) / (np.linalg.norm(base) * np.linalg.norm(up))
        if sine < 1e-9:
            raise self.fail("up", "must not be parallel to baseline")
        if self.point_data or self.cell_data:
            raise self.fail("point_data", "an Annotation carries metadata, not properties")
