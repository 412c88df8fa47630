"""Built-in sample data, generated on the fly (no download).

* :func:`faulted_layer_cake` — a conformal faulted and folded layer-cake model with its complete
  B-Rep topology (patches, arcs, corners, blocks).
* :func:`scattered_points` — survey points on a known folded dome: a dense, exact core and a
  sparse, noisy rim (the data of the hybrid NURBS fitting workflow).
"""

from __future__ import annotations

from geobrep.datasets.layer_cake import faulted_layer_cake
from geobrep.datasets.scattered import dome_elevation, scattered_points

__all__ = ["dome_elevation", "faulted_layer_cake", "scattered_points"]
