"""Options of the block builder (validated by pydantic; the CLI and docs read them from here)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from geobrep.plugins import Cli

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

    tolerance: Annotated[
        float | None,
        Cli(
            help="vertex merge and contact distance (model units; default: 4 quanta of the "
            "precision the coordinates carry, e.g. float32 or 2 decimals)"
        ),
    ] = Field(default=None, ge=0.0)
    relative_tolerance: Annotated[
        float | None,
        Cli(help="vertex merge and contact distance relative to the model diagonal"),
    ] = Field(default=None, ge=0.0, lt=1e-2)
    free_borders: Annotated[
        FreeBorders,
        Cli(
            help="patches with a free border: internal surfaces (default), removed (the paper's "
            "rule) or an error"
        ),
    ] = "internal"
    check_conformity: Annotated[
        bool,
        Cli(
            negate="--no-conformity-check",
            help="skip the search for crossing surfaces, T-junctions and gaps",
        ),
    ] = True
    gap_tolerance: Annotated[float | None, Cli(help="gap detection distance (model units)")] = (
        Field(default=None, ge=0.0)
    )
    relative_gap_tolerance: Annotated[
        float, Cli(help="gap detection distance relative to the model diagonal (default 1e-3)")
    ] = Field(default=1e-3, ge=0.0, lt=0.5)
    angle_tolerance: Annotated[
        float,
        Cli(help="radians under which two patches around an arc overlap (default 1e-10)"),
    ] = Field(default=1e-10, ge=0.0, lt=0.1)
    validate_blocks: Annotated[
        bool, Cli(negate="--no-validate", help="skip the closed/oriented check of each block")
    ] = Field(default=True, alias="validate")
    surfaces: Annotated[
        tuple[int | str, ...] | None,
        Cli(
            parse=lambda text: tuple(s.strip() for s in text.split(",") if s.strip()),
            metavar="SURFACES",
            help="comma-separated names of the surfaces to build from (default: all)",
        ),
    ] = None
