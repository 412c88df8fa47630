"""Attributes of the built blocks: horizons above and below, faults, a unit name, the centroid.

A horizon patch bounds a block from above when the block lies on the side its normal points away
from upwards: with the block on side ``s`` and the patch's mean normal ``n``, ``s · n_z < 0``
means the horizon is the block's top, ``s · n_z > 0`` its base. Surfaces count as horizons when
their ``kind`` is one of :data:`HORIZON_KINDS` (GOCAD's geological types included) and as faults
when it is ``"fault"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins.blocks._measures import PatchMeasures
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._soup import Soup

__all__ = ["HORIZON_KINDS", "BlockAttributes", "block_attributes", "unit_name"]


#: Surface kinds read as stratigraphic horizons.
HORIZON_KINDS = frozenset(
    {"horizon", "top", "base", "intraformational", "unconformity", "erosion", "stratigraphic"}
)


@dataclass(frozen=True)
class BlockAttributes:
    """What a block's bounding patches say about it."""

    tops: tuple[str, ...]
    bases: tuple[str, ...]
    faults: tuple[str, ...]
    centroid: tuple[float, float, float]

    @property
    def unit_name(self) -> str | None:
        return unit_name(self.tops, self.bases)


def unit_name(tops: tuple[str, ...], bases: tuple[str, ...]) -> str | None:
    """``"H1 – H2"`` between a top and a base, ``"above H1"``, ``"below H2"``, or None.

    >>> unit_name(("H1",), ("H2",)), unit_name((), ("H1",)), unit_name(("H2",), ())
    ('H1 – H2', 'above H1', 'below H2')
    """
    top, base = "/".join(tops), "/".join(bases)
    if top and base:
        return f"{top} – {base}"
    if base:
        return f"above {base}"
    if top:
        return f"below {top}"
    return None


def block_attributes(
    soup: Soup,
    split: PatchSplit,
    measures: PatchMeasures,
    positive: IntArray,
    negative: IntArray,
    volumes: FloatArray,
    bodies: list[int],
) -> dict[int, BlockAttributes]:
    """Attributes of each body in ``bodies`` (ids as in ``positive`` / ``negative``)."""
    area, moment = measures.area, measures.moment
    internal = positive == negative
    result: dict[int, BlockAttributes] = {}
    kinds = [s.kind for s in soup.surfaces]
    for body in bodies:
        tops: list[str] = []
        bases: list[str] = []
        faults: list[str] = []
        first_moment = np.zeros(3)
        for side, members in ((1, positive == body), (-1, negative == body)):
            first_moment -= side * moment[members].sum(axis=0)
            for patch in np.flatnonzero(members & ~internal).tolist():
                index = int(split.patch_surface[patch])
                name = soup.surface_name(index)
                if kinds[index] == "fault" and name not in faults:
                    faults.append(name)
                if kinds[index] in HORIZON_KINDS:
                    upward = side * area[patch, 2]
                    target = bases if upward > 0 else tops
                    if upward != 0 and name not in target:
                        target.append(name)
        centre = first_moment / volumes[body] + soup.centre if volumes[body] else soup.centre
        x, y, z = (float(v) for v in centre)
        result[body] = BlockAttributes(tuple(tops), tuple(bases), tuple(faults), (x, y, z))
    return result
