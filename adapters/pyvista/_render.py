"""Pictures of a scene, off-screen (no display needed): the ``png`` format's writer.

Grids are drawn as their (active) cells, wells as their traces with their markers labelled
(:mod:`geobrep.adapters.pyvista._grids`). Colour by ``entity`` (one colour per mesh entity),
``block`` (the closed boundary of every block, one colour per unit) or ``property`` (a named
point or cell property, one colour scale); optionally cut away everything on the side of a
plane its normal points to, or draw a section: the model cut by a plane (blocks closed by the
cut, so the units show as filled areas), looked at square to it. Pictures carry a legend (unit
or entity names with their colours), a box of axes labelled in world coordinates, a scale bar
and a title naming the CRS. Colours are those of the glTF and HTML outputs
(:func:`geobrep.adapters.colors.scene_colours`). Coordinates are centred on the scene before
rendering, so UTM-scale models draw without float32 jitter.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from geobrep.adapters.colors import PALETTE, RGBA, scene_colours
from geobrep.adapters.pyvista._convert import (
    import_pyvista,
    scene_blocks_to_pyvista,
    to_pyvista,
)
from geobrep.adapters.pyvista._grids import MARKER_NAMES, grid_and_well_datasets
from geobrep.errors import OptionsError
from geobrep.model.entities import Block, Entity
from geobrep.model.scene import Scene

__all__ = ["VIEWS", "RenderOptions", "render_scene"]

_BLOCK_SHRINK = 0.99

View = Literal["isometric", "top", "bottom", "north", "south", "east", "west"]
#: Where the camera looks from, as a direction from the model's centre (z up).
VIEWS: dict[str, tuple[float, float, float]] = {
    "isometric": (-1.0, -1.6, 1.0),
    "top": (0.0, 0.0, 1.0),
    "bottom": (0.0, 0.0, -1.0),
    "north": (0.0, 1.0, 0.0),
    "south": (0.0, -1.0, 0.0),
    "east": (1.0, 0.0, 0.0),
    "west": (-1.0, 0.0, 0.0),
}


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
    section_origin: tuple[float, float, float] | None = None
    """A point of the section plane (with ``section_normal``)."""
    section_normal: tuple[float, float, float] | None = None
    """The section plane's normal: the side it points to is removed, blocks are closed by the
    cut, and the camera looks at the cut from that side (unless ``view`` is given)."""
    view: View | None = None
    """Where the camera looks from (default: isometric, or square to the section)."""
    azimuth: float = 0.0
    """Degrees to turn the camera about the vertical, after ``view``."""
    elevation: float = 0.0
    """Degrees to raise the camera, after ``view``."""
    window_size: tuple[int, int] = (1200, 900)
    """Picture size in pixels (width, height)."""
    show_edges: bool = False
    """Draw the triangle edges."""
    vertical_exaggeration: float = Field(default=1.0, gt=0)
    """Scale of z relative to x and y."""
    background: str = "white"
    title: str | None = None
    """The picture's title (default: the scene's name and its CRS)."""
    legend: bool = True
    """A legend of unit (or entity) names and colours."""
    axes: bool = True
    """A box of axes labelled in world coordinates."""
    scale_bar: bool = True
    """A bar of a round length along x, labelled in the CRS's unit."""

    @model_validator(mode="after")
    def _check(self) -> RenderOptions:
        for name in ("clip", "section"):
            origin, normal = getattr(self, f"{name}_origin"), getattr(self, f"{name}_normal")
            if (origin is None) != (normal is None):
                raise ValueError(f"{name}_origin and {name}_normal go together")
            if normal is not None and not np.any(normal):
                raise ValueError(f"{name}_normal must not be the zero vector")
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
    if options.color_by != "block":
        items.extend((label, dataset) for label, dataset, _ in grid_and_well_datasets(scene))
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


def _sources(scene: Scene, items: list[tuple[str, Any]], block_mode: bool) -> list[Entity | None]:
    """The entity each drawn dataset shows (matched by name among blocks or mesh entities)."""
    pool = [e for e in scene.entities if isinstance(e, Block) == block_mode]
    by_name: dict[str, Entity] = {}
    for entity in pool:
        by_name.setdefault(entity.name or entity.label, entity)
    return [by_name.get(label) for label, _ in items]


def _colours(scene: Scene, sources: list[Entity | None]) -> list[RGBA]:
    known = scene_colours(scene)
    out: list[RGBA] = []
    for index, source in enumerate(sources):
        colour = known.get(source.id) if source is not None and source.id is not None else None
        if colour is None:
            r, g, b = PALETTE[index % len(PALETTE)]
            colour = (r, g, b, 1.0)
        out.append(colour)
    return out


def _legend_entries(
    items: list[tuple[str, Any]], sources: list[Entity | None], colours: list[RGBA]
) -> list[tuple[str, RGBA]]:
    """One line per unit (blocks of one unit share it) or per entity."""
    entries: dict[str, RGBA] = {}
    for (label, _), source, colour in zip(items, sources, colours, strict=True):
        text = source.unit_name if isinstance(source, Block) and source.unit_name else label
        entries.setdefault(text, colour)
    return list(entries.items())


def render_scene(scene: Scene, path: Path, options: RenderOptions) -> None:
    """Render ``scene`` into the PNG file ``path`` off-screen."""
    pv = import_pyvista("rendering pictures")
    # without a display VTK logs "bad X server connection" although off-screen rendering works
    with pv.vtk_verbosity("error"):
        _render(pv, scene, path, options)


def _cut(mesh: Any, options: RenderOptions, centre: NDArray[np.float64], scale: Any) -> Any:
    """``mesh`` without what the clip and the section remove (closed meshes capped)."""
    if options.clip_normal is not None and options.clip_origin is not None:
        origin = (np.asarray(options.clip_origin, dtype=np.float64) - centre) * scale
        mesh = mesh.clip(normal=list(options.clip_normal), origin=list(origin), invert=True)
    if mesh.n_points and options.section_normal is not None and options.section_origin is not None:
        origin = (np.asarray(options.section_origin, dtype=np.float64) - centre) * scale
        normal = np.asarray(options.section_normal, dtype=np.float64) / scale
        surface = mesh.extract_surface(algorithm=None) if hasattr(mesh, "n_cells") else mesh
        closed = surface.n_open_edges == 0 if hasattr(surface, "n_open_edges") else False
        if closed and surface.n_cells:
            mesh = surface.clip_closed_surface(normal=list(-normal), origin=list(origin))
        else:
            mesh = mesh.clip(normal=list(normal), origin=list(origin), invert=True)
    return mesh


def _render(pv: Any, scene: Scene, path: Path, options: RenderOptions) -> None:
    items = _datasets(scene, options)
    # centre on the drawn points (not scene.bounds: that caches a value on the caller's scene)
    lows = np.min([np.asarray(d.points, np.float64).min(axis=0) for _, d in items], axis=0)
    highs = np.max([np.asarray(d.points, np.float64).max(axis=0) for _, d in items], axis=0)
    centre = (lows + highs) / 2
    scale = np.array([1.0, 1.0, options.vertical_exaggeration])
    plotter = pv.Plotter(off_screen=True, window_size=list(options.window_size))
    plotter.set_background(options.background)
    sources = _sources(scene, items, options.color_by == "block")
    colours = _colours(scene, sources)
    clim = _property_range(items, options.property) if options.color_by == "property" else None
    drawn = 0
    labels: list[tuple[Any, list[str]]] = []  # marker names, drawn last (after the scalar bar)
    bar_mapper: Any = None  # the scalar bar is that of a mesh coloured by the property
    for (label, dataset), colour in zip(items, colours, strict=True):
        mesh = dataset.copy()
        points = np.asarray(mesh.points, dtype=np.float64) - centre
        if options.color_by == "block":
            # blocks share their faces: pull each a little towards its middle to avoid z-fighting
            middle = points.mean(axis=0)
            points = middle + (points - middle) * _BLOCK_SHRINK
        mesh.points = points * scale
        mesh = _cut(mesh, options, centre, scale)
        if mesh.n_points == 0:
            continue
        actor = _add(plotter, mesh, label, colour[:3], clim, options)
        if bar_mapper is None and clim is not None and _has(mesh, options.property):
            bar_mapper = actor.mapper
        names = mesh.field_data.get(MARKER_NAMES)
        if names is not None and len(names) == mesh.n_points:
            labels.append((mesh.points, [str(n) for n in names]))
        drawn += 1
    if not drawn:
        raise OptionsError("the clip or section plane cuts everything away")
    if options.color_by == "property" and options.property is not None:
        plotter.add_scalar_bar(title=options.property, mapper=bar_mapper)
    elif options.legend:
        entries = _legend_entries(items, sources, colours)
        width, height = 0.2, min(0.045 * len(entries) + 0.02, 0.6)
        legend = plotter.add_legend(
            labels=[[text, colour[:3]] for text, colour in entries],
            bcolor="white",
            border=True,
            face="rectangle",
            size=(width, height),
        )
        legend.SetPosition(1.0 - width - 0.01, 1.0 - height - 0.07)  # below the title line
        legend.SetPosition2(width, height)
    for points, names in labels:
        plotter.add_point_labels(
            points, names, font_size=14, point_size=10, shape_opacity=0.6, always_visible=True
        )
    _decorate(plotter, scene, lows, highs, centre, scale, options)
    plotter.screenshot(str(path))
    plotter.close()


def _add(
    plotter: Any,
    mesh: Any,
    label: str,
    colour: tuple[float, ...],
    clim: tuple[float, float] | None,
    options: RenderOptions,
) -> Any:
    style: dict[str, Any] = {"show_edges": options.show_edges}
    if mesh.n_cells and mesh.get_cell(0).dimension < 2:
        style["line_width" if mesh.get_cell(0).dimension == 1 else "point_size"] = 4
    name = options.property
    if clim is not None and name is not None and _has(mesh, name):
        preference = "point" if name in mesh.point_data else "cell"
        return plotter.add_mesh(
            mesh, scalars=name, clim=clim, preference=preference, cmap="viridis", **style
        )
    return plotter.add_mesh(mesh, color=colour if clim is None else "lightgrey", **style)


def _has(mesh: Any, name: str | None) -> bool:
    return name is not None and (name in mesh.point_data or name in mesh.cell_data)


def _nice_length(span: float) -> float:
    """1, 2 or 5 times a power of ten, about a fifth of ``span``."""
    raw = max(span / 5.0, 1e-9)
    power = 10.0 ** np.floor(np.log10(raw))
    return float(next(m * power for m in (1, 2, 5, 10) if m * power >= raw))


def _decorate(
    plotter: Any,
    scene: Scene,
    lows: NDArray[np.float64],
    highs: NDArray[np.float64],
    centre: NDArray[np.float64],
    scale: NDArray[np.float64],
    options: RenderOptions,
) -> None:
    """Title with the CRS, axes in world coordinates, a scale bar, and the camera."""
    crs = scene.crs
    names = crs.axis_names if crs is not None else ("X", "Y", "Z")
    units = crs.axis_units if crs is not None else ("m", "m", "m")
    where = "CRS unknown"
    if crs is not None:
        where = f"CRS {crs.label}" + (f" ({crs.name})" if crs.name and crs.epsg else "")
    title = options.title or f"{scene.name or 'model'} - {where}"
    plotter.add_text(title, position="upper_left", font_size=12, color="black")
    local_low, local_high = (lows - centre) * scale, (highs - centre) * scale
    along = np.abs(_direction(options)) > 0.99  # an axis the camera looks along shows nothing
    if options.axes:
        plotter.show_bounds(
            show_xaxis=not along[0],
            show_yaxis=not along[1],
            show_zaxis=not along[2],
            bounds=[local_low[0], local_high[0], local_low[1], local_high[1],
                    local_low[2], local_high[2]],
            axes_ranges=[lows[0], highs[0], lows[1], highs[1], lows[2], highs[2]],
            xtitle=f"{names[0]} ({units[0]})",
            ytitle=f"{names[1]} ({units[1]})",
            ztitle=f"{names[2]} ({units[2]})",
            fmt="%.0f",
            color="black",
            location="outer",
            ticks="outside",
            font_size=10,
        )  # fmt: skip
    if options.scale_bar:
        length = _nice_length(float(highs[0] - lows[0]))
        extent = np.maximum(local_high - local_low, 1e-9)
        # in front of and under the model's low corner: below it in every view
        start = local_low - np.array([0.0, 0.16, 0.16]) * extent
        end = start + np.array([length, 0.0, 0.0])
        plotter.add_mesh(_bar(start, end), color="black", line_width=6)
        text = f"{length:g} {units[0]}"
        below = (start + end) / 2 - np.array([0.0, 0.06, 0.06]) * extent
        plotter.add_point_labels(
            [below], [text], font_size=14, text_color="black",
            shape_opacity=0.0, show_points=False, always_visible=True,
        )  # fmt: skip
    _camera(plotter, local_low, local_high, options)


def _bar(start: NDArray[np.float64], end: NDArray[np.float64]) -> Any:
    pv = import_pyvista("rendering pictures")
    return pv.Line(start, end)


def _direction(options: RenderOptions) -> NDArray[np.float64]:
    """The unit vector from the model's centre to the camera."""
    if options.view is None and options.section_normal is not None:
        direction = np.asarray(options.section_normal, np.float64)
    else:
        direction = np.asarray(VIEWS[options.view or "isometric"], np.float64)
    return direction / np.linalg.norm(direction)


def _camera(
    plotter: Any,
    low: NDArray[np.float64],
    high: NDArray[np.float64],
    options: RenderOptions,
) -> None:
    direction = _direction(options)
    if options.section_normal is not None or options.view not in (None, "isometric"):
        plotter.enable_parallel_projection()  # square views: the scale bar holds everywhere
    focus = (low + high) / 2
    distance = 2.5 * float(np.linalg.norm(high - low)) + 1e-9
    up = (0.0, 1.0, 0.0) if abs(direction[2]) > 0.99 else (0.0, 0.0, 1.0)
    plotter.camera_position = [tuple(focus + direction * distance), tuple(focus), up]
    plotter.reset_camera()
    if options.azimuth:
        plotter.camera.azimuth = options.azimuth
    if options.elevation:
        plotter.camera.elevation = options.elevation
    plotter.camera.zoom(0.95)


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
