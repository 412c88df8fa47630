"""Options of the built-in clippers (pydantic models: validated, documented, JSON Schema)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from geobrep.plugins import ClipContext

__all__ = [
    "AnnotationClipOptions",
    "ClipOptions",
    "GridClipOptions",
    "NurbsClipOptions",
    "OctreeClipOptions",
    "SurfaceClipOptions",
    "WellClipOptions",
    "tolerance_of",
]


class ClipOptions(BaseModel):
    """Options every built-in clipper takes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    tolerance: float | None = Field(
        default=None,
        ge=0,
        allow_inf_nan=False,
        description="Distance within which a point counts as on the plane (model units); "
        "default: the clip's tolerance, 1e-9 of the model's bounding-box diagonal.",
    )


class SurfaceClipOptions(ClipOptions):
    """Options of the Surface clipper."""

    caps: Literal["auto", "always", "never"] = Field(
        default="auto",
        description="Close the cut with cap faces on the plane: 'auto' caps closed surfaces "
        "(except the patches of a scene's blocks, whose caps the Block clipper makes).",
    )


class AnnotationClipOptions(ClipOptions):
    """Options of the Annotation clipper (the paper's three precisions)."""

    precision: Literal["string", "character", "stroke"] = Field(
        default="character",
        description="'string': keep the text only if all of it is on the kept side; "
        "'character': keep the characters entirely on the kept side; 'stroke': cut the "
        "glyph strokes and keep their parts on the kept side (metadata['strokes']).",
    )


class OctreeClipOptions(ClipOptions):
    """Options of the LinearOctree clipper."""

    straddling: Literal["subdivide", "centre"] = Field(
        default="subdivide",
        description="Leaves the plane crosses: 'subdivide' splits them down to the finest "
        "level and keeps the cells whose centre is on the kept side; 'centre' keeps or drops "
        "each whole leaf by its centre.",
    )


class NurbsClipOptions(ClipOptions):
    """Options of the NurbsSurface clipper."""

    samples: int = Field(
        default=65, ge=2, le=4097, description="Tessellation samples per parameter direction."
    )


class GridClipOptions(ClipOptions):
    """Options of the RegularGrid and StructuredGrid clippers (cells are kept whole)."""

    cells: Literal["centre", "inside", "touching"] = Field(
        default="centre",
        description="Which cells a side keeps: 'centre', those whose centre is on it (a centre "
        "on the plane counts as positive, so keep='both' partitions the cells); 'inside', those "
        "with no corner beyond the plane; 'touching', those with a corner strictly on it.",
    )


class WellClipOptions(ClipOptions):
    """Options of the Well clipper and section."""

    within: float | None = Field(
        default=None,
        gt=0,
        allow_inf_nan=False,
        description="Section only: the well on the section, the parts of its path within this "
        "distance of the plane projected onto it (a PolyLine with md and offset), instead of "
        "the points where it crosses the plane.",
    )


def tolerance_of(options: ClipOptions, context: ClipContext) -> float:
    """The tolerance to use: the option when given, else the clip's."""
    return context.tolerance if options.tolerance is None else float(options.tolerance)
