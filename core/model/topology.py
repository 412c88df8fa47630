"""The B-Rep topology of a structural model: corners, arcs and patches.

* A **patch** is a set of faces of one surface (its ``label`` in ``Surface.patch_labels``). It
  separates two bodies: its **positive block**, on the side its right-hand normal points to, and
  its **negative block**. Blocks are :class:`~geobrep.Block` entities of the scene that
  list ``(patch, side)`` pairs; the side convention is the same.
* An **arc** is a boundary line shared by patches (a horizon–fault intersection, a model border),
  directed from its ``start`` corner to its ``end`` corner. ``patches`` lists the patches around
  it in right-hand cyclic order: counter-clockwise when the arc points at the viewer.
* A **corner** is where arcs meet.

This module holds the data model and its self-consistency checks; references to entities are
checked by :class:`~geobrep.Scene`, and the builder plugin fills the model from surfaces.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any, Self

from pydantic import Field, JsonValue, ValidationError, model_validator

from geobrep.errors import TopologyError
from geobrep.model.arrays import Points, Vector3
from geobrep.model.base import FrozenModel

__all__ = ["Arc", "Corner", "Patch", "Topology"]


class _TopologyModel(FrozenModel):
    """Raises the :class:`TopologyError` its checks found rather than pydantic's wrapper."""

    def __init__(self, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            original = (exc.errors()[0].get("ctx") or {}).get("error")
            if isinstance(original, TopologyError):
                raise original from exc
            raise


class Corner(FrozenModel):
    """A point where arcs meet."""

    id: int = Field(ge=0)
    point: Vector3


class Arc(_TopologyModel):
    """A boundary polyline ``points (K, 3)`` from corner ``start`` to corner ``end``."""

    id: int = Field(ge=0)
    points: Points
    start: int | None = None
    end: int | None = None
    patches: tuple[int, ...] = ()

    @model_validator(mode="after")
    def _two_points(self) -> Self:
        if self.points.shape[0] < 2:
            raise TopologyError(f"arc {self.id}: needs at least 2 points")
        return self


class Patch(FrozenModel):
    """Faces ``label`` of surface entity ``surface``, with the blocks on either side."""

    id: int = Field(ge=0)
    surface: int = Field(ge=0)
    label: int = Field(default=0, ge=0)
    name: str = ""
    positive_block: int | None = None
    negative_block: int | None = None
    arcs: tuple[int, ...] = ()
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    @property
    def is_internal(self) -> bool:
        """The same block lies on both sides (a surface ending inside a block)."""
        return self.positive_block is not None and self.positive_block == self.negative_block


class Topology(_TopologyModel):
    """Corners, arcs and patches, each with ids unique within its kind."""

    corners: tuple[Corner, ...] = ()
    arcs: tuple[Arc, ...] = ()
    patches: tuple[Patch, ...] = ()

    @property
    def is_empty(self) -> bool:
        return not (self.corners or self.arcs or self.patches)

    @cached_property
    def corner_by_id(self) -> dict[int, Corner]:
        return {c.id: c for c in self.corners}

    @cached_property
    def arc_by_id(self) -> dict[int, Arc]:
        return {a.id: a for a in self.arcs}

    @cached_property
    def patch_by_id(self) -> dict[int, Patch]:
        return {p.id: p for p in self.patches}

    def patch(self, patch_id: int) -> Patch:
        """The patch with this id (TopologyError if there is none)."""
        try:
            return self.patch_by_id[patch_id]
        except KeyError:
            raise TopologyError(f"no patch with id {patch_id}") from None

    def arc(self, arc_id: int) -> Arc:
        try:
            return self.arc_by_id[arc_id]
        except KeyError:
            raise TopologyError(f"no arc with id {arc_id}") from None

    def corner(self, corner_id: int) -> Corner:
        try:
            return self.corner_by_id[corner_id]
        except KeyError:
            raise TopologyError(f"no corner with id {corner_id}") from None

    @model_validator(mode="after")
    def _check_references(self) -> Self:
        for kind, items in (("corner", self.corners), ("arc", self.arcs), ("patch", self.patches)):
            ids = [item.id for item in items]
            if len(set(ids)) != len(ids):
                duplicate = next(i for i in ids if ids.count(i) > 1)
                raise TopologyError(f"{kind} id {duplicate} is used more than once")
        corners, patches, arcs = self.corner_by_id, self.patch_by_id, self.arc_by_id
        for arc in self.arcs:
            for end in (arc.start, arc.end):
                if end is not None and end not in corners:
                    raise TopologyError(f"arc {arc.id}: corner {end} does not exist")
            missing = [p for p in arc.patches if p not in patches]
            if missing:
                raise TopologyError(f"arc {arc.id}: patch {missing[0]} does not exist")
        for patch in self.patches:
            missing = [a for a in patch.arcs if a not in arcs]
            if missing:
                raise TopologyError(f"patch {patch.id}: arc {missing[0]} does not exist")
        return self
