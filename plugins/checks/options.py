"""Options of the built-in checks (each check's options model; most take none).

>>> IntersectionOptions().margin
0.0
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["GapOptions", "IntersectionOptions", "VolumeBalanceOptions"]


class IntersectionOptions(BaseModel):
    """``margin``: triangles nearer than this (model units) count as touching (default: only
    triangles that meet)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    margin: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)


class GapOptions(BaseModel):
    """A free border vertex within ``gap_tolerance`` of another surface (default:
    ``relative_gap_tolerance`` × the model's diagonal) is a gap."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    gap_tolerance: float | None = Field(default=None, ge=0.0, allow_inf_nan=False)
    relative_gap_tolerance: float = Field(default=1e-3, ge=0.0, allow_inf_nan=False)


class VolumeBalanceOptions(BaseModel):
    """The blocks' volumes must add up to the universe's within ``relative_tolerance``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    relative_tolerance: float = Field(default=1e-6, gt=0.0, allow_inf_nan=False)
