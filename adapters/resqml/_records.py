"""What RESQML objects cannot say of a geobrep scene, kept as JSON in their extra metadata.

Each representation carries a ``geobrep`` extra-metadata item with its entity's id, kind,
metadata, patch names and the exact dtype, unit, no-data value and description of each property;
the local CRS carries the scene's (name, metadata, groups, topology and the CRS fields RESQML has
no place for). A file without them (from another program) reads from its RESQML content alone.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import orjson
from numpy.typing import NDArray

from geobrep.model.crs import CRS
from geobrep.model.entities import Entity
from geobrep.model.properties import Property, PropertyMap
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Topology

__all__ = [
    "RECORD_KEY",
    "decode_record",
    "encode_record",
    "entity_record",
    "property_record",
    "restore_property",
    "scene_from_record",
    "scene_record",
]

RECORD_KEY = "geobrep"
"""The extra-metadata name of geobrep's records."""


def encode_record(record: dict[str, Any] | list[Any]) -> str:
    """``record`` as compact JSON text (floats written as their shortest exact repr)."""
    return orjson.dumps(record, option=orjson.OPT_SERIALIZE_NUMPY).decode()


def decode_record(extra: dict[str, Any] | None) -> dict[str, Any] | None:
    """The geobrep record in an object's extra metadata, or None (absent or not geobrep's)."""
    text = (extra or {}).get(RECORD_KEY)
    if not isinstance(text, str):
        return None
    try:
        record = orjson.loads(text)
    except orjson.JSONDecodeError:
        return None
    return record if isinstance(record, dict) else None


def property_record(prop: Property) -> dict[str, Any]:
    """What a RESQML property part does not hold exactly of ``prop``."""
    return {
        "dtype": prop.dtype.str,
        "unit": prop.unit,
        "no_data_value": prop.model_dump(mode="json", include={"no_data_value"})["no_data_value"],
        "description": prop.description,
        "metadata": prop.metadata,
    }


def restore_property(
    values: NDArray[Any], record: dict[str, Any] | None, unit: str | None
) -> Property:
    """A property from the values read and its record (None: from RESQML alone)."""
    if record is None:
        return Property(values=values, unit=unit)
    return Property.model_validate(
        {
            "values": np.asarray(values).astype(np.dtype(record["dtype"]), copy=False),
            "unit": record.get("unit"),
            "no_data_value": record.get("no_data_value"),
            "description": record.get("description", ""),
            "metadata": record.get("metadata", {}),
        }
    )


def entity_record(entity: Entity) -> dict[str, Any]:
    """Id, kind, metadata, patch names and property records of ``entity``."""
    record: dict[str, Any] = {
        "type": entity.type,
        "id": entity.id,
        "kind": entity.kind,
        "metadata": entity.metadata,
        "point_data": {n: property_record(p) for n, p in entity.point_data.items()},
        "cell_data": {n: property_record(p) for n, p in entity.cell_data.items()},
    }
    names = getattr(entity, "patch_names", ())
    if names:
        record["patch_names"] = list(names)
    return record


def scene_record(scene: Scene) -> dict[str, Any]:
    """The scene's name, metadata, groups, topology and CRS fields."""
    return {
        "name": scene.name,
        "metadata": scene.metadata,
        "groups": [g.model_dump(mode="json") for g in scene.groups],
        "topology": scene.topology.model_dump(mode="json"),
        "crs": None if scene.crs is None else scene.crs.model_dump(mode="json"),
        "order": [e.id for e in scene.entities],
    }


def scene_from_record(
    entities: list[Entity], record: dict[str, Any] | None, crs: CRS | None, name: str
) -> Scene:
    """The scene of ``entities`` with what ``record`` keeps (None: a foreign file)."""
    if record is None:
        return Scene(entities=entities, crs=crs, name=name)
    ids = {e.id for e in entities}
    order = {ident: at for at, ident in enumerate(record.get("order", []))}
    if ids <= set(order):  # the order of the scene written
        entities = sorted(entities, key=lambda e: order[e.id])
    groups = [Group.model_validate(g) for g in record.get("groups", [])]
    topology = Topology.model_validate(record.get("topology") or {})
    kept = [p for p in topology.patches if p.surface in ids]
    if len(kept) != len(topology.patches):  # surfaces missing from the file: no topology
        topology = Topology()
    return Scene(
        entities=entities,
        groups=[_members_in(g, ids) for g in groups],
        topology=topology,
        crs=CRS.model_validate(record["crs"]) if record.get("crs") else None,
        name=str(record.get("name", name)),
        metadata=record.get("metadata", {}),
    )


def _members_in(group: Group, ids: set[int | None]) -> Group:
    return group.model_copy(
        update={
            "members": tuple(m for m in group.members if m in ids),
            "children": tuple(_members_in(c, ids) for c in group.children),
        }
    )


def properties_from(
    found: dict[str, tuple[NDArray[Any], str | None]], records: dict[str, Any] | None
) -> PropertyMap:
    """The properties read (name -> values, RESQML unit) with their records applied."""
    records = records or {}
    return PropertyMap(
        {
            name: restore_property(values, records.get(name), unit)
            for name, (values, unit) in found.items()
        }
    )
