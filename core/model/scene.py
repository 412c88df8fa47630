"""The scene graph: entities by id and name, a group tree, CRS, topology and a spatial index."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Sequence
from functools import cache, cached_property
from typing import TYPE_CHECKING, Annotated, Any, Self, TypeVar

import numpy as np
from numpy.typing import NDArray
from pydantic import (
    BeforeValidator,
    Field,
    GetCoreSchemaHandler,
    JsonValue,
    TypeAdapter,
    ValidationError,
    model_validator,
)
from pydantic_core import CoreSchema

from geobrep.errors import (
    EntityNotFoundError,
    EntityValidationError,
    GeobrepError,
    TopologyError,
)
from geobrep.geometry import mesh
from geobrep.geometry.bbox import BoundingBox
from geobrep.geometry.spatial_index import SpatialIndex
from geobrep.model.base import FrozenModel
from geobrep.model.crs import CRS, as_crs
from geobrep.model.entities import Block, Entity, PointSet, PolyLine, Surface, is_entity_class
from geobrep.model.topology import Patch, Topology

if TYPE_CHECKING:
    from geobrep.model.entities import (
        Annotation,
        AnyEntity,
        LinearOctree,
        NurbsSurface,
        Polygon,
        RegularGrid,
        StructuredGrid,
        TetMesh,
        Well,
    )

__all__ = ["STRATIGRAPHIC_COLUMN", "Group", "Scene"]

E = TypeVar("E", bound=Entity)

#: Default tolerance for joining coincident vertices of different surfaces, relative to the
#: diagonal of the model's bounding box.
RELATIVE_MERGE_TOLERANCE = 1e-9

STRATIGRAPHIC_COLUMN = "stratigraphic_column"
"""The kind of a group that is a stratigraphic column (a SKUA horizon stack): its children are a
group of kind ``horizons`` and one of kind ``stratigraphic_units``, each listing theirs top down
(see docs/grids-wells-rasters.md)."""


class Group(FrozenModel):
    """A named group of entities (a GOCAD LAYER or FAULT_BLOCK, a folder), possibly nested."""

    name: str
    kind: str | None = None
    members: tuple[int, ...] = ()
    children: tuple[Group, ...] = ()
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    def walk(self) -> Iterable[Group]:
        """This group and all groups below it, depth first."""
        yield self
        for child in self.children:
            yield from child.walk()


def _assign_ids(entities: Sequence[Any]) -> list[Any]:
    """Give every entity without an id the next free one, in order."""
    used: set[int] = set()
    for item in entities:
        ident = (
            item.id
            if isinstance(item, Entity)
            else item.get("id")
            if isinstance(item, dict)
            else None
        )
        if isinstance(ident, int):
            used.add(ident)
    next_id = max(used, default=-1) + 1
    result = []
    for item in entities:
        if isinstance(item, Entity) and item.id is None:
            item = item.model_copy(update={"id": next_id})
            next_id += 1
        elif isinstance(item, dict) and item.get("id") is None:
            item = {**item, "id": next_id}
            next_id += 1
        result.append(item)
    return result


class _EveryEntityType:
    """Stands for :data:`geobrep.model.entities.AnyEntity` in the ``entities`` field: the schema
    pydantic builds for it is that union's, built (and its entity modules imported) only when the
    scene's own schema is, on first validation (the scene's schema is deferred). A reader's
    scene, made by :meth:`Scene.from_validated`, imports no entity type the file does not hold.
    """

    def __get_pydantic_core_schema__(
        self, source: Any, handler: GetCoreSchemaHandler
    ) -> CoreSchema:
        from geobrep.model.entities import AnyEntity

        return handler.generate_schema(AnyEntity)


if not TYPE_CHECKING:
    AnyEntity = Annotated[Entity, _EveryEntityType()]


@cache
def _json_object() -> TypeAdapter[dict[str, JsonValue]]:
    """Validates a scene's ``metadata`` as its field does."""
    return TypeAdapter(dict[str, JsonValue])


class Scene(FrozenModel):
    """A structural model: entities, groups, CRS and topology.

    Entities get ids in order when they have none. A scene is immutable; operations return new
    scenes (:meth:`with_entities`, :meth:`replace`). ``crs`` takes a :class:`~geobrep.CRS` or
    what pyproj accepts (``"EPSG:32633"``, ``32633``, WKT, a ``pyproj.CRS``; see
    :func:`geobrep.model.crs.as_crs`).

    >>> from geobrep import PointSet, Scene
    >>> scene = Scene(entities=[PointSet(vertices=[[0, 0, 0]], name="wells")])
    >>> scene["wells"].id
    0
    """

    entities: tuple[AnyEntity, ...] = ()
    groups: tuple[Group, ...] = ()
    crs: Annotated[CRS | None, BeforeValidator(as_crs)] = None
    topology: Topology = Field(default_factory=Topology)
    name: str = ""
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    def __init__(self, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            first = exc.errors()[0]
            original = (first.get("ctx") or {}).get("error")
            if isinstance(original, GeobrepError):
                raise original from exc
            loc = ".".join(str(p) for p in first["loc"]) or "(scene)"
            message = first["msg"].removeprefix("Value error, ")
            raise EntityValidationError("Scene", loc, message) from exc

    @classmethod
    def from_validated(
        cls,
        *,
        entities: Sequence[Entity],
        groups: Sequence[Group] = (),
        crs: CRS | None = None,
        topology: Topology | None = None,
        name: str = "",
        metadata: dict[str, Any] | None = None,
    ) -> Scene:
        """The scene ``Scene(entities=..., ...)`` makes of parts that are models validated
        already (a reader's), checked as that would check them but without validating the
        parts again: the entities, groups and topology are taken as they are, the metadata
        validated, ids given and references checked. Parts of any other kind go through the
        constructor. (The scene's own schema, one branch per entity type, is then built only
        when a scene is first validated.)
        """
        values: dict[str, Any] = {
            "entities": entities,
            "groups": groups,
            "crs": crs,
            # the empty topology Topology() validates to (its schema is built on first use)
            "topology": topology if topology is not None else Topology.model_construct(),
            "name": name,
            "metadata": metadata if metadata is not None else {},
        }
        taken = (
            all(is_entity_class(type(e)) for e in entities)
            and all(type(g) is Group for g in groups)
            and (crs is None or type(crs) is CRS)
            and type(values["topology"]) is Topology
            and type(name) is str
        )
        if not taken:
            return cls(**values)
        try:  # (an empty mapping needs no schema: none is built for it)
            metadata = values["metadata"]
            empty = type(metadata) is dict and not metadata
            checked = {} if empty else _json_object().validate_python(metadata)
        except ValidationError as exc:  # as the constructor reports it
            first = exc.errors()[0]
            loc = ".".join(str(p) for p in ("metadata", *first["loc"]))
            message = first["msg"].removeprefix("Value error, ")
            raise EntityValidationError("Scene", loc, message) from exc
        values["entities"] = tuple(_assign_ids(list(entities)))
        values["groups"] = tuple(groups)
        values["metadata"] = checked
        scene = cls.model_construct(**values)
        scene._check_ids_and_references()
        return scene

    @model_validator(mode="before")
    @classmethod
    def _give_ids(cls, data: Any) -> Any:
        if isinstance(data, dict) and data.get("entities"):
            data = {**data, "entities": _assign_ids(list(data["entities"]))}
        return data

    @model_validator(mode="after")
    def _check_references(self) -> Self:
        self._check_ids_and_references()
        return self

    def _check_ids_and_references(self) -> None:
        ids = [entity.id for entity in self.entities]
        if len(set(ids)) != len(ids):
            duplicate = next(i for i in ids if ids.count(i) > 1)
            raise EntityValidationError("Scene", "entities", f"entity id {duplicate} is used twice")
        by_id = self.entity_by_id
        for group in (g for root in self.groups for g in root.walk()):
            missing = [m for m in group.members if m not in by_id]
            if missing:
                raise EntityValidationError(
                    "Scene", f"groups[{group.name!r}]", f"member {missing[0]} is not an entity id"
                )
        self._check_topology()

    def _check_topology(self) -> None:
        by_id = self.entity_by_id
        for patch in self.topology.patches:
            surface = by_id.get(patch.surface)
            if not isinstance(surface, Surface):
                raise TopologyError(f"patch {patch.id}: entity {patch.surface} is not a Surface")
            if patch.label >= surface.n_patches:
                raise TopologyError(
                    f"patch {patch.id}: {surface.label} has no patch label {patch.label}"
                )
            for block_id in (patch.positive_block, patch.negative_block):
                if block_id is not None and not isinstance(by_id.get(block_id), Block):
                    raise TopologyError(f"patch {patch.id}: entity {block_id} is not a Block")
        patches = self.topology.patch_by_id
        owner: dict[tuple[int, int], int] = {}
        for block in self.of_type(Block):
            for patch_id, side in block.sides:
                listed = patches.get(patch_id)
                if listed is None:
                    raise TopologyError(f"{block.label}: patch {patch_id} does not exist")
                expected = listed.positive_block if side == 1 else listed.negative_block
                if expected is not None and expected != block.id:
                    raise TopologyError(
                        f"{block.label}: lists side {side:+d} of patch {patch_id}, "
                        f"but the patch gives that side to block {expected}"
                    )
                previous = owner.setdefault((patch_id, side), int(block.id or 0))
                if previous != block.id:
                    raise TopologyError(
                        f"side {side:+d} of patch {patch_id} is claimed by blocks "
                        f"{previous} and {block.id}"
                    )

    # -- lookup ---------------------------------------------------------------------------------
    @cached_property
    def entity_by_id(self) -> dict[int, Entity]:
        return {int(e.id): e for e in self.entities if e.id is not None}

    @cached_property
    def _by_name(self) -> dict[str, list[Entity]]:
        names: dict[str, list[Entity]] = defaultdict(list)
        for entity in self.entities:
            names[entity.name].append(entity)
        return dict(names)

    def get(self, entity_id: int) -> Entity:
        """The entity with this id (KeyError-compatible GeobrepError if absent)."""
        try:
            return self.entity_by_id[entity_id]
        except KeyError:
            raise EntityNotFoundError(f"no entity with id {entity_id}") from None

    def find(self, name: str) -> list[Entity]:
        """All entities with this name (names need not be unique)."""
        return list(self._by_name.get(name, []))

    def __getitem__(self, key: int | str) -> Entity:
        """``scene[3]`` by id, ``scene["top"]`` by name (an error if the name is ambiguous)."""
        if isinstance(key, int):
            return self.get(key)
        found = self.find(key)
        if len(found) == 1:
            return found[0]
        if not found:
            raise EntityNotFoundError(f"no entity named {key!r}")
        ids = ", ".join(str(e.id) for e in found)
        raise EntityNotFoundError(
            f"{len(found)} entities are named {key!r} (ids {ids}): use the id"
        )

    def __len__(self) -> int:
        return len(self.entities)

    def __contains__(self, key: object) -> bool:
        if isinstance(key, int):
            return key in self.entity_by_id
        if isinstance(key, str):
            return key in self._by_name
        return any(key is entity for entity in self.entities)

    def of_type(self, cls: type[E]) -> tuple[E, ...]:
        """Entities of one class, in scene order."""
        return tuple(e for e in self.entities if isinstance(e, cls))

    @property
    def surfaces(self) -> tuple[Surface, ...]:
        return self.of_type(Surface)

    @property
    def point_sets(self) -> tuple[PointSet, ...]:
        return self.of_type(PointSet)

    @property
    def polylines(self) -> tuple[PolyLine, ...]:
        return self.of_type(PolyLine)

    @property
    def polygons(self) -> tuple[Polygon, ...]:
        from geobrep.model.entities.polygon import Polygon

        return self.of_type(Polygon)

    @property
    def tet_meshes(self) -> tuple[TetMesh, ...]:
        from geobrep.model.entities.tetmesh import TetMesh

        return self.of_type(TetMesh)

    @property
    def nurbs_surfaces(self) -> tuple[NurbsSurface, ...]:
        from geobrep.model.entities.nurbs import NurbsSurface

        return self.of_type(NurbsSurface)

    @property
    def annotations(self) -> tuple[Annotation, ...]:
        from geobrep.model.entities.annotation import Annotation

        return self.of_type(Annotation)

    @property
    def octrees(self) -> tuple[LinearOctree, ...]:
        from geobrep.model.entities.octree import LinearOctree

        return self.of_type(LinearOctree)

    @property
    def regular_grids(self) -> tuple[RegularGrid, ...]:
        from geobrep.model.entities.grid import RegularGrid

        return self.of_type(RegularGrid)

    @property
    def structured_grids(self) -> tuple[StructuredGrid, ...]:
        from geobrep.model.entities.structured import StructuredGrid

        return self.of_type(StructuredGrid)

    @property
    def wells(self) -> tuple[Well, ...]:
        from geobrep.model.entities.well import Well

        return self.of_type(Well)

    @property
    def blocks(self) -> tuple[Block, ...]:
        """The geological blocks (the universe, if any, is :attr:`universe`)."""
        return tuple(b for b in self.of_type(Block) if not b.is_universe)

    @property
    def universe(self) -> Block | None:
        """The outer region around the model, when the topology has one."""
        return next((b for b in self.of_type(Block) if b.is_universe), None)

    @property
    def patches(self) -> tuple[Patch, ...]:
        return self.topology.patches

    @property
    def stratigraphic_columns(self) -> tuple[Group, ...]:
        """The groups of kind :data:`STRATIGRAPHIC_COLUMN`, anywhere in the group tree."""
        return tuple(
            g for root in self.groups for g in root.walk() if g.kind == STRATIGRAPHIC_COLUMN
        )

    @property
    def holds_nothing(self) -> bool:
        """True when no entity has geometry and there is no stratigraphic column."""
        return self.bounds is None and not self.stratigraphic_columns

    # -- geometry -------------------------------------------------------------------------------
    @cached_property
    def bounds(self) -> BoundingBox | None:
        """Box around every entity with geometry."""
        boxes = [b for b in (e.bounds for e in self.entities) if b is not None]
        if not boxes:
            return None
        result = boxes[0]
        for box in boxes[1:]:
            result = result.union(box)
        return result

    @cached_property
    def index(self) -> SpatialIndex:
        """R-tree of entity bounding boxes, keyed by entity id."""
        located = [(e.id, e.bounds) for e in self.entities if e.bounds is not None]
        ids = np.array([int(i or 0) for i, _ in located], dtype=np.int64)
        mins = np.array([b.mins for _, b in located], dtype=np.float64).reshape(-1, 3)
        maxs = np.array([b.maxs for _, b in located], dtype=np.float64).reshape(-1, 3)
        return SpatialIndex(ids, mins, maxs)

    def _block(self, block: Block | int | str) -> Block:
        found = block if isinstance(block, Block) else self[block]
        if not isinstance(found, Block):
            raise TopologyError(f"{found.label} is not a Block")
        return found

    def block_mesh(self, block: Block | int | str, tolerance: float | None = None) -> Surface:
        """The closed boundary of a block as one outward-oriented surface.

        Each listed patch contributes its faces, flipped when the block is on the patch's
        positive side (the side its normal points to); patches listed with both sides lie inside
        the block and are left out. Coincident vertices of different surfaces are joined within
        ``tolerance`` (default: 1e-9 of the model's bounding-box diagonal). One patch label per
        side keeps track of where each face came from.
        """
        target = self._block(block)
        internal = target.internal_patches
        sides = [s for s in target.sides if s.patch not in internal]
        if not sides:
            raise TopologyError(f"{target.label} has no boundary patches")
        surfaces: dict[int, Surface] = {}
        offsets: dict[int, int] = {}
        pieces: list[NDArray[np.int64]] = []
        labels: list[NDArray[np.int64]] = []
        names: list[str] = []
        total = 0
        for position, (patch_id, side) in enumerate(sides):
            patch = self.topology.patch(patch_id)
            surface = self.get(patch.surface)
            assert isinstance(surface, Surface)  # checked at construction
            if patch.surface not in surfaces:
                surfaces[patch.surface] = surface
                offsets[patch.surface] = total
                total += surface.n_vertices
            triangles, _ = mesh.triangulate(surface.faces[surface.patch_faces(patch.label)])
            triangles = triangles.astype(np.int64) + offsets[patch.surface]
            pieces.append(mesh.flip_faces(triangles) if side == 1 else triangles)
            labels.append(np.full(len(triangles), position, dtype=np.int64))
            names.append(
                patch.name or f"{surface.name or surface.label}:{surface.patch_name(patch.label)}"
            )
        vertices = np.concatenate([s.vertices for s in surfaces.values()])
        faces = np.concatenate(pieces)
        used, faces = mesh.compact_indices(faces, vertices.shape[0])
        vertices = vertices[used]
        if tolerance is None:
            tolerance = RELATIVE_MERGE_TOLERANCE * (self.bounds.diagonal if self.bounds else 1.0)
        merged, inverse = mesh.merge_close_vertices(vertices, tolerance)
        faces = inverse[faces]
        keep = (
            (faces[:, 0] != faces[:, 1])
            & (faces[:, 1] != faces[:, 2])
            & (faces[:, 0] != faces[:, 2])
        )
        used, compact = mesh.compact_indices(faces[keep], merged.shape[0])
        return Surface(
            vertices=merged[used],
            faces=compact,
            patch_labels=np.concatenate(labels)[keep],
            patch_names=tuple(names),
            name=target.name,
            kind=target.kind,
            metadata={"block": int(target.id or 0)},
        )

    def block_adjacency(self) -> list[tuple[int, int]]:
        """Pairs ``(a, b)``, ``a < b``, of blocks that share a patch (the universe excluded)."""
        positive: dict[int, int] = {}
        negative: dict[int, int] = {}
        for block in self.blocks:
            for patch_id, side in block.sides:
                (positive if side == 1 else negative)[patch_id] = int(block.id or 0)
        pairs = {
            (min(a, b), max(a, b))
            for patch_id, a in positive.items()
            if (b := negative.get(patch_id)) is not None and a != b
        }
        return sorted(pairs)

    # -- derivation -----------------------------------------------------------------------------
    def with_entities(self, *entities: Entity) -> Scene:
        """A new scene with these entities appended (ids assigned where missing)."""
        return self.replace(entities=(*self.entities, *entities))

    def replace(self, **changes: Any) -> Scene:
        """A validated copy with some fields changed."""
        values = {name: getattr(self, name) for name in type(self).model_fields}
        values.update(changes)
        return Scene(**values)

    def to_crs(self, target: Any, *, source: Any = None) -> Scene:
        """This scene reprojected into ``target`` (see :func:`geobrep.gis.crs_ops.to_crs`).

        >>> import geobrep
        >>> geobrep.datasets.faulted_layer_cake().to_crs("EPSG:32632").crs.label
        'EPSG:32632'
        """
        from geobrep.gis.crs_ops import to_crs

        return to_crs(self, target, source=source)

    def __repr__(self) -> str:
        counts: dict[str, int] = defaultdict(int)
        for entity in self.entities:
            counts[type(entity).__name__] += 1
        inner = ", ".join(f"{n} {t}" for t, n in sorted(counts.items()))
        crs = f", crs={self.crs.label}" if self.crs else ""
        return f"Scene({self.name!r}: {inner or 'empty'}{crs}, {len(self.patches)} patches)"

    __str__ = __repr__
