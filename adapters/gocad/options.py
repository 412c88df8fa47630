"""Options of the ``gocad`` format (one model for reading and writing, as the registry wants)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["GocadOptions"]


class GocadOptions(BaseModel):
    """Options of the ``gocad`` format.

    >>> GocadOptions(vertex_ids=True).vertex_ids
    True
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    repair: bool = True
    """Reading: mend what a file gets wrong and say so in a warning (a TFACE's triangles turned
    to agree with its key triangle, REGION sides that contradict the geometry reversed).
    ``False`` keeps the model exactly as written, defects included (for inspection)."""
    vertex_ids: bool = False
    """Reading: add the file's vertex ids as the point property ``gocad_vertex_id``."""
    merge_tolerance: float | None = Field(default=None, ge=0)
    """Reading: distance under which vertices of different surfaces are one point when a
    Model3d's corners and arcs are rebuilt (default: 1e-8 of the bounding-box diagonal)."""
    object_type: str | None = None
    """Writing: ``TSurf``, ``PLine``, ``VSet``, ``TSolid``, ``Model3d``,
    ``HeterogeneousGroup``, ``Voxet``, ``SGrid`` or ``Well``; default: from the extension
    (.ts .pl .vs .so .ml .gp .vo .sg .wl)."""

    tface_vertices: Literal["own", "shared"] | None = None
    """Writing a surface of several patches (TFACEs): ``"own"``, each TFACE declares every
    vertex its triangles use, a vertex an earlier TFACE declared coming again as an ``ATOM``
    (as GOCAD writes them; OpenGeode-GeosciencesIO needs it), so a border vertex is read back
    once per patch; ``"shared"``, each vertex once, later TFACEs' triangles using earlier ids
    (the surface reads back vertex for vertex). Default: ``"own"`` in a Model3d, ``"shared"``
    in a TSurf file."""
    voxet_ascii: bool = False
    """Writing a Voxet: its properties in one ``ASCII_DATA_FILE`` table of ``I J K value...``
    rows (as test.vo; the form OpenGeode-GeosciencesIO reads) instead of raw big-endian
    ``PROP_FILE``s. Values are written as exact decimal text and read back as float64."""

    def merge_tolerance_for(self, diagonal: float) -> float:
        """The joining distance for a model whose bounding-box diagonal is ``diagonal``."""
        from geobrep.model.arcs import DEFAULT_RELATIVE_TOLERANCE  # a Model3d read's, as it is

        if self.merge_tolerance is not None:
            return self.merge_tolerance
        return DEFAULT_RELATIVE_TOLERANCE * (diagonal if diagonal > 0 else 1.0)
