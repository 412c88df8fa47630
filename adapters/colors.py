"""Colours of entities for pictures, glTF materials and the HTML viewer (shared by adapters).

An entity's own colour is ``metadata["color"]`` (three or four numbers in [0, 1], what the
GOCAD reader keeps from ``*solid*color``); others get a colour from a fixed palette
(matplotlib's tab20 cycle, without matplotlib). Blocks of one stratigraphic unit share the
unit's colour, so the two sides of a fault show the same layer alike.

>>> import geobrep
>>> colours = scene_colours(geobrep.datasets.faulted_layer_cake())
>>> colours[9] == colours[11]  # 'footwall unit 1' and 'hanging wall unit 1': unit 1
True
"""

from __future__ import annotations

from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.model.entities import Block, Entity
from geobrep.model.scene import Scene

__all__ = [
    "PALETTE",
    "RAMP",
    "RGBA",
    "entity_colour",
    "hex_colour",
    "known_values",
    "ramp_colours",
    "scene_colours",
]

RGBA = tuple[float, float, float, float]

PALETTE: Final[tuple[tuple[float, float, float], ...]] = (
    (0.122, 0.467, 0.706), (1.0, 0.498, 0.055), (0.173, 0.627, 0.173),
    (0.839, 0.153, 0.157), (0.580, 0.404, 0.741), (0.549, 0.337, 0.294),
    (0.890, 0.467, 0.761), (0.498, 0.498, 0.498), (0.737, 0.741, 0.133),
    (0.090, 0.745, 0.812), (0.682, 0.780, 0.910), (1.0, 0.733, 0.471),
    (0.596, 0.875, 0.541), (1.0, 0.596, 0.588), (0.773, 0.690, 0.835),
    (0.769, 0.612, 0.580), (0.969, 0.714, 0.824), (0.780, 0.780, 0.780),
    (0.859, 0.859, 0.553), (0.620, 0.855, 0.898),
)  # fmt: skip


#: Anchors of the colour ramp for property values, low to high (matplotlib's viridis at 0, 1/8,
#: ..., 1, without matplotlib); values in between are interpolated linearly.
RAMP: Final[tuple[tuple[float, float, float], ...]] = (
    (0.267, 0.005, 0.329), (0.283, 0.141, 0.458), (0.254, 0.265, 0.530),
    (0.207, 0.372, 0.553), (0.164, 0.471, 0.558), (0.128, 0.567, 0.551),
    (0.135, 0.659, 0.518), (0.267, 0.749, 0.441), (0.478, 0.821, 0.318),
    (0.741, 0.873, 0.150), (0.993, 0.906, 0.144),
)  # fmt: skip
#: The colour of values that are missing (NaN or the property's no-data value).
NO_DATA_COLOUR: Final[tuple[float, float, float]] = (0.6, 0.6, 0.6)


def known_values(values: ArrayLike, no_data: float | None = None) -> NDArray[np.bool_]:
    """Which values are data: finite and not ``no_data``."""
    data = np.asarray(values, dtype=np.float64).reshape(-1)
    known = np.isfinite(data)
    return known if no_data is None else known & (data != no_data)


def ramp_colours(values: ArrayLike, no_data: float | None = None) -> NDArray[np.uint8]:
    """RGB bytes ``(n, 3)`` of ``values`` on :data:`RAMP` over their range (grey where
    :func:`known_values` is False; one value maps to the middle of the ramp).

    >>> ramp_colours([0.0, 1.0, float("nan")]).tolist()
    [[68, 1, 84], [253, 231, 37], [153, 153, 153]]
    """
    data = np.asarray(values, dtype=np.float64).reshape(-1)
    known = known_values(data, no_data)
    low, high = (float(data[known].min()), float(data[known].max())) if known.any() else (0, 0)
    span = high - low
    t = np.where(known, (data - low) / span if span > 0 else 0.5, 0.0)
    anchors = np.asarray(RAMP)
    position = np.clip(t, 0.0, 1.0) * (len(RAMP) - 1)
    below = np.minimum(position.astype(np.int64), len(RAMP) - 2)
    share = (position - below)[:, None]
    rgb = anchors[below] * (1.0 - share) + anchors[below + 1] * share
    rgb[~known] = NO_DATA_COLOUR
    return np.asarray(np.round(rgb * 255.0), dtype=np.uint8)


def entity_colour(entity: Entity) -> RGBA | None:
    """``metadata["color"]`` as RGBA in [0, 1], or None when the entity has no usable colour."""
    value = entity.metadata.get("color")
    if not isinstance(value, list | tuple) or len(value) not in (3, 4):
        return None
    numbers = [float(c) for c in value if isinstance(c, int | float) and not isinstance(c, bool)]
    if len(numbers) != len(value) or not all(0.0 <= c <= 1.0 for c in numbers):
        return None
    rgba = numbers + [1.0] * (4 - len(numbers))
    return rgba[0], rgba[1], rgba[2], rgba[3]


def scene_colours(scene: Scene) -> dict[int, RGBA]:
    """A colour per entity id: its own, else the palette's (blocks: one colour per unit)."""
    colours: dict[int, RGBA] = {}
    slots: dict[str, int] = {}
    # blocks first: the units take the first, most distinct colours
    ordered = sorted(scene.entities, key=lambda e: not isinstance(e, Block))
    for entity in ordered:
        if entity.id is None:
            continue
        own = entity_colour(entity)
        if own is not None:
            colours[entity.id] = own
            continue
        key = f"entity:{entity.id}"
        if isinstance(entity, Block):
            key = f"unit:{entity.unit_name or entity.name or entity.id}"
        slot = slots.setdefault(key, len(slots))
        r, g, b = PALETTE[slot % len(PALETTE)]
        colours[entity.id] = (r, g, b, 1.0)
    return colours


def hex_colour(rgba: RGBA) -> str:
    """``#rrggbb`` of an RGBA colour (alpha dropped)."""
    return "#" + "".join(f"{round(max(0.0, min(1.0, c)) * 255):02x}" for c in rgba[:3])
