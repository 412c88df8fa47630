"""Geological blocks (units, regions): closed bodies bounded by sides of surface patches."""

from __future__ import annotations

from typing import Literal, NamedTuple

from pydantic import Field

from geobrep.model.entities.base import Entity

__all__ = ["UNIVERSE_KIND", "Block", "PatchSide"]

#: ``kind`` of the outer region that surrounds the model (GOCAD's "Universe").
UNIVERSE_KIND = "universe"


class PatchSide(NamedTuple):
    """A patch (topology id) and the side of it the block lies on: +1 or -1.

    ``+1`` means the block is on the side the patch's right-hand normal points to.
    """

    patch: int
    side: Literal[1, -1]


class Block(Entity):
    """A region bounded by an ordered list of ``(patch, side)`` pairs.

    A patch listed with both sides lies inside the block (an internal surface, e.g. a fault that
    ends inside it). ``unit_name`` names the stratigraphic unit when known.

    >>> Block(sides=[(0, 1), (3, -1)], name="B1", unit_name="Jurassic").sides[1].side
    -1
    """

    type: Literal["Block"] = "Block"
    kind: str | None = "unit"
    sides: tuple[PatchSide, ...] = Field(default=())
    unit_name: str | None = None

    @property
    def is_universe(self) -> bool:
        return self.kind == UNIVERSE_KIND

    @property
    def patch_ids(self) -> tuple[int, ...]:
        return tuple(side.patch for side in self.sides)

    @property
    def internal_patches(self) -> frozenset[int]:
        """Patches listed with both sides (surfaces inside the block)."""
        plus = {s.patch for s in self.sides if s.side == 1}
        minus = {s.patch for s in self.sides if s.side == -1}
        return frozenset(plus & minus)

    def _check(self) -> None:
        seen: set[tuple[int, int]] = set()
        for side in self.sides:
            if side.patch < 0:
                raise self.fail("sides", f"patch id {side.patch} is negative")
            if (side.patch, side.side) in seen:
                raise self.fail("sides", f"patch {side.patch} side {side.side:+d} listed twice")
            seen.add((side.patch, side.side))
        if self.point_data or self.cell_data:
            raise self.fail("point_data", "a Block holds no arrays; properties live on patches")
