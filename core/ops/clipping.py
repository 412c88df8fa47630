"""Cutting entities and scenes by planes: :func:`clip`, :func:`clip_box` and :func:`section`.

The negative side of ``Plane(a, b, c, d)`` is where ``a·x + b·y + c·z + d < 0``. ``clip`` keeps one
side (``keep="negative"`` or ``"positive"``) or splits into both (``keep="both"`` returns the tuple
``(negative, positive)``). A clipped entity has the type of the input; ``None`` means nothing is
left. For a :class:`~geobrep.Scene`, the spatial index decides which entities straddle the
plane: only those are cut, the others are kept or dropped whole, and the B-Rep topology is carried
over (:mod:`geobrep.ops._clip_topology`): each cut block is closed again by a cap patch between it
and the universe.

The cutting itself is done by plugins: one :class:`~geobrep.plugins.ClipperSpec` per entity type,
called as ``function(entity, plane, keep, options, context)`` with a :class:`ClipContext`.

>>> import geobrep
>>> from geobrep.ops.clipping import clip
>>> cake = geobrep.datasets.faulted_layer_cake()
>>> west, east = clip(cake, geobrep.Plane.x(450_500.0), keep="both")
>>> len(west.blocks) + len(east.blocks) > len(cake.blocks)
True
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, TypeAlias, cast

import numpy as np
from pydantic import BaseModel

from geobrep.errors import DegenerateGeometryError, EntityValidationError, OptionsError, PluginError
from geobrep.geometry import BoundingBox, Plane
from geobrep.model.entities import Annotation, Block, Entity, Surface
from geobrep.model.scene import Scene
from geobrep.model.topology import Patch

if TYPE_CHECKING:
    from geobrep.demo import DemoContext
    from geobrep.host.registry import ClipperRegistry, ClipperSpec

__all__ = [
    "KEEP_CHOICES",
    "RELATIVE_TOLERANCE",
    "ClipContext",
    "Keep",
    "SceneDraft",
    "box_planes",
    "clip",
    "clip_box",
    "demo_stage",
    "halves",
    "pack_halves",
    "section",
]

Keep: TypeAlias = Literal["negative", "positive", "both"]
KEEP_CHOICES: tuple[str, ...] = ("negative", "positive", "both")

#: Default on-plane tolerance, relative to the diagonal of the clipped object's bounding box.
RELATIVE_TOLERANCE = 1e-9

ClipInput: TypeAlias = Entity | Scene
ClipOutput: TypeAlias = Any  # an entity, a Scene, None, or a (negative, positive) tuple of them


def halves(keep: Keep) -> tuple[int, ...]:
    """The sides a ``keep`` value asks for: ``(-1,)``, ``(1,)`` or ``(-1, 1)``.

    >>> halves("both")
    (-1, 1)
    """
    return {"negative": (-1,), "positive": (1,), "both": (-1, 1)}[keep]


def pack_halves(keep: Keep, parts: Mapping[int, Any]) -> Any:
    """What a clipper returns for ``keep``, from its result per side (−1, +1; missing = None).

    >>> pack_halves("both", {-1: "west"})
    ('west', None)
    """
    if keep == "both":
        return (parts.get(-1), parts.get(1))
    return parts.get(halves(keep)[0])


@dataclass
class SceneDraft:
    """One half of a scene being clipped: its entities by id, its patches, and block caps.

    The facade fills ``entities`` and ``patches`` before the Block clippers run; a Block clipper
    registers the cap that closes a cut block with :meth:`add_cap`.
    """

    side: int
    entities: dict[int, Entity] = field(default_factory=dict)
    patches: dict[int, Patch] = field(default_factory=dict)
    caps: dict[int, Surface] = field(default_factory=dict)

    def add_cap(self, block_id: int, cap: Surface) -> None:
        """Register ``cap`` (triangles on the plane, facing out of the block) for a block."""
        if block_id in self.caps:
            raise PluginError(f"block {block_id} got two caps in the same half")
        self.caps[block_id] = cap


@dataclass
class ClipContext:
    """What a clipper knows about the current cut besides its entity, plane and options.

    ``tolerance`` is the absolute distance within which a point counts as on the plane (the same
    for every entity of a scene, so shared vertices are classified alike). ``scene`` is the scene
    being clipped (``None`` for a lone entity); ``drafts`` holds its halves (side −1 and/or +1)
    for clippers that need their neighbours (blocks); ``cache`` lets clippers share work.
    """

    tolerance: float
    scene: Scene | None = None
    drafts: dict[int, SceneDraft] = field(default_factory=dict)
    cache: dict[Any, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)


# ------------------------------------------------------------------------------- public API
def clip(
    obj: ClipInput,
    plane: Plane | Sequence[float],
    keep: Keep = "negative",
    *,
    tolerance: float | None = None,
    options: Mapping[str, Any] | None = None,
    clippers: Mapping[str, str] | None = None,
) -> ClipOutput:
    """Cut an entity or a scene by ``plane`` and keep one side, or both.

    Args:
        obj: an entity (not a Block: blocks are cut with their scene) or a Scene.
        plane: a :class:`~geobrep.geometry.Plane` or its coefficients ``(a, b, c, d)``.
        keep: ``"negative"`` (``a·x+b·y+c·z+d < 0``), ``"positive"``, or ``"both"``, which
            returns ``(negative, positive)``.
        tolerance: distance within which a point counts as on the plane (default
            :data:`RELATIVE_TOLERANCE` × the diagonal of ``obj``'s bounding box).
        options: options per clipper name, e.g. ``{"annotation": {"precision": "stroke"}}``.
        clippers: the clipper to use per entity type when several are registered.

    Returns:
        The clipped entity (same type) or ``None`` when nothing is left; a Scene for a Scene;
        the tuple ``(negative, positive)`` for ``keep="both"``.

    >>> import numpy as np
    >>> from geobrep import Plane, PolyLine
    >>> line = PolyLine(vertices=np.array([[0.0, 0, 0], [2, 0, 0], [2, 2, 0]]))
    >>> clip(line, Plane.x(1)).vertices.tolist()
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    """
    the_plane = as_plane(plane)
    the_keep = _check_keep(keep)
    context = ClipContext(tolerance=_tolerance(tolerance, obj), options=_check_options(options))
    registry = _registry()
    choice = dict(clippers or {})
    if isinstance(obj, Scene):
        context.scene = obj
        return _clip_scene(obj, the_plane, the_keep, context, registry, choice)
    if isinstance(obj, Block):
        raise EntityValidationError(
            obj.label, "obj", "a Block is clipped with its scene: call clip(scene, plane)"
        )
    if isinstance(obj, Entity):
        return clip_entity(obj, the_plane, the_keep, context, registry, choice)
    raise EntityValidationError(
        "clip", "obj", f"expected an entity or a Scene, got {type(obj).__name__}"
    )


def clip_box(
    obj: ClipInput,
    bounds: BoundingBox | Sequence[float] | Iterable[Plane | Sequence[float]],
    *,
    tolerance: float | None = None,
    options: Mapping[str, Any] | None = None,
    clippers: Mapping[str, str] | None = None,
) -> ClipOutput:
    """Keep the inside of an axis-aligned box, or of a convex set of planes (a "carved column").

    ``bounds`` is ``(xmin, xmax, ymin, ymax, zmin, zmax)``, a :class:`BoundingBox`, or planes
    whose negative sides all contain the inside (normals pointing out). The cut is made plane
    after plane, keeping the negative side each time; ``None`` if nothing is left.

    >>> import numpy as np
    >>> from geobrep import PointSet
    >>> points = PointSet(vertices=np.array([[0.5, 0.5, 0.5], [2.0, 0.0, 0.0]]))
    >>> clip_box(points, (0, 1, 0, 1, 0, 1)).n_points
    1
    """
    planes = box_planes(bounds)
    base = _tolerance(tolerance, obj)
    result: ClipOutput = obj
    for plane in planes:
        if result is None:
            return None
        result = clip(result, plane, "negative", tolerance=base, options=options, clippers=clippers)
    return result


def section(
    obj: ClipInput,
    plane: Plane | Sequence[float],
    *,
    tolerance: float | None = None,
    options: Mapping[str, Any] | None = None,
    clippers: Mapping[str, str] | None = None,
) -> ClipOutput:
    """The cut itself: what lies on ``plane``.

    For a Scene: a new Scene with one :class:`~geobrep.Polygon` per cut block (its
    section with holes, named after the block, ``kind="section"``, the block's id, unit and
    metadata in ``metadata``) and one :class:`~geobrep.PolyLine` trace per cut open
    surface (``kind`` of the surface, its id in ``metadata["surface"]``): a fence-diagram panel.
    For an entity: its section (a closed Surface gives a Polygon, an open one a PolyLine, a
    PolyLine a PointSet, a Polygon a PolyLine), or ``None`` if the plane misses it.

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> panel = section(cake, geobrep.Plane.y(6_700_400.0))
    >>> sorted({e.kind for e in panel.entities})
    ['boundary', 'fault', 'horizon', 'section']
    """
    the_plane = as_plane(plane)
    context = ClipContext(tolerance=_tolerance(tolerance, obj), options=_check_options(options))
    registry = _registry()
    choice = dict(clippers or {})
    if isinstance(obj, Scene):
        context.scene = obj
        return _section_scene(obj, the_plane, context, registry, choice)
    if isinstance(obj, Entity):
        if isinstance(obj, Block):
            raise EntityValidationError(
                obj.label, "obj", "a Block is sectioned with its scene: call section(scene, plane)"
            )
        spec = _clipper_for(type(obj).__name__, registry, choice)
        return _section_entity(obj, the_plane, spec, context)
    raise EntityValidationError(
        "section", "obj", f"expected an entity or a Scene, got {type(obj).__name__}"
    )


def box_planes(
    bounds: BoundingBox | Sequence[float] | Iterable[Plane | Sequence[float]],
) -> list[Plane]:
    """The planes bounding a box or convex region, normals pointing out.

    >>> [p.coefficients.tolist() for p in box_planes((0, 1, 0, 2, 0, 3))][:2]
    [[-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, -1.0]]
    """
    if isinstance(bounds, BoundingBox):
        bounds = bounds.as_tuple()
    items: list[Any] = list(bounds)
    if len(items) == 6 and all(isinstance(v, int | float | np.number) for v in items):
        xmin, xmax, ymin, ymax, zmin, zmax = (float(v) for v in items)
        if not (xmin <= xmax and ymin <= ymax and zmin <= zmax):
            raise EntityValidationError(
                "clip_box", "bounds", f"expected xmin ≤ xmax, ymin ≤ ymax, zmin ≤ zmax: {items}"
            )
        return [
            Plane(-1.0, 0.0, 0.0, xmin),
            Plane(1.0, 0.0, 0.0, -xmax),
            Plane(0.0, -1.0, 0.0, ymin),
            Plane(0.0, 1.0, 0.0, -ymax),
            Plane(0.0, 0.0, -1.0, zmin),
            Plane(0.0, 0.0, 1.0, -zmax),
        ]
    if not items:
        raise EntityValidationError("clip_box", "bounds", "no planes given")
    return [as_plane(item) for item in items]


def as_plane(plane: Plane | Sequence[float] | Any) -> Plane:
    """A :class:`Plane` from a plane or its four coefficients.

    >>> as_plane((1, 0, 0, -450))
    Plane(a=1.0, b=0.0, c=0.0, d=-450.0)
    """
    if isinstance(plane, Plane):
        return plane
    try:
        values = [float(v) for v in plane]
    except (TypeError, ValueError) as exc:
        raise DegenerateGeometryError(
            f"plane: expected a Plane or four numbers (a, b, c, d), got {plane!r}"
        ) from exc
    if len(values) != 4:
        raise DegenerateGeometryError(
            f"plane: expected four numbers (a, b, c, d), got {len(values)}"
        )
    return Plane(*values)


# ------------------------------------------------------------------------------- dispatch
def _registry() -> ClipperRegistry:
    from geobrep.host import registries

    return registries().clippers


def _check_keep(keep: Any) -> Keep:
    if keep not in KEEP_CHOICES:
        raise OptionsError(f"keep must be one of {', '.join(KEEP_CHOICES)}; got {keep!r}")
    return cast(Keep, keep)


def _check_options(options: Mapping[str, Any] | None) -> Mapping[str, Any]:
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise OptionsError(
            f"options must map clipper names to their options, got {type(options).__name__}"
        )
    names = set(_registry().names())
    unknown = sorted(set(options) - names)
    if unknown:
        raise OptionsError(
            f"options for unknown clipper(s) {', '.join(map(repr, unknown))} "
            f"(clippers: {', '.join(sorted(names))})"
        )
    return options


def _tolerance(tolerance: float | None, obj: Any) -> float:
    if tolerance is not None:
        value = float(tolerance)
        if not np.isfinite(value) or value < 0:
            raise OptionsError(f"tolerance must be finite and ≥ 0, got {tolerance!r}")
        return value
    bounds = getattr(obj, "bounds", None)
    if not isinstance(bounds, BoundingBox):
        return 0.0
    return RELATIVE_TOLERANCE * bounds.diagonal


def _clipper_for(
    type_name: str, registry: ClipperRegistry, choice: Mapping[str, str]
) -> ClipperSpec:
    from geobrep.host.registry import UnknownItemError

    wanted = choice.get(type_name)
    if wanted is not None:
        if wanted not in registry:
            raise UnknownItemError(
                f"no clipper named {wanted!r} (clippers: {', '.join(registry.names())})"
            )
        spec = registry.get(wanted)
        if spec.entity_type != type_name:
            raise OptionsError(f"clipper {wanted!r} cuts {spec.entity_type}, not {type_name}")
        return spec
    candidates = registry.for_entity_type(type_name)
    if not candidates:
        raise UnknownItemError(
            f"no clipper is registered for {type_name} entities "
            f"(clippers: {', '.join(registry.names()) or 'none'})"
        )
    return candidates[0]


def _validated(spec: ClipperSpec, context: ClipContext) -> BaseModel:
    return spec.validate_options(context.options.get(spec.name))


def clip_entity(
    entity: Entity,
    plane: Plane,
    keep: Keep,
    context: ClipContext,
    registry: ClipperRegistry | None = None,
    choice: Mapping[str, str] | None = None,
) -> ClipOutput:
    """Hand one entity to the clipper registered for its type and check what comes back."""
    spec = _clipper_for(type(entity).__name__, registry or _registry(), choice or {})
    result = spec.function(entity, plane, keep, _validated(spec, context), context)
    parts = result if keep == "both" else (result,)
    if not isinstance(parts, tuple) or len(parts) != len(halves(keep)):
        raise PluginError(
            f"{spec.label} returned {type(result).__name__} for keep={keep!r}; expected "
            + ("a (negative, positive) tuple" if keep == "both" else "one entity or None")
        )
    for part in parts:
        if part is not None and type(part) is not type(entity):
            raise PluginError(
                f"{spec.label} turned {entity.label} into a {type(part).__name__}; "
                f"a clipped entity keeps its type"
            )
    return result


def _section_entity(
    entity: Entity, plane: Plane, spec: ClipperSpec, context: ClipContext
) -> Entity | None:
    if spec.section is None:
        return None
    result = spec.section(entity, plane, _validated(spec, context), context)
    if result is not None and not isinstance(result, Entity):
        raise PluginError(f"{spec.label} section returned {type(result).__name__}")
    return result


# ------------------------------------------------------------------------------- scenes
def _entity_sides(scene: Scene, plane: Plane, tolerance: float) -> dict[int, int]:
    index = scene.index
    if len(index) == 0:
        return {}
    sides = index.plane_side(plane, tolerance)
    return dict(zip(index.ids.tolist(), sides.tolist(), strict=True))


def _clip_scene(
    scene: Scene,
    plane: Plane,
    keep: Keep,
    context: ClipContext,
    registry: ClipperRegistry,
    choice: Mapping[str, str],
) -> ClipOutput:
    from geobrep.ops._clip_topology import carry_topology

    wanted = halves(keep)
    context.drafts = {side: SceneDraft(side) for side in wanted}
    box_side = _entity_sides(scene, plane, context.tolerance)
    for entity in scene.entities:
        if isinstance(entity, Block):
            continue
        ident = int(entity.id or 0)
        # An annotation's box is its anchor only: its glyphs may reach across the plane.
        side = 0 if isinstance(entity, Annotation) else box_side.get(ident, 0)
        if entity.bounds is None and not isinstance(entity, Annotation):
            side = 2  # no geometry: belongs to every half
        if side in (-1, 1, 2):
            for half in wanted:
                if side in (half, 2):
                    context.drafts[half].entities[ident] = entity
            continue
        result = clip_entity(entity, plane, keep, context, registry, choice)
        parts = result if keep == "both" else (result,)
        for half, part in zip(wanted, parts, strict=True):
            if part is not None:
                context.drafts[half].entities[ident] = part

    def clip_block(block: Block) -> tuple[Block | None, ...]:
        result = clip_entity(block, plane, keep, context, registry, choice)
        return tuple(result) if keep == "both" else (result,)

    scenes = carry_topology(scene, plane, keep, context, clip_block, registry, choice)
    return scenes if keep == "both" else scenes[0]


def _section_scene(
    scene: Scene,
    plane: Plane,
    context: ClipContext,
    registry: ClipperRegistry,
    choice: Mapping[str, str],
) -> Scene:
    box_side = _entity_sides(scene, plane, context.tolerance)
    found: list[Entity] = []
    traces: list[int] = []
    for entity in scene.entities:
        ident = int(entity.id or 0)
        if isinstance(entity, Block) or box_side.get(ident, 0) != 0:
            continue
        spec = _clipper_for(type(entity).__name__, registry, choice)
        cut = _section_entity(entity, plane, spec, context)
        if cut is None:
            continue
        found.append(cut.model_copy(update={"id": None}))
        traces.append(ident)
    polygons: list[Entity] = []
    if scene.patches:
        for block in scene.blocks:
            spec = _clipper_for("Block", registry, choice)
            cut = _section_entity(block, plane, spec, context)
            if cut is not None:
                polygons.append(cut)
    entities = [*polygons, *found]
    scene_out = Scene(entities=entities, crs=scene.crs, name=f"{scene.name} section".strip())
    from geobrep.model.scene import Group

    ids_sections = tuple(int(e.id or 0) for e in scene_out.entities[: len(polygons)])
    ids_traces = tuple(int(e.id or 0) for e in scene_out.entities[len(polygons) :])
    groups = []
    if ids_sections:
        groups.append(Group(name="sections", kind="sections", members=ids_sections))
    if ids_traces:
        groups.append(Group(name="traces", kind="traces", members=ids_traces))
    return scene_out.replace(groups=tuple(groups))


# ------------------------------------------------------------------------------- demo
def demo_stage(ctx: DemoContext) -> None:
    """Demo: cut the layer cake with a vertical plane into two closed halves, and section it."""
    from geobrep.ops.io import write

    scene = ctx.scene
    bounds = scene.bounds
    assert bounds is not None
    # A vertical plane through the model's centre, oblique to the fault: it cuts every block.
    plane = Plane.from_point_normal(bounds.center, (1.0, 0.8, 0.0))
    _registry()  # load the plugins before timing the cut
    start = time.perf_counter()
    negative, positive = clip(scene, plane, keep="both")
    elapsed = time.perf_counter() - start
    rows: list[dict[str, Any]] = []
    worst = 0.0
    for block in scene.blocks:
        original = scene.block_mesh(block).volume
        parts = []
        for half in (negative, positive):
            if int(block.id or 0) in half and isinstance(half[int(block.id or 0)], Block):
                mesh = half.block_mesh(int(block.id or 0))
                parts.append((mesh.volume, mesh.is_closed and mesh.is_consistently_oriented))
            else:
                parts.append((0.0, True))
        total = parts[0][0] + parts[1][0]
        worst = max(worst, abs(total - original) / original)
        rows.append(
            {
                "id": block.id,
                "name": block.name,
                "volume_m3": original,
                "west_m3": parts[0][0],
                "east_m3": parts[1][0],
                "closed_and_oriented": parts[0][1] and parts[1][1],
            }
        )
    panel = section(scene, plane)
    section_rows = [
        {"block": e.metadata.get("block"), "name": e.name, "area_m2": getattr(e, "area", None)}
        for e in panel.entities
        if e.kind == "section"
    ]
    caps = [e for e in negative.surfaces if e.kind == "cap"]
    west_path = ctx.output / "layer_cake_west.geobrep"
    east_path = ctx.output / "layer_cake_east.geobrep"
    section_path = ctx.output / "layer_cake_section.geobrep"
    write(negative, west_path)
    write(positive, east_path)
    write(panel, section_path)
    ctx.summary["clip"] = {
        "plane": plane.coefficients.tolist(),
        "seconds": elapsed,
        "blocks": rows,
        "worst_relative_volume_error": worst,
        "cap_patches": sum(c.n_patches for c in caps),
        "sections": section_rows,
        "files": [str(west_path), str(east_path), str(section_path)],
    }
    ctx.lines.append(
        f"clip: a vertical plane cut {len(scene.blocks)} blocks into {len(negative.blocks)} "
        f"west + {len(positive.blocks)} east in {elapsed:.3f} s; volumes conserved within "
        f"{worst:.1e} (relative); {sum(c.n_patches for c in caps)} cap patches per side"
    )
    for row in rows:
        ctx.lines.append(
            f"  block #{row['id']} {row['name']!r:24} {row['volume_m3']:14.1f} m³ = "
            f"{row['west_m3']:14.1f} + {row['east_m3']:14.1f}  "
            f"closed={row['closed_and_oriented']}"
        )
    for row in section_rows:
        ctx.lines.append(
            f"  section of block #{row['block']} {row['name']!r}: {row['area_m2']:.1f} m²"
        )
    ctx.lines.append(f"  wrote {west_path.name}, {east_path.name}, {section_path.name}")
