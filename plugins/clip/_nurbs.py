"""The NurbsSurface clipper: exact trimming by half-spaces, decided through the tessellation.

A cut NurbsSurface keeps its control net, knots and weights (so it stays exact) and records the
half-spaces it was clipped to in ``metadata["clip_planes"]``: a list of ``[a, b, c, d]``, each
keeping the part where ``a·x + b·y + c·z + d ≤ 0``. Whether anything is left on a side is decided
on the tessellation (``samples`` per parameter direction) unless the control net, which holds the
surface, lies on one side. :func:`trimmed_mesh` gives the triangles of the trimmed surface.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geobrep import NurbsSurface, Surface
from geobrep.geometry import Plane
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._sides import vertex_sides
from geobrep.plugins.clip._surfaces import clip_surface
from geobrep.plugins.clip.options import NurbsClipOptions, SurfaceClipOptions, tolerance_of

__all__ = ["clip_nurbs", "trimmed_mesh"]


def _stored_planes(surface: NurbsSurface) -> list[Plane]:
    stored = surface.metadata.get("clip_planes")
    if not isinstance(stored, list):
        return []
    return [Plane(*np.asarray(plane, dtype=np.float64).tolist()) for plane in stored]


def trimmed_mesh(
    surface: NurbsSurface, samples: int = 65, tolerance: float | None = None
) -> Surface | None:
    """The tessellation of ``surface`` cut to its ``clip_planes`` (``None`` if nothing is left)."""
    mesh: Surface | None = surface.tessellate(resolution=samples)
    options = SurfaceClipOptions(caps="never", tolerance=tolerance)
    bounds = surface.bounds
    context = ClipContext(tolerance=0.0 if bounds is None else 1e-9 * bounds.diagonal)
    for plane in _stored_planes(surface):
        if mesh is None:
            return None
        mesh = clip_surface(mesh, plane, "negative", options, context)
    return mesh


def clip_nurbs(
    surface: NurbsSurface,
    plane: Plane,
    keep: Keep,
    options: NurbsClipOptions,
    context: ClipContext,
) -> Any:
    """Clipper of :class:`NurbsSurface` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    net = np.asarray(surface.control_points, dtype=np.float64).reshape(-1, 3)
    net_sides = vertex_sides(plane.signed_distance(net), tolerance)
    parts: dict[int, NurbsSurface | None] = {}
    mesh: Surface | None = None
    for side in halves(keep):
        if not (net_sides == -side).any():
            parts[side] = surface
            continue
        if not (net_sides == side).any() and not (net_sides == 0).any():
            parts[side] = None
            continue
        if mesh is None:
            mesh = trimmed_mesh(surface, options.samples, tolerance)
        if mesh is None:
            parts[side] = None
            continue
        half = plane if side < 0 else plane.flipped()
        kept = clip_surface(
            mesh, half, "negative", SurfaceClipOptions(caps="never", tolerance=tolerance), context
        )
        if kept is None:
            parts[side] = None
            continue
        planes = [p.coefficients.tolist() for p in (*_stored_planes(surface), half)]
        parts[side] = surface.replace(metadata={**surface.metadata, "clip_planes": planes})
    return pack_halves(keep, parts)
