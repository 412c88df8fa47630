"""The ``skinning`` fitter: sections (PolyLine parts) or rows of points to an exact surface."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep import Entity, NurbsSurface, PointSet, PolyLine
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import IntArray
from geobrep.plugins import FitResult
from geobrep.plugins.fit._domain_map import check_fold_free
from geobrep.plugins.fit._frame import LocalFrame
from geobrep.plugins.fit._skinning import rows_from_lattice, skin_rows
from geobrep.plugins.fit.distance import surface_distances
from geobrep.plugins.fit.options import SkinningOptions
from geobrep.plugins.fit.report import accuracy_report

__all__ = ["fit_skinning", "sections_of"]

LABEL = "fitter 'skinning'"


def sections_of(
    entities: list[Entity], options: SkinningOptions
) -> tuple[NDArray[np.float64], list[IntArray], PointSet | None, bool]:
    """All points, the rows (index arrays into them), the first PointSet, and whether the rows
    were given explicitly (PolyLine parts or a row property)."""
    points: list[NDArray[np.float64]] = []
    rows: list[IntArray] = []
    pointset: PointSet | None = None
    explicit = True
    offset = 0
    for entity in entities:
        if isinstance(entity, PolyLine):
            for p in range(entity.n_parts):
                part = np.asarray(
                    entity.indices[entity.part_offsets[p] : entity.part_offsets[p + 1]]
                )
                rows.append(offset + np.arange(part.size, dtype=np.int64))
                points.append(np.asarray(entity.vertices)[part])
                offset += part.size
        elif isinstance(entity, PointSet):
            pointset = pointset or entity
            vertices = np.asarray(entity.vertices)
            points.append(vertices)
            if options.row_property is not None:
                if options.row_property not in entity.point_data:
                    raise OptionsError(
                        f"{LABEL}: option 'row_property': {entity.label} has no point property "
                        f"{options.row_property!r}"
                    )
                labels = np.asarray(entity.point_data[options.row_property].values)
                if labels.ndim != 1:
                    raise OptionsError(
                        f"{LABEL}: option 'row_property' must name a scalar property"
                    )
                for value in np.unique(labels):
                    rows.append(offset + np.flatnonzero(labels == value).astype(np.int64))
            else:
                explicit = False
            offset += vertices.shape[0]
        else:
            raise OptionsError(
                f"{LABEL}: cannot skin a {entity.label}; give a PointSet or PolyLine"
            )
    if not points:
        raise OptionsError(f"{LABEL}: no points given")
    return np.concatenate(points), rows, pointset, explicit


def fit_skinning(entities: list[Entity], options: SkinningOptions) -> FitResult:
    """Skin ordered sections: the surface passes through every point (A X = B of the paper)."""
    points, rows, pointset, explicit = sections_of(entities, options)
    frame = LocalFrame.from_points(points, LABEL)
    local = frame.to_local(points)
    if explicit:
        # order points within property rows along the row, and rows across them
        if options.row_property is not None:
            rows = [r[np.argsort(local[r, 0], kind="stable")] for r in rows]
            rows.sort(key=lambda r: float(local[r, 1].mean()))
        # sections traced in alternating directions would twist the surface: align them
        reference = local[rows[0][-1]] - local[rows[0][0]]
        rows = [
            r if float((local[r[-1]] - local[r[0]]) @ reference) >= 0 else r[::-1] for r in rows
        ]
    else:
        rows, angle = rows_from_lattice(local[:, :2], LABEL)
        frame = frame.rotated(angle)
        local = frame.to_local(points)
    skinned = skin_rows([local[r] for r in rows], options.degree_u, options.degree_v, LABEL)
    order = np.concatenate(rows)
    if np.unique(order).size != order.size or order.size != points.shape[0]:
        raise DegenerateGeometryError(f"{LABEL}: a point belongs to no row or to several rows")
    net = skinned.net.control_points
    world = frame.to_world(net.reshape(-1, 3)).reshape(net.shape)
    surface = NurbsSurface(
        degree_u=skinned.net.degree_u,
        degree_v=skinned.net.degree_v,
        knots_u=skinned.net.knots_u,
        knots_v=skinned.net.knots_v,
        control_points=world,
        weights=np.ones(net.shape[:2]),
        name="skinning",
        kind=pointset.kind if pointset is not None else None,
    )
    u_rows, v_rows = skinned.point_parameters()
    u = np.empty(points.shape[0])
    v = np.empty(points.shape[0])
    u[order], v[order] = u_rows, v_rows
    distances = surface_distances(surface, points, u, v)
    notes = []
    try:
        check_fold_free(skinned.net, LABEL)
    except DegenerateGeometryError:
        notes.append(
            "the skinned surface folds over in plan somewhere (sections of very different "
            "extent or uneven spacing); it still passes through every point"
        )
    report = accuracy_report(
        distances,
        points,
        epsilon=options.epsilon,
        method="skinning",
        notes=notes,
        details={
            "control_points": [int(net.shape[0]), int(net.shape[1])],
            "sections": len(rows),
            "points_per_section": [int(r.size) for r in rows],
        },
    )
    return FitResult(
        surface=surface,
        report=report,
        distances=distances,
        method="skinning",
        points=points,
    )
