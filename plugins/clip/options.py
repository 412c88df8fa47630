"""Options of the built-in clippers (pydantic models: validated, documented, JSON Schema)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from geobrep.plugins import ClipContext

__all__ = [
    "AnnotationClipOptions",
    "ClipOptions",
    "NurbsClipOptions",
    "OctreeClipOptions",
    "SurfaceClipOptions",
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


def tolerance_of(options: ClipOptions, context: ClipContext) -> float:
    """The tolerance to use: the option when given, else the clip's."""
    return context.tolerance if options.tolerance is None else float(options.tolerance)
