"""Pictures of a scene, off-screen (no display needed): the ``png`` format's writer.

Colour by ``entity`` (one colour per mesh entity), ``block`` (the closed boundary of every
block) or ``property`` (a named point or cell property, one colour scale); optionally cut away
everything on the side of a plane its normal points to. Coordinates are centred on the scene
before rendering, so UTM-scale models draw without float32 jitter.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from geobrep.adapters.pyvista._convert import (
    import_pyvista,
    scene_blocks_to_pyvista,
    to_pyvista,
)
from geobrep.errors import OptionsError
from geobrep.model.scene import Scene

__all__ = ["RenderOptions", "render_scene"]

_BLOCK_SHRINK = 0.99


class RenderOptions(BaseModel):
    """Options of the ``png`` writer (``geobrep render``)."""

    model_config = ConfigDict(extra="forbid")

    color_by: Literal["entity", "block", "property"] = "entity"
    """What sets the colours."""
    property: str | None = None
    """The property to colour by (with ``color_by="property"``)."""
    clip_origin: tuple[float, float, float] | None = None
    """A point of the cut-away plane (with ``clip_normal``)."""
    clip_normal: tuple[float, float, float] | None = None
    """The plane's normal: what lies on the side it points to is cut away."""
    window_size: tuple[int, int] = (1200, 900)
    """Picture size in pixels (width, height)."""
    show_edges: bool = False
    """Draw the triangle edges."""
    vertical_exaggeration: float = Field(default=1.0, gt=0)
    """Scale of z relative to x and y."""
    background: str = "white"

    @model_validator(mode="after")
    def _check(self) -> RenderOptions:
        if (self.clip_origin is None) != (self.clip_normal is None):
            raise ValueError("clip_origin and clip_normal go together")
        if self.clip_normal is not None and not np.any(self.clip_normal):
            raise ValueError("clip_normal must not be the zero vector")
        if self.color_by == "property" and not self.property:
            raise ValueError("color_by='property' needs property='<name>'")
        return self


def _datasets(scene: Scene, options: RenderOptions) -> list[tuple[str, Any]]:
    if options.color_by == "block":
        if not [b for b in scene.blocks if b is not scene.universe]:
            raise OptionsError("color_by='block': the scene has no blocks")
        # block meshes cache bounds on the entities: work on copies, not the caller's scene
        copies = scene.replace(entities=[e.model_copy() for e in scene.entities])
        multiblock = scene_blocks_to_pyvista(copies)
    else:
        multiblock = to_pyvista(scene)
    items = []
    for index in range(multiblock.n_blocks):
        dataset = multiblock[index]
        if dataset is not None and dataset.n_points:
            items.append((multiblock.get_block_name(index) or str(index), dataset))
    if not items:
        raise OptionsError("nothing to draw: the scene has no mesh entities")
    if options.color_by == "property":
        name = options.property
        if not any(name in d.point_data or name in d.cell_data for _, d in items):
            available = sorted(
                {k for _, d in items for k in [*d.point_data.keys(), *d.cell_data.keys()]}
                - {"geobrep_entity", "geobrep_part"}
            )
            raise OptionsError(
                f"no entity has the property {name!r}; properties: {', '.join(available) or 'none'}"
            )
    return items


def render_scene(scene: Scene, path: Path, options: RenderOptions) -> None:
    """Render ``scene`` into the PNG file ``path`` off-screen."""
    pv = import_pyvista("rendering pictures")
    # without a display VTK logs "bad X server connection" although off-screen rendering works
    with pv.vtk_verbosity("error"):
        _render(pv, scene, path, options)


def _render(pv: Any, scene: Scene, path: Path, options: RenderOptions) -> None:
    items = _datasets(scene, options)
    # centre on the drawn points (not scene.bounds: that caches a value on the caller's scene)
    lows = np.min([np.asarray(d.points, np.float64).min(axis=0) for _, d in items], axis=0)
    highs = np.max([np.asarray(d.points, np.float64).max(axis=0) for _, d in items], axis=0)
    centre = (lows + highs) / 2
    scale = np.array([1.0, 1.0, options.vertical_exaggeration])
    plotter = pv.Plotter(off_screen=True, window_size=list(options.window_size))
    plotter.set_background(options.background)
    colours = _palette(len(items))
    clim = _property_range(items, options.property) if options.color_by == "property" else None
    drawn = 0
    for (label, dataset), colour in zip(items, colours, strict=True):
        mesh = dataset.copy()
        points = np.asarray(mesh.points, dtype=np.float64) - centre
        if options.color_by == "block":
            # blocks share their faces: pull each a little towards its middle to avoid z-fighting
            middle = points.mean(axis=0)
            points = middle + (points - middle) * _BLOCK_SHRINK
        mesh.points = points * scale
        if options.clip_normal is not None and options.clip_origin is not None:
            origin = (np.asarray(options.clip_origin, dtype=np.float64) - centre) * scale
            mesh = mesh.clip(normal=list(options.clip_normal), origin=list(origin), invert=True)
            if mesh.n_points == 0:
                continue
        style: dict[str, Any] = {"show_edges": options.show_edges, "label": label}
        if mesh.n_cells and mesh.get_cell(0).dimension < 2:
            style["line_width" if mesh.get_cell(0).dimension == 1 else "point_size"] = 4
        name = options.property
        if (
            clim is not None
            and name is not None
            and (name in mesh.point_data or name in mesh.cell_data)
        ):
            preference = "point" if name in mesh.point_data else "cell"
            plotter.add_mesh(
                mesh, scalars=name, clim=clim, preference=preference, cmap="viridis", **style
            )
        else:
            plotter.add_mesh(mesh, color=colour if clim is None else "lightgrey", **style)
        drawn += 1
    if not drawn:
        raise OptionsError("the clip plane cuts everything away")
    if options.color_by == "property" and name is not None:
        plotter.add_scalar_bar(title=name)
    plotter.view_isometric()
    plotter.screenshot(str(path))
    plotter.close()


def _palette(count: int) -> list[tuple[float, float, float]]:
    """Distinct colours (matplotlib's tab20 cycle, without needing matplotlib)."""
    base = [
        (0.122, 0.467, 0.706), (1.0, 0.498, 0.055), (0.173, 0.627, 0.173),
        (0.839, 0.153, 0.157), (0.580, 0.404, 0.741), (0.549, 0.337, 0.294),
        (0.890, 0.467, 0.761), (0.498, 0.498, 0.498), (0.737, 0.741, 0.133),
        (0.090, 0.745, 0.812), (0.682, 0.780, 0.910), (1.0, 0.733, 0.471),
        (0.596, 0.875, 0.541), (1.0, 0.596, 0.588), (0.773, 0.690, 0.835),
        (0.769, 0.612, 0.580), (0.969, 0.714, 0.824), (0.780, 0.780, 0.780),
        (0.859, 0.859, 0.553), (0.620, 0.855, 0.898),
    ]  # fmt: skip
    return [base[i % len(base)] for i in range(count)]


def _property_range(items: list[tuple[str, Any]], name: str | None) -> tuple[float, float]:
    low, high = np.inf, -np.inf
    for _, dataset in items:
        for data in (dataset.point_data, dataset.cell_data):
            if name in data:
                values = np.asarray(data[name], dtype=np.float64)
                finite = values[np.isfinite(values)]
                if finite.size:
                    low, high = min(low, float(finite.min())), max(high, float(finite.max()))
    if not np.isfinite(low):
        return (0.0, 1.0)
    return (low, high if high > low else low + 1.0)
