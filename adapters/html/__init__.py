"""The ``html`` format (write only): a model you can open in a browser, offline.

``geobrep view MODEL -o model.html`` (or ``geobrep.write(scene, "model.html")``) writes one
self-contained page: three.js r187 (MIT, vendored with its licence) and the model inlined, no
server and no network needed. It lists the blocks, surfaces, lines, point sets, grids and
wells with their names and colours (blocks by unit), each switchable: a grid is drawn as the
outer boundary of its active cells (coloured by a cell or point property with ``property``), a
well as its trajectory with its markers, named in the view and the list; a clipping plane
across x, y or z cuts the model open; a box of axes is labelled in world coordinates; the title
and CRS head the list. The page reports what it shows on the browser console
(``geobrep-view: {...}``).
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from geobrep.adapters.html._page import page_html
from geobrep.hookspecs import hookimpl
from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec
from geobrep.model.scene import Scene

__all__ = ["CAPABILITIES", "HtmlOptions", "geobrep_register_formats", "page_html"]

CAPABILITIES = FormatCapabilities(
    entity_types=frozenset(
        {"Block", "PointSet", "PolyLine", "RegularGrid", "StructuredGrid", "Surface", "Well"}
    ),
    names=True,
    crs=True,
    multiple_entities=True,
)


class HtmlOptions(BaseModel):
    """Options of the ``html`` writer (``geobrep view``)."""

    model_config = ConfigDict(extra="forbid")

    title: str | None = None
    """The page's title (default: the scene's name)."""
    blocks: bool = True
    """Show the blocks (their boundaries, coloured by unit)."""
    surfaces_with_blocks: bool = False
    """With blocks shown, start with the surfaces shown too (else only faults are)."""
    property: str | None = None
    """Colour the grids by this cell or point property (a grid without it: its colour)."""


def _write(scene: Scene, path: Path, options: HtmlOptions) -> None:
    text = page_html(
        scene,
        title=options.title,
        blocks=options.blocks,
        surfaces_with_blocks=options.surfaces_with_blocks,
        property=options.property,
    )
    path.write_text(text, encoding="utf-8")


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``html``."""
    registry.add(
        FormatSpec(
            name="html",
            description="an offline 3D viewer page (three.js inlined); write only",
            extensions=(".html", ".htm"),
            writer=_write,
            options=HtmlOptions,
            capabilities=CAPABILITIES,
        )
    )
