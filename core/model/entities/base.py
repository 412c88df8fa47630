"""The base of every scene entity: identity, role, metadata and properties."""

from __future__ import annotations

from functools import cached_property
from typing import Any, ClassVar, Self

from pydantic import Field, JsonValue, PrivateAttr, ValidationError, model_validator

from geobrep.errors import EntityValidationError
from geobrep.geometry.bbox import BoundingBox
from geobrep.model.base import FrozenModel
from geobrep.model.properties import PropertyMap

__all__ = ["Entity", "VertexEntity", "describe_entity"]


def describe_entity(type_name: str, name: object = None, entity_id: object = None) -> str:
    """``"Surface 'top'"``, ``"Surface #3"`` or ``"Surface"``: how errors name an entity."""
    if isinstance(name, str) and name:
        return f"{type_name} {name!r}"
    if isinstance(entity_id, int):
        return f"{type_name} #{entity_id}"
    return type_name


def _field_path(loc: tuple[int | str, ...]) -> str:
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(entity)"


def translate_validation_error(label: str, exc: ValidationError) -> EntityValidationError:
    """Turn pydantic's error into geobrep's, naming the entity and the first bad field."""
    first = exc.errors()[0]
    original = (first.get("ctx") or {}).get("error")
    if isinstance(original, EntityValidationError):
        return original
    message = first["msg"].removeprefix("Value error, ")
    extra = f" (and {exc.error_count() - 1} more problem(s))" if exc.error_count() > 1 else ""
    return EntityValidationError(label, _field_path(tuple(first["loc"])), message + extra)


class Entity(FrozenModel):
    """Identity (``id``), ``name``, geological ``kind`` and free ``metadata`` of an entity.

    Entities are immutable: arrays are read-only and fields cannot be reassigned; derive a
    changed entity with :meth:`replace`.
    """

    type: str
    id: int | None = Field(default=None, ge=0)
    name: str = ""
    kind: str | None = None
    metadata: dict[str, JsonValue] = Field(default_factory=dict)
    point_data: PropertyMap = Field(default_factory=PropertyMap)
    cell_data: PropertyMap = Field(default_factory=PropertyMap)

    #: What one cell is for this entity type ("faces", "segments", ...), for messages.
    cell_noun: ClassVar[str] = "cells"

    #: True once the cross-field checks passed. pydantic runs "after" validators again when a
    #: validated instance goes into another model (a Scene): immutable, it needs no second look.
    _checked: bool = PrivateAttr(default=False)

    def __init__(self, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            label = describe_entity(type(self).__name__, data.get("name"), data.get("id"))
            raise translate_validation_error(label, exc) from exc
        self._checked = True

    @property
    def label(self) -> str:
        """How messages name this entity: ``"Surface 'top'"`` or ``"Surface #3"``."""
        return describe_entity(type(self).__name__, self.name, self.id)

    def fail(self, field: str, reason: str) -> EntityValidationError:
        """Build the error that names this entity and ``field``."""
        return EntityValidationError(self.label, field, reason)

    # -- sizes that properties must match; subclasses override -------------------------------
    @property
    def n_points(self) -> int:
        """Number of elements ``point_data`` arrays must have."""
        return 0

    @property
    def n_cells(self) -> int:
        """Number of elements ``cell_data`` arrays must have."""
        return 0

    def _check(self) -> None:
        """Cross-field checks of a subclass; raise :meth:`fail` errors."""

    def check_fields(self) -> None:
        """Run the cross-field checks validation runs (raising its
        :class:`~geobrep.errors.EntityValidationError`) and mark the entity checked: for an
        entity made with ``model_construct`` from fields that already have their validated
        form (read-only arrays of the field's dtype and shape, a PropertyMap, JSON metadata)."""
        if not getattr(self, "_checked", False):
            self._cross_checks()
        self._checked = True

    def _cross_checks(self) -> None:
        self._check()
        for field, props, count, noun in (
            ("point_data", self.point_data, self.n_points, "points"),
            ("cell_data", self.cell_data, self.n_cells, self.cell_noun),
        ):
            for name, prop in props.items():
                if len(prop) != count:
                    raise self.fail(
                        f"{field}[{name!r}]", f"has {len(prop)} values for {count} {noun}"
                    )

    @model_validator(mode="after")
    def _validate_entity(self) -> Self:
        if not getattr(self, "_checked", False):
            self._cross_checks()
        return self

    @property
    def bounds(self) -> BoundingBox | None:
        """Axis-aligned bounding box, or None for an entity without geometry."""
        return None

    def replace(self, **changes: Any) -> Self:
        """A validated copy with some fields changed.

        >>> from geobrep import PointSet
        >>> PointSet(vertices=[[0, 0, 0]], name="a").replace(name="b").name
        'b'
        """
        values = {name: getattr(self, name) for name in type(self).model_fields}
        values.update(changes)
        return type(self)(**values)


class VertexEntity(Entity):
    """An entity whose geometry starts with a ``vertices`` array; point data is per vertex."""

    @property
    def n_points(self) -> int:
        vertices = getattr(self, "vertices", None)
        return 0 if vertices is None else int(vertices.shape[0])

    @cached_property
    def bounds(self) -> BoundingBox | None:
        vertices = getattr(self, "vertices", None)
        if vertices is None or len(vertices) == 0:
            return None
        return BoundingBox.from_points(vertices)
