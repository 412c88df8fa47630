"""The ``thin`` operation: keep every N-th point of each PointSet (its properties with it).

Declared once (:data:`THIN`): geobrep derives its Python function (``THIN(scene, every=3)``),
the ``geobrep thin IN OUT --every 3`` command, the pipeline step ``thin: {every: 3}`` and its
line in ``geobrep plugins`` from the options model and the function.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from geobrep import PointSet, Scene
from geobrep.plugins import Cli, OperationSpec


class ThinOptions(BaseModel):
    """The options of ``thin``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    every: Annotated[int, Cli(metavar="N")] = Field(default=2, ge=1)
    """keep every N-th point"""
    first: Annotated[int, Cli(metavar="I")] = Field(default=0, ge=0)
    """index of the first point kept"""


def thin(scene: Scene, options: ThinOptions) -> Scene:
    """The scene with every PointSet thinned; other entities are kept as they are."""
    entities = []
    for entity in scene.entities:
        if isinstance(entity, PointSet):
            keep = np.arange(options.first, entity.n_points, options.every)
            entity = entity.replace(
                vertices=entity.vertices[keep], point_data=entity.point_data.take(keep)
            )
        entities.append(entity)
    return scene.replace(entities=tuple(entities))


THIN = OperationSpec(
    name="thin",
    summary="keep every N-th point of each PointSet",
    options=ThinOptions,
    function=thin,
    writes="the scene with its PointSets thinned",
)
