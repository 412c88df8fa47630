"""``geobrep info FILE``: what a file holds — entities, counts, bounds, CRS, properties."""

from __future__ import annotations

import argparse
import json
import re
from typing import Any

from geobrep.cli.common import add_allow_empty, format_name, is_empty, refuse_empty
from geobrep.errors import GeobrepError
from geobrep.model.crs import CRS
from geobrep.model.entities import Block, Entity, PointSet, PolyLine, Surface
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Group, Scene
from geobrep.ops.io import read

__all__ = ["add_parser", "describe_entity", "describe_scene"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser("info", description="Describe the entities of a file.")
    parser.add_argument("file", help="file to describe (any readable format)")
    parser.add_argument(
        "--format", type=format_name("read"), help="format name, when the extension is not enough"
    )
    parser.add_argument("--json", action="store_true", help="print JSON for machines")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def _properties(props: PropertyMap) -> list[dict[str, Any]]:
    return [
        {
            "name": name,
            "dtype": str(prop.dtype),
            "element_size": prop.element_size,
            "unit": prop.unit,
            "no_data_value": prop.no_data_value,
        }
        for name, prop in props.items()
    ]


#: The entity types a surface file holds, whose modules come with :mod:`geobrep.model.entities`:
#: the others' modules are imported for an entity of none of these (its own was, to make it).
_SURFACE_FILE_TYPES = (Surface, PolyLine, PointSet, Block)


def _counts(entity: Entity) -> dict[str, int]:
    counts: dict[str, int] = {}
    if hasattr(entity, "vertices"):
        counts["vertices"] = int(entity.vertices.shape[0])
    if isinstance(entity, Surface):
        counts["faces"] = entity.n_faces
        counts["patches"] = entity.n_patches
    elif isinstance(entity, PolyLine):
        counts["parts"] = entity.n_parts
        counts["segments"] = entity.n_cells
    elif isinstance(entity, Block):
        counts["sides"] = len(entity.sides)
    elif not isinstance(entity, PointSet):
        counts.update(_other_counts(entity))
    return counts


def _other_counts(entity: Entity) -> dict[str, int]:
    """The counts of an entity of none of :data:`_SURFACE_FILE_TYPES`."""
    from geobrep.model.entities.nurbs import NurbsSurface
    from geobrep.model.entities.octree import LinearOctree
    from geobrep.model.entities.polygon import Polygon
    from geobrep.model.entities.tetmesh import TetMesh

    if isinstance(entity, TetMesh):
        return {"tetrahedra": entity.n_cells, "regions": entity.n_regions}
    if isinstance(entity, Polygon):
        return {"polygons": entity.n_polygons, "rings": entity.n_rings}
    if isinstance(entity, NurbsSurface):
        return {"control_points": entity.n_points}
    if isinstance(entity, LinearOctree):
        return {"leaves": entity.n_leaves}
    return _grid_counts(entity)


def _grid_counts(entity: Entity) -> dict[str, int]:
    """Cells, points and well contents of the grid and well entities."""
    from geobrep.model.entities.grid import RegularGrid
    from geobrep.model.entities.structured import StructuredGrid
    from geobrep.model.entities.well import Well

    if isinstance(entity, RegularGrid | StructuredGrid):
        ni, nj, nk = entity.counts
        counts = {"ni": ni, "nj": nj, "nk": nk, "cells": entity.n_cells}
        if isinstance(entity, RegularGrid):
            counts["points"] = entity.n_points
        else:
            counts["active_cells"] = entity.n_active
        return counts
    if isinstance(entity, Well):
        return {
            "segments": entity.n_cells,
            "markers": len(entity.markers),
            "zones": len(entity.zones),
            "logs": len(entity.logs),
        }
    return {}


def _details(entity: Entity) -> dict[str, Any] | None:
    """What a user checks of a grid (its lattice) or a well (its depths and picks)."""
    if isinstance(entity, _SURFACE_FILE_TYPES):
        return None
    from geobrep.model.entities.grid import RegularGrid
    from geobrep.model.entities.structured import StructuredGrid
    from geobrep.model.entities.well import Well

    if isinstance(entity, RegularGrid):
        return {
            "origin": entity.origin.tolist(),
            "axes": entity.axes.tolist(),
            "cell_size": [float(v) for v in (entity.axes**2).sum(axis=1) ** 0.5],
        }
    if isinstance(entity, StructuredGrid):
        return {"geometry": "corner-point" if entity.is_corner_point else "points"}
    if isinstance(entity, Well):
        md = entity.md.tolist()
        return {
            "head": entity.head.tolist(),
            "md": [md[0], md[-1]] if md else [],
            "datum": entity.datum,
            "datum_elevation": entity.datum_elevation,
            "markers": [{"name": m.name, "md": m.md, "surface": m.surface} for m in entity.markers],
            "zones": [
                {"name": z.name, "top_md": z.top_md, "base_md": z.base_md} for z in entity.zones
            ],
            "logs": list(entity.logs),
        }
    return None


def describe_entity(entity: Entity) -> dict[str, Any]:
    """A JSON-ready summary of one entity (grids and wells add ``details``)."""
    bounds = entity.bounds
    summary = {
        "id": entity.id,
        "type": type(entity).__name__,
        "name": entity.name,
        "kind": entity.kind,
        "counts": _counts(entity),
        "bounds": list(bounds.as_tuple()) if bounds is not None else None,
        "point_data": _properties(entity.point_data),
        "cell_data": _properties(entity.cell_data),
    }
    details = _details(entity)
    if details is not None:
        summary["details"] = details
    return summary


#: Markers listed one a line by the text form of ``info`` (the JSON form has them all).
MARKER_LINES = 10


def _detail_lines(details: dict[str, Any]) -> list[str]:
    if "cell_size" in details:
        size = " × ".join(f"{v:g}" for v in details["cell_size"])
        origin = ", ".join(f"{v:.3f}" for v in details["origin"])
        return [f"      lattice origin ({origin}), cells {size}"]
    if "geometry" in details:
        return [f"      geometry {details['geometry']}"]
    if "md" not in details or not details["md"]:
        return []
    datum = details["datum"] or "-"
    if details["datum_elevation"] is not None:
        datum += f" at {details['datum_elevation']:g}"
    head = ", ".join(f"{v:.3f}" for v in details["head"])
    lines = [f"      MD {details['md'][0]:g} .. {details['md'][1]:g} from ({head}), datum {datum}"]
    markers = details["markers"]
    for marker in markers[:MARKER_LINES]:
        hits = f" -> {marker['surface']}" if marker["surface"] else ""
        lines.append(f"      marker {marker['name']!r} at MD {marker['md']:g}{hits}")
    if len(markers) > MARKER_LINES:
        lines.append(f"      ... {len(markers) - MARKER_LINES} more markers (--json lists them)")
    for zone in details["zones"]:
        lines.append(f"      zone {zone['name']!r} MD {zone['top_md']:g} .. {zone['base_md']:g}")
    if details["logs"]:
        lines.append(f"      logs {', '.join(details['logs'])}")
    return lines


#: CRS names GOCAD and SKUA give a model built in local coordinates (``Default``, ``SKUA Local``,
#: ``gocad Local``, ...): no projection, no datum.
_LOCAL_NAME = re.compile(r"\s*(default|.*\blocal)\s*", re.IGNORECASE)


def local_crs(crs: CRS) -> bool:
    """True for a local engineering CRS: only a name such as ``Default`` or ``SKUA Local``.

    A GOCAD header with ``PROJECTION Unknown`` and ``DATUM Unknown`` says the same of any name.

    >>> local_crs(CRS(name="SKUA Local")), local_crs(CRS(epsg=32631))
    (True, False)
    """
    if crs.epsg is not None or crs.wkt or crs.proj:
        return False
    gocad = crs.metadata.get("gocad")
    unknown = isinstance(gocad, dict) and all(
        str(gocad.get(key, "Unknown")).strip().lower() in ("unknown", "none", "")
        for key in ("projection", "datum")
    )
    return bool(unknown or (crs.name and _LOCAL_NAME.fullmatch(crs.name)))


def _parsed_crs(scene: Scene) -> dict[str, Any] | None:
    """What pyproj reads in the scene's CRS (name, units, vertical datum), when it is there.

    A local engineering CRS (GOCAD's ``Default``, ``SKUA Local``) that pyproj cannot read is
    described as such (``"local": True``), not as a failure.
    """
    crs = scene.crs
    if crs is None:
        return None
    if not (crs.epsg or crs.wkt or crs.proj) and _LOCAL_NAME.fullmatch(crs.name or ""):
        return _local(crs)  # only a local name, which no PROJ CRS has: no need of pyproj
    try:
        from geobrep.gis.crs_ops import describe_crs
    except ImportError:  # pragma: no cover - crs_ops itself is always importable
        return None
    try:
        return describe_crs(crs)
    except ImportError:  # pyproj (the gis extra) is not installed
        return None
    except GeobrepError as exc:
        return _local(crs) if local_crs(crs) else {"error": str(exc)}


def _local(crs: CRS) -> dict[str, Any]:
    return {
        "name": crs.name,
        "type": "local engineering CRS",
        "local": True,
        "units": list(crs.axis_units),
    }


def describe_scene(scene: Scene) -> dict[str, Any]:
    """A JSON-ready summary of a scene."""
    bounds = scene.bounds
    return {
        "name": scene.name,
        "crs": scene.crs.model_dump(mode="json") if scene.crs else None,
        "crs_parsed": _parsed_crs(scene),
        "bounds": list(bounds.as_tuple()) if bounds is not None else None,
        "entities": [describe_entity(e) for e in scene.entities],
        "topology": {
            "corners": len(scene.topology.corners),
            "arcs": len(scene.topology.arcs),
            "patches": len(scene.topology.patches),
            "blocks": len(scene.blocks),
            "universe": scene.universe is not None,
        },
        "groups": [g.name for g in scene.groups],
        "stratigraphic_columns": [_column(c) for c in scene.stratigraphic_columns],
    }


def _column(column: Group) -> dict[str, Any]:
    """A stratigraphic column's horizons and units, top down."""
    parts = {c.kind: [g.name for g in c.children] for c in column.children}
    return {
        "name": column.name,
        "horizons": parts.get("horizons", []),
        "units": parts.get("stratigraphic_units", []),
    }


def _format_bounds(bounds: list[float] | None) -> str:
    if bounds is None:
        return "-"
    xmin, xmax, ymin, ymax, zmin, zmax = bounds
    return f"x [{xmin:.3f}, {xmax:.3f}]  y [{ymin:.3f}, {ymax:.3f}]  z [{zmin:.3f}, {zmax:.3f}]"


def render_text(summary: dict[str, Any], source: str) -> str:
    """Human-readable form of :func:`describe_scene`."""
    crs = summary["crs"]
    crs_text = "none"
    if crs:
        label = f"EPSG:{crs['epsg']}" if crs.get("epsg") else (crs.get("name") or "unnamed")
        crs_text = (
            f"{label} (axes {' '.join(crs['axis_names'])}, units {' '.join(crs['axis_units'])}, "
            f"z positive {crs['z_positive']} in the source)"
        )
    lines = [
        f"{source}: {len(summary['entities'])} entities",
        f"  CRS     {crs_text}",
        *_parsed_crs_lines(summary.get("crs_parsed")),
        f"  bounds  {_format_bounds(summary['bounds'])}",
    ]
    topo = summary["topology"]
    if topo["patches"] or topo["blocks"]:
        lines.append(
            f"  topology  {topo['corners']} corners, {topo['arcs']} arcs, "
            f"{topo['patches']} patches, {topo['blocks']} blocks"
            + (" + universe" if topo["universe"] else "")
        )
    for column in summary.get("stratigraphic_columns", []):
        horizons, units = column["horizons"], column["units"]
        lines.append(
            f"  stratigraphic column {column['name']!r}: {len(horizons)} horizons, "
            f"{len(units)} units (top down)"
        )
        lines.append(f"      horizons {', '.join(horizons) or '-'}")
        lines.append(f"      units    {', '.join(units) or '-'}")
    for entity in summary["entities"]:
        counts = ", ".join(f"{v} {k}" for k, v in entity["counts"].items())
        kind = f" [{entity['kind']}]" if entity["kind"] else ""
        lines.append(f"  #{entity['id']} {entity['type']} {entity['name']!r}{kind}: {counts}")
        lines.extend(_detail_lines(entity.get("details") or {}))
        for where in ("point_data", "cell_data"):
            for prop in entity[where]:
                unit = f" {prop['unit']}" if prop["unit"] else ""
                size = f"×{prop['element_size']}" if prop["element_size"] > 1 else ""
                lines.append(f"      {where} {prop['name']!r}: {prop['dtype']}{size}{unit}")
    return "\n".join(lines)


def _parsed_crs_lines(parsed: dict[str, Any] | None) -> list[str]:
    if not parsed:
        return []
    if "error" in parsed:
        return [f"          not understood by pyproj: {parsed['error']}"]
    if parsed.get("local"):
        name = str(parsed["name"]).strip()
        return [f"          local (engineering) CRS {name!r}, not georeferenced"]
    datum = parsed.get("vertical_datum") or "none given"
    return [
        f"          {parsed['name']} ({parsed['type']}; units {', '.join(parsed['units'])}; "
        f"vertical units {parsed['vertical_units']}; vertical datum {datum})"
    ]


def run(args: argparse.Namespace) -> int:
    scene = read(args.file, format=args.format)
    summary = describe_scene(scene)
    if args.json:
        print(json.dumps({"file": args.file, **summary}, indent=2))
    else:
        print(render_text(summary, args.file))
    if is_empty(scene):
        count = len(scene.entities)
        what = f"{count} entities, none with geometry" if count else "no entities"
        refuse_empty(args, [f"{args.file}: nothing read ({what})"])
    return 0
