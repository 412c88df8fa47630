"""The Well clipper: the trajectory cut at the plane, with the measured depth of the cut.

A well is a path in measured depth (MD). Where its stations carry inclination and azimuth
(``INCL`` and ``AZIM_GN`` / ``AZIM_TN`` / ``AZIM`` station properties, as deviation tables give)
and the stations follow from them by the minimum-curvature method, the path between two stations
is that method's circular arc, and the plane is cut on the arc; elsewhere the path is the straight
segment between stations. The cut point's MD is the MD along that path, so it is exact for a
minimum-curvature survey.

A clipped well is one continuous stretch of hole: the MD interval of the kept side nearest the
head, from the cut point (a new station, its inclination and azimuth those of the arc there) to
the end of the kept side. Markers, zones (clipped to the interval) and log samples in that
interval are kept; head, datum and the MD values stay as they were. A trajectory that crosses the
plane several times keeps several intervals on one side: the shallowest is the clipped well, and
a :class:`WellClipWarning` names the others (all are in ``metadata["clip"]["md_intervals"]``).

The section of a well is where its path crosses the plane: a PointSet with the ``md`` of each
crossing. With the option ``within`` (a distance), it is instead "the well on the section": the
parts of the path within that distance of the plane, projected onto it, as a PolyLine with the
point properties ``md`` and ``offset`` (the signed distance from the plane before projecting)
and the markers on those parts, projected too, in ``metadata["markers"]``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from geobrep import PointSet, PolyLine, Property, Well, WellLog, WellZone
from geobrep.geometry import Plane
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.geometry.trajectory import StationPath, angles
from geobrep.plugins import ClipContext, Keep, PropertyMap, halves, pack_halves
from geobrep.plugins.clip._sides import interpolate_properties, vertex_sides
from geobrep.plugins.clip.options import WellClipOptions, tolerance_of

__all__ = ["Trajectory", "WellClipWarning", "clip_well", "section_well"]

_BISECTIONS = 64

Interval = tuple[float, float]


class WellClipWarning(UserWarning):
    """A clipped well kept only one of several MD intervals on its side of the plane."""


@dataclass(frozen=True)
class Trajectory:
    """A well's path as a function of MD (:attr:`geobrep.Well.path`), cut by planes."""

    path: StationPath
    angle_names: tuple[str, str] | None

    @classmethod
    def of(cls, well: Well) -> Trajectory:
        """The path of ``well`` (arcs where its station angles give its stations)."""
        return cls(well.path, well.angle_names)

    @property
    def md(self) -> FloatArray:
        return self.path.md

    @property
    def xyz(self) -> FloatArray:
        return self.path.xyz

    @property
    def arc(self) -> BoolArray:
        return self.path.arc

    def at(self, md: FloatArray) -> tuple[FloatArray, IntArray, FloatArray, FloatArray | None]:
        """Positions at ``md``, with each depth's interval, fraction of it and path direction."""
        return self.path.at(md)

    def crossings(self, plane: Plane, offset: float, tolerance: float) -> FloatArray:
        """MD of every strict crossing of the plane ``distance = offset`` between stations."""
        d = plane.signed_distance(self.xyz) - offset
        sides = vertex_sides(d, tolerance)
        k = np.flatnonzero(sides[:-1] * sides[1:] < 0)
        if k.shape[0] == 0:
            return np.zeros(0)
        low, high = np.zeros(k.shape[0]), np.ones(k.shape[0])
        linear = d[k] / (d[k] - d[k + 1])
        arcs = self.arc[k]
        if arcs.any():
            negative_first = d[k] < 0
            for _ in range(_BISECTIONS):
                middle = 0.5 * (low + high)
                points, _, _, _ = self.at(self.md[k] + middle * (self.md[k + 1] - self.md[k]))
                below = (plane.signed_distance(points) - offset < 0) == negative_first
                low, high = np.where(below, middle, low), np.where(below, high, middle)
        fraction = np.where(arcs, 0.5 * (low + high), linear)
        return np.asarray(self.md[k] + fraction * (self.md[k + 1] - self.md[k]))

    def kept(self, plane: Plane, offset: float, side: int, tolerance: float) -> list[Interval]:
        """MD intervals of the path on ``side`` of the plane ``distance = offset`` (or on it)."""
        breaks = np.unique(np.concatenate([self.md, self.crossings(plane, offset, tolerance)]))
        if breaks.shape[0] < 2:
            return []
        middle, _, _, _ = self.at(0.5 * (breaks[:-1] + breaks[1:]))
        sides = vertex_sides(plane.signed_distance(middle) - offset, tolerance)
        intervals: list[Interval] = []
        for index in np.flatnonzero(sides != -side).tolist():
            a, b = float(breaks[index]), float(breaks[index + 1])
            if intervals and intervals[-1][1] == a:
                intervals[-1] = (intervals[-1][0], b)
            else:
                intervals.append((a, b))
        return intervals


def _intersect(first: list[Interval], second: list[Interval]) -> list[Interval]:
    out: list[Interval] = []
    for a0, b0 in first:
        for a1, b1 in second:
            a, b = max(a0, a1), min(b0, b1)
            if a < b:
                out.append((a, b))
    return out


# ------------------------------------------------------------------------------- clip
def clip_well(
    well: Well, plane: Plane, keep: Keep, options: WellClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`Well` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    path = Trajectory.of(well)
    parts: dict[int, Well | None] = {}
    for side in halves(keep):
        intervals = path.kept(plane, 0.0, side, tolerance)
        if not intervals:
            parts[side] = None
        elif len(intervals) == 1 and intervals[0] == (float(path.md[0]), float(path.md[-1])):
            parts[side] = well
        else:
            parts[side] = _piece(well, path, intervals)
    return pack_halves(keep, parts)


def _piece(well: Well, path: Trajectory, intervals: list[Interval]) -> Well:
    a, b = intervals[0]
    inner = path.md[(path.md > a) & (path.md < b)]
    md = np.concatenate([[a], inner, [b]])
    xyz, k, fraction, direction = path.at(md)
    point_data = dict(interpolate_properties(well.point_data, np.zeros(0, np.int64), k, k + 1,
                                             fraction))  # fmt: skip
    if path.angle_names is not None and direction is not None:
        bent = path.arc[k]
        inc, azi = angles(direction)
        for name, values in zip(path.angle_names, (inc, azi), strict=True):
            prop = point_data[name]
            mixed = np.where(bent, values, prop.values).astype(prop.values.dtype)
            point_data[name] = prop.model_copy(update={"values": mixed})
    segment_of = np.searchsorted(well.md, 0.5 * (md[:-1] + md[1:]), side="right") - 1
    metadata = dict(well.metadata)
    if len(intervals) > 1:
        metadata["clip"] = {"md_intervals": [list(i) for i in intervals]}
        warnings.warn(
            f"{well.label}: the plane cuts the well into {len(intervals)} stretches on the kept "
            f"side; kept MD {a:g}..{b:g}, not "
            + ", ".join(f"{x:g}..{y:g}" for x, y in intervals[1:]),
            WellClipWarning,
            stacklevel=2,
        )
    return well.replace(
        vertices=xyz,
        md=md,
        point_data=PropertyMap(point_data),
        cell_data=well.cell_data.take(np.clip(segment_of, 0, max(well.n_cells - 1, 0)))
        if well.cell_data
        else PropertyMap(),
        markers=tuple(m for m in well.markers if a <= m.md <= b),
        zones=tuple(_clip_zones(well.zones, a, b)),
        logs={name: log for name, log in _clip_logs(well.logs, a, b)},
        metadata=metadata,
    )


def _clip_zones(zones: tuple[WellZone, ...], a: float, b: float) -> list[WellZone]:
    kept = []
    for zone in zones:
        top, base = max(zone.top_md, a), min(zone.base_md, b)
        if top < base or (top == base and zone.top_md == zone.base_md):
            kept.append(zone.model_copy(update={"top_md": top, "base_md": base}))
    return kept


def _clip_logs(logs: dict[str, WellLog], a: float, b: float) -> list[tuple[str, WellLog]]:
    kept = []
    for name, log in logs.items():
        inside = (log.md >= a) & (log.md <= b)
        if inside.any():
            kept.append((name, log.model_copy(update={"md": log.md[inside],
                                                      "values": log.values[inside]})))  # fmt: skip
    return kept


# ------------------------------------------------------------------------------- section
def section_well(
    well: Well, plane: Plane, options: WellClipOptions, context: ClipContext
) -> PointSet | PolyLine | None:
    """Where the well crosses the plane, or (option ``within``) the well on the section."""
    tolerance = tolerance_of(options, context)
    path = Trajectory.of(well)
    if options.within is not None:
        return _on_section(well, path, plane, float(options.within), tolerance)
    sides = vertex_sides(plane.signed_distance(path.xyz), tolerance)
    md = np.unique(np.concatenate([path.md[sides == 0], path.crossings(plane, 0.0, tolerance)]))
    if md.shape[0] == 0:
        return None
    points, _, _, _ = path.at(md)
    return PointSet(
        vertices=points,
        point_data={"md": Property(values=md, description="measured depth")},
        name=well.name,
        kind=well.kind,
        metadata={**well.metadata, "well": well.id},
    )


def _on_section(
    well: Well, path: Trajectory, plane: Plane, within: float, tolerance: float
) -> PolyLine | None:
    intervals = _intersect(
        path.kept(plane, within, -1, tolerance), path.kept(plane, -within, 1, tolerance)
    )
    if not intervals:
        return None
    parts, depths = [], []
    for a, b in intervals:
        md = np.concatenate([[a], path.md[(path.md > a) & (path.md < b)], [b]])
        points, _, _, _ = path.at(md)
        parts.append(points)
        depths.append(md)
    md = np.concatenate(depths)
    points = np.concatenate(parts)
    offset = plane.signed_distance(points)
    projected = points - offset[:, None] * plane.normal
    markers = []
    for marker in well.markers:
        if any(a <= marker.md <= b for a, b in intervals):
            where, _, _, _ = path.at(np.array([marker.md]))
            distance = float(plane.signed_distance(where)[0])
            markers.append(
                {
                    "name": marker.name,
                    "surface": marker.surface,
                    "md": marker.md,
                    "offset": distance,
                    "position": (where[0] - distance * plane.normal).tolist(),
                }
            )
    sizes = np.cumsum([0, *(p.shape[0] for p in parts)])
    return PolyLine(
        vertices=projected,
        indices=np.arange(points.shape[0], dtype=np.int64),
        part_offsets=sizes.astype(np.int64),
        closed=np.zeros(len(parts), dtype=bool),
        point_data={
            "md": Property(values=md, description="measured depth"),
            "offset": Property(values=offset, description="signed distance from the plane"),
        },
        name=well.name,
        kind=well.kind,
        metadata={**well.metadata, "well": well.id, "within": within, "markers": markers},
    )
