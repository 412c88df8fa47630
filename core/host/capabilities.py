"""What a format cannot hold of a scene: the loss report behind honest conversion.

:func:`capability_losses` compares a scene with a format's
:class:`~geobrep.host.registry.FormatCapabilities` and lists, in words, what writing would drop;
:func:`restrict_scene` drops exactly that, so a writer never meets what it cannot store.

>>> import geobrep
>>> from geobrep.host.registry import FormatCapabilities, FormatRegistry
>>> caps = FormatCapabilities(entity_types=frozenset({"Surface"}), names=True,
...                           multiple_entities=True)
>>> capability_losses(geobrep.datasets.faulted_layer_cake(), caps)[:2]
['7 Block entities dropped (format holds Surface)', 'topology dropped (31 patches)']
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec
from geobrep.model.entities import Entity
from geobrep.model.entities.base import VertexEntity
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Topology

__all__ = [
    "SKIPPED_ON_READ",
    "capability_losses",
    "capability_table",
    "format_losses",
    "has_geometry",
    "read_losses",
    "restrict_scene",
    "without_read_losses",
]

SKIPPED_ON_READ = "skipped_on_read"
"""Scene metadata key: a reader's list of what the file held and it did not read."""


def has_geometry(entity: Entity) -> bool:
    """False for a vertex entity without vertices (a GOCAD header-only object)."""
    return not isinstance(entity, VertexEntity) or entity.n_points > 0


def read_losses(scene: Scene) -> list[str]:
    """What the reader of ``scene`` skipped, one sentence each (from its metadata)."""
    skipped = scene.metadata.get(SKIPPED_ON_READ)
    if not isinstance(skipped, list | tuple):
        return []
    return [f"skipped on read: {item}" for item in skipped]


def without_read_losses(scene: Scene) -> Scene:
    """``scene`` without the reader's skipped list (it describes the source, not the target)."""
    if SKIPPED_ON_READ not in scene.metadata:
        return scene
    metadata = {k: v for k, v in scene.metadata.items() if k != SKIPPED_ON_READ}
    return scene.model_copy(update={"metadata": metadata})


def capability_losses(scene: Scene, caps: FormatCapabilities) -> list[str]:
    """One sentence per kind of content ``caps`` cannot hold (empty: nothing is lost).

    What the reader skipped (:func:`read_losses`) comes first: it is lost too.
    """
    lost: list[str] = read_losses(scene)
    dropped = Counter(e.type for e in scene.entities if e.type not in caps.entity_types)
    held = ", ".join(sorted(caps.entity_types)) or "no entities"
    for type_name, count in sorted(dropped.items()):
        lost.append(f"{count} {type_name} entities dropped (format holds {held})")
    kept = [e for e in scene.entities if e.type in caps.entity_types]
    if not caps.empty_entities:
        empty = [e.label for e in kept if not has_geometry(e)]
        if empty:
            lost.append(f"{len(empty)} entities without geometry dropped: {', '.join(empty)}")
        kept = [e for e in kept if has_geometry(e)]
    if scene.patches and not caps.topology:
        lost.append(f"topology dropped ({len(scene.patches)} patches)")
    if scene.crs is not None and not caps.crs:
        lost.append(f"CRS {scene.crs.label} dropped")
    if len(kept) > 1 and not caps.multiple_entities and not all(e.type == "Well" for e in kept):
        # (wells are never merged: a format of one well writes the first and says so)
        lost.append(f"{len(kept)} entities merged into one")
    named = [e for e in kept if e.name]
    if named and not caps.names:
        lost.append(f"names of {len(named)} entities dropped")
    if kept and not caps.ids:
        lost.append(f"ids of {len(kept)} entities dropped")
    if scene.groups and not caps.names:
        lost.append(f"{len(scene.groups)} groups dropped")
    for field, able, noun in (
        ("point_data", caps.point_data, "point"),
        ("cell_data", caps.cell_data, "cell"),
    ):
        names = sorted({name for e in kept for name in getattr(e, field)})
        if names and not able:
            lost.append(f"{noun} properties dropped: {', '.join(names)}")
    patched = [e for e in kept if getattr(e, "patch_labels", None) is not None]
    if patched and not caps.cell_data:
        lost.append(f"patch labels of {len(patched)} surfaces dropped")
    return lost


def format_losses(scene: Scene, spec: FormatSpec, target: Path) -> list[str]:
    """Everything writing ``scene`` to ``target`` in format ``spec`` loses, one sentence each.

    :func:`capability_losses`, then what the format says it drops for this target
    (:attr:`~geobrep.host.registry.FormatSpec.losses`, e.g. the object type of a GOCAD extension).
    """
    lost = capability_losses(scene, spec.capabilities)
    if spec.losses is not None:
        lost.extend(spec.losses(restrict_scene(scene, spec.capabilities), target))
    return lost


def restrict_scene(scene: Scene, caps: FormatCapabilities) -> Scene:
    """``scene`` without what ``caps`` cannot hold (entities of other types, properties)."""
    kept = []
    for entity in scene.entities:
        if entity.type not in caps.entity_types:
            continue
        if not caps.empty_entities and not has_geometry(entity):
            continue
        changes: dict[str, Any] = {}
        if not caps.point_data and entity.point_data:
            changes["point_data"] = {}
        if not caps.cell_data and entity.cell_data:
            changes["cell_data"] = {}
        kept.append(entity.replace(**changes) if changes else entity)
    ids = {e.id for e in kept}
    groups = [_filter_group(g, ids) for g in scene.groups] if caps.names else []
    if caps.topology and len(kept) == len(scene.entities):
        return scene if caps.crs or scene.crs is None else scene.replace(crs=None)
    return Scene(
        entities=kept,
        groups=groups,
        topology=_kept_topology(scene, caps, ids),
        crs=scene.crs if caps.crs else None,
        name=scene.name,
        metadata=scene.metadata,
    )


def _kept_topology(scene: Scene, caps: FormatCapabilities, ids: set[int | None]) -> Topology:
    """The scene's topology when the format holds it and every surface and block it names is
    kept (a format of surfaces and blocks that drops tetrahedra keeps the blocks' sides)."""
    if not caps.topology:
        return Topology()
    named: set[int | None] = {p.surface for p in scene.topology.patches}
    named |= {b for p in scene.topology.patches for b in (p.positive_block, p.negative_block)}
    return scene.topology if (named - {None}) <= ids else Topology()


def _filter_group(group: Group, ids: set[int | None]) -> Group:
    return group.model_copy(
        update={
            "members": tuple(m for m in group.members if m in ids),
            "children": tuple(_filter_group(c, ids) for c in group.children),
        }
    )


_ENTITY_ABBREVIATIONS = {
    "PointSet": "points",
    "PolyLine": "lines",
    "Polygon": "polygons",
    "Surface": "surfaces",
    "TetMesh": "tets",
    "NurbsSurface": "NURBS",
    "Annotation": "annotations",
    "Block": "blocks",
    "LinearOctree": "octrees",
    "RegularGrid": "grids",
    "StructuredGrid": "sgrids",
    "Well": "wells",
}


def capability_table(formats: FormatRegistry) -> str:
    """The Markdown table of every registered format's capabilities (docs/formats.md).

    >>> from geobrep.host import registries
    >>> capability_table(registries().formats).splitlines()[0].startswith("| format |")
    True
    """
    flags = ("point_data", "cell_data", "names", "ids", "topology", "crs", "multiple_entities")
    header = (
        "| format | extensions | read | write | entities | point data | cell data | names "
        "| ids | topology | CRS | several entities | plugin |"
    )
    rows = [header, "|" + "---|" * 13]
    for spec in formats:
        caps = spec.capabilities
        kinds = ", ".join(_ENTITY_ABBREVIATIONS.get(t, t) for t in sorted(caps.entity_types))
        marks = " | ".join("yes" if getattr(caps, flag) else "-" for flag in flags)
        rows.append(
            f"| {spec.name} | {' '.join(spec.extensions)} | {'yes' if spec.can_read else '-'} "
            f"| {'yes' if spec.can_write else '-'} | {kinds or '-'} | {marks} | {spec.plugin} |"
        )
    return "\n".join(rows)
