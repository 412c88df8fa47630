"""Conformity checks between surfaces: T-junctions and gaps along contacts (the builder's
machinery, at a tolerance following the data's precision by default)."""

from __future__ import annotations

from typing import Any

from geobrep import Scene
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.checks._intersections import contact_defects, contacts

__all__ = ["gaps", "t_junctions"]


def t_junctions(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """A vertex of one surface lying (within the tolerance) on another surface's face or edge
    that has no vertex there: the two do not share the contact's vertices."""
    if len(scene.surfaces) < 2:
        return []
    return contact_defects(scene, {"T-junction"}, contacts(scene, context))


def gaps(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """A free border vertex of one surface lying near (within the gap tolerance, beyond the
    tolerance) another surface: a surface stopping just short of the one it should meet."""
    if len(scene.surfaces) < 2:
        return []
    return contact_defects(scene, {"gap"}, contacts(scene, context, options))
