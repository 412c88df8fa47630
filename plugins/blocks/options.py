"""Options of the block builder (validated by pydantic; the CLI and docs read them from here)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["BlockBuilderOptions", "FreeBorders"]

#: What to do with a patch that has a free border (an arc used by that patch alone).
FreeBorders = Literal["internal", "remove", "error"]


class BlockBuilderOptions(BaseModel):
    """How the ``blocks`` builder turns conformal surfaces into blocks.

    * ``tolerance`` — absolute distance under which vertices are merged and surfaces count as
      touching; else ``relative_tolerance`` × the diagonal of the surfaces' bounding box; else
      (the default) a few quanta of the precision the coordinates carry — float32, a number of
      decimals or significant digits, or float64 — within [1e-9, 1e-4] × the diagonal
      (:mod:`geobrep.plugins.blocks.precision`).
    * ``free_borders`` — ``"internal"`` (default): a patch with a free border inside a block is an
      internal surface (listed with both sides, like GOCAD's ``+k -k``), and patches outside the
      model or floating alone are dangling, removed and reported; ``"remove"``: the paper's rule,
      every patch with an arc used by it alone is dangling; ``"error"``: any free border is a
      :class:`~geobrep.errors.TopologyError`.
    * ``check_conformity`` — look for surfaces crossing without shared vertices, T-junctions and
      gaps (``gap_tolerance``, default ``relative_gap_tolerance`` × diagonal; 0 disables the gap
      test) and raise a ``TopologyError`` with their locations.
    * ``angle_tolerance`` — radians under which two patches around an arc count as overlapping.
    * ``validate`` — check every block with ``Scene.block_mesh`` (closed, outward, positive volume).
    * ``surfaces`` — ids or names of the surfaces to build from (default: every surface).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)

    tolerance: float | None = Field(default=None, ge=0.0)
    relative_tolerance: float | None = Field(default=None, ge=0.0, lt=1e-2)
    free_borders: FreeBorders = "internal"
    check_conformity: bool = True
    gap_tolerance: float | None = Field(default=None, ge=0.0)
    relative_gap_tolerance: float = Field(default=1e-3, ge=0.0, lt=0.5)
    angle_tolerance: float = Field(default=1e-10, ge=0.0, lt=0.1)
    validate_blocks: bool = Field(default=True, alias="validate")
    surfaces: tuple[int | str, ...] | None = None
