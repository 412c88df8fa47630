"""``geobrep map IN OUT``: the map products of a model as GIS layers (GeoPackage, ...).

The block outlines on the map plane, the traces of faults and horizons on the top surface
(``--top``), and sections at ``--section-levels`` and on ``--section-plane`` planes, in the
model's CRS (:func:`geobrep.map_products`). The parser is derived from the ``map_products``
operation (:class:`~geobrep.batch.pipeline.MapProductsStep`) and the files of
:class:`~geobrep.cli.operation.SceneCommand`.
"""

from __future__ import annotations

from collections import Counter

from geobrep.batch.operations import map_scene_products
from geobrep.batch.pipeline import MapProductsStep
from geobrep.cli.common import is_empty, read_input, refuse_empty
from geobrep.cli.operation import SceneCommand

__all__ = ["COMMAND", "OPERATION", "run"]

OPERATION = "map_products"


def run(step: MapProductsStep, command: SceneCommand) -> int:
    from geobrep.ops.io import write

    scene = read_input(command, command.input, format=command.format)
    products = map_scene_products(scene, step)
    if is_empty(products):
        refuse_empty(command, [f"{command.output}: no map products"], "no file written")
    path = write(products, command.output, format=command.output_format)
    layers = Counter(str(e.metadata.get("layer", "?")) for e in products.entities)
    shown = ", ".join(f"{layer} {n}" for layer, n in layers.items())
    print(f"{path}: {len(products.entities)} map products ({shown})")
    return 0


COMMAND = SceneCommand
