"""Model3d (.ml) semantics: TFACE identity by key triangle, REGION signs, LAYER/FAULT_BLOCK.

* The i-th header ``TFACE k <type> <tsurf>`` is the i-th TFACE part of the TSurf called
  ``<tsurf>``; its three coordinate lines are a **key triangle**: one triangle of that part in
  the same vertex order (often not the first triangle).
* ``REGION`` lists signed TFACE ids: ``+k`` means the region lies on the side the normal of
  TFACE k's key triangle points to, in z-up coordinates (after ``ZPOSITIVE Depth`` is negated).
  ``+k ... -k`` in one region is a surface inside it; the ``Universe`` region is the outside.
* Corners and arcs are rebuilt from the patches (:mod:`geobrep.model.arcs`), with the BSTONE
  vertices as extra corners; coincident vertices of different TSurfs are joined with a tolerance.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad.objects import gocad_section
from geobrep.adapters.gocad.parser import GocadObject
from geobrep.geometry.bbox import column_extremes
from geobrep.model.arcs import corners_and_arcs
from geobrep.model.entities import UNIVERSE_KIND, Block, Entity, PatchSide, Surface
from geobrep.model.orientation import orient_patches
from geobrep.model.scene import Group
from geobrep.model.topology import Patch, Topology

__all__ = ["attach_model3d", "border_topology", "find_key_triangle"]

_LIST_KINDS = {
    "LAYER": "layer",
    "FAULT_BLOCK": "fault_block",
    "SURFACE": "feature",
    "FAULT": "fault",
    "BOUNDARY": "boundary",
    "UNIT": "unit",
}


def find_key_triangle(
    surface: Surface, label: int, key: NDArray[np.float64], tolerance: float
) -> tuple[int | None, bool]:
    """``(face index, reversed)`` of the triangle of patch ``label`` matching ``key`` (3, 3).

    A match keeps the vertex order up to a cyclic rotation; ``reversed`` is true when only the
    opposite order matches. ``(None, False)`` when no triangle matches.
    """
    faces = surface.patch_faces(label)
    if faces.size == 0:
        return None, False
    corners = surface.vertices[surface.faces[faces][:, :3]]  # (m, 3, 3)
    for reverse in (False, True):
        target = key[::-1] if reverse else key
        for shift in range(3):
            rolled = np.roll(target, shift, axis=0)
            close = (np.abs(corners - rolled[None]) <= tolerance).all(axis=(1, 2))
            hit = np.flatnonzero(close)
            if hit.size:
                return int(faces[hit[0]]), reverse
    return None, False


def _tsurf_names(surface: Surface) -> list[str]:
    names = [surface.name]
    for key, value in gocad_section(surface.metadata).get("header", []):
        if key == "name_in_model_list":
            names.insert(0, str(value))
    return names


def attach_model3d(
    model: GocadObject,
    surfaces: list[Surface],
    first_id: int,
    z_sign: float,
    options: Any,
    builder: Any,
) -> tuple[Topology, list[Entity], list[Group], dict[str, Any], list[Surface]]:
    """Topology, blocks, groups, scene metadata and the member surfaces of a Model3d header.

    With ``options.repair`` (the default) each TFACE's triangles are turned to agree with its
    key triangle, so the surfaces returned may differ from those given.
    """
    by_name: dict[str, Surface] = {}
    listed: set[str] = set()  # names given by name_in_model_list
    for surface in surfaces:
        names = _tsurf_names(surface)
        if len(names) > 1:
            listed.add(names[0])
        for name in names:
            by_name.setdefault(name, surface)
    points = [s.vertices for s in surfaces if s.n_vertices]
    if points:
        stacked = np.concatenate(points)
        low, high = column_extremes(stacked)
        diagonal = float(np.linalg.norm(high - low))
    else:
        diagonal = 1.0
    key_tolerance = 1e-9 * max(diagonal, 1.0)
    patches: list[Patch] = []
    flipped: dict[int, bool] = {}
    seen_parts: dict[str, int] = {}
    key_faces: dict[int, dict[int, int | None]] = {}  # surface id -> patch label -> key face
    declared = set(model.model.get("tsurfs", []))
    for entry in model.model.get("tfaces", []):
        if entry["tsurf"] not in declared:
            builder.warn(
                f"TFACE {entry['id']} names {entry['tsurf']!r}, which has no TSURF line",
                entry["line"],
            )
            declared.add(entry["tsurf"])
        found = by_name.get(entry["tsurf"])
        if found is None:
            raise builder.error(
                f"TFACE {entry['id']} names TSurf {entry['tsurf']!r}, which is not in the file",
                entry["line"],
            )
        surface = found
        if entry["tsurf"] not in listed:
            builder.warn(
                f"TSurf {entry['tsurf']!r} has no name_in_model_list: matched by its name",
                entry["line"],
            )
            listed.add(entry["tsurf"])
        label = seen_parts.get(entry["tsurf"], 0)
        seen_parts[entry["tsurf"]] = label + 1
        if label >= surface.n_patches:
            raise builder.error(
                f"TFACE {entry['id']} is part {label + 1} of TSurf {entry['tsurf']!r}, "
                f"which has {surface.n_patches} TFACE part(s)",
                entry["line"],
            )
        key = np.asarray(entry["key"], dtype=np.float64)
        key[:, 2] *= z_sign
        face, reverse = find_key_triangle(surface, label, key, key_tolerance)
        if face is None:
            builder.warn(
                f"the key triangle of TFACE {entry['id']} is not a triangle of part {label + 1} "
                f"of {entry['tsurf']!r}; its REGION signs are taken as they are",
                entry["line"],
            )
        flipped[entry["id"]] = reverse
        key_faces.setdefault(int(surface.id or 0), {})[label] = face
        gocad: dict[str, Any] = {"geological_type": entry["type"], "key_triangle": face}
        if reverse:
            gocad["key_reversed"] = True
        patches.append(
            Patch(
                id=entry["id"],
                surface=int(surface.id or 0),
                label=label,
                name=f"{entry['tsurf']}:{label}",
                metadata={"gocad": gocad},
            )
        )
    if getattr(options, "repair", True):
        surfaces = _orient_by_key_triangles(surfaces, key_faces, patches, builder)
    patch_ids = {p.id for p in patches}
    blocks: list[Entity] = []
    region_block: dict[int, int] = {}
    lists = model.model.get("lists", [])
    layer_of: dict[int, str] = {}
    for keyword, entry in lists:
        if keyword == "LAYER":
            for region in entry["items"]:
                layer_of.setdefault(region, entry["name"])
    n_tfaces = len(patches)
    for keyword, entry in lists:
        if keyword != "REGION":
            continue
        if entry["id"] <= n_tfaces or entry["id"] in region_block:
            builder.warn(
                f"REGION id {entry['id']} should follow the TFACE ids and be unique; "
                "it is renumbered when written",
                entry["line"],
            )
        sides: list[PatchSide] = []
        for value in entry["items"]:
            tface = abs(value)
            if tface not in patch_ids:
                raise builder.error(
                    f"REGION {entry['name']!r} refers to TFACE {tface}, which is not defined",
                    entry["line"],
                )
            side = 1 if value > 0 else -1
            if flipped.get(tface):
                side = -side
            pair = PatchSide(tface, side)  # type: ignore[arg-type]
            if pair in sides:
                builder.warn(f"REGION {entry['name']!r} lists {value:+d} twice", entry["line"])
                continue
            sides.append(pair)
        block_id = first_id + len(blocks)
        region_block[entry["id"]] = block_id
        universe = entry["name"].strip().lower() == "universe"
        blocks.append(
            Block(
                id=block_id,
                name=entry["name"],
                kind=UNIVERSE_KIND if universe else "unit",
                sides=tuple(sides),
                unit_name=None if universe else layer_of.get(entry["id"]),
                metadata={"gocad": {"region_id": entry["id"]}},
            )
        )
    positive: dict[int, int] = {}
    negative: dict[int, int] = {}
    for block in blocks:
        assert isinstance(block, Block)
        for patch_id, side in block.sides:
            (positive if side == 1 else negative).setdefault(patch_id, int(block.id or 0))
    patches = [
        p.model_copy(
            update={"positive_block": positive.get(p.id), "negative_block": negative.get(p.id)}
        )
        for p in patches
    ]
    groups = _groups(lists, region_block, patches, builder)
    bstones = _bstone_points(surfaces)
    corners, arcs, patch_arcs = corners_and_arcs(
        {int(s.id or 0): s for s in surfaces},
        patches,
        options.merge_tolerance_for(diagonal),
        bstones,
    )
    warn_idle_bstones(surfaces, corners, options.merge_tolerance_for(diagonal), builder.warn)
    topology = Topology(
        corners=tuple(corners),
        arcs=tuple(arcs),
        patches=tuple(
            p.model_copy(update={"arcs": tuple(patch_arcs.get(p.id, ()))}) for p in patches
        ),
    )
    metadata: dict[str, Any] = {
        "gocad": {
            "model3d": {
                "version": model.version,
                "header": [[k, v] for k, v in model.header],
                "tsurfs": model.model.get("tsurfs", []),
            }
        }
    }
    if model.extra_lines:
        metadata["gocad"]["model3d"]["extra_lines"] = model.extra_lines
    return topology, blocks, groups, metadata, surfaces


def _orient_by_key_triangles(
    surfaces: list[Surface],
    key_faces: dict[int, dict[int, int | None]],
    patches: list[Patch],
    builder: Any,
) -> list[Surface]:
    """Each TFACE's triangles turned to agree with its key triangle (one warning per surface)."""
    tface_of = {(p.surface, p.label): p.id for p in patches}
    out: list[Surface] = []
    for surface in surfaces:
        sid = int(surface.id or 0)
        oriented, flips = orient_patches(surface, key_faces.get(sid, {}))
        if flips:
            total = sum(flips.values())
            where = ", ".join(
                f"TFACE {tface_of.get((sid, label), label + 1)}: {count}"
                for label, count in sorted(flips.items())
            )
            builder.warn(
                f"surface {surface.name!r}: {total} triangle(s) flipped to agree with the key "
                f"triangle of their TFACE ({where}); read with repair=False to keep them as written"
            )
        out.append(oriented)
    return out


def _groups(
    lists: list[tuple[str, dict[str, Any]]],
    region_block: dict[int, int],
    patches: list[Patch],
    builder: Any,
) -> list[Group]:
    surface_of_tface = {p.id: p.surface for p in patches}
    groups: list[Group] = []
    for keyword, entry in lists:
        if keyword == "REGION":
            continue
        items = entry["items"]
        if keyword in ("LAYER", "FAULT_BLOCK"):
            unknown = [i for i in items if i not in region_block]
            if unknown:
                builder.warn(
                    f"{keyword} {entry['name']!r}: id {unknown[0]} does not match a REGION",
                    entry["line"],
                )
            members = [region_block[i] for i in items if i in region_block]
            # "unmatched": ids the file itself lists without a REGION (kept when written)
            raw = {"keyword": keyword, "regions": items, "unmatched": unknown}
        else:
            members = list(
                dict.fromkeys(surface_of_tface[i] for i in items if i in surface_of_tface)
            )
            raw = {"keyword": keyword, "tfaces": items}
        groups.append(
            Group(
                name=entry["name"],
                kind=_LIST_KINDS[keyword],
                members=tuple(dict.fromkeys(members)),
                metadata={"gocad": raw},
            )
        )
    return groups


def _bstone_points(surfaces: list[Surface]) -> NDArray[np.float64]:
    points = []
    for surface in surfaces:
        gocad = gocad_section(surface.metadata)
        if gocad.get("bstones"):
            points.append(surface.vertices[np.asarray(gocad["bstones"], dtype=np.int64)])
    return np.concatenate(points) if points else np.zeros((0, 3))


def warn_idle_bstones(
    surfaces: list[Surface], corners: list[Any], tolerance: float, warn: Any
) -> None:
    """One warning per surface whose BSTONEs mark no corner (not on a border of the model):
    a writer then puts its BSTONEs at the corners, so they need not come back as they were."""
    if not corners:
        points = np.zeros((0, 3))
    else:
        points = np.array([c.point for c in corners], dtype=np.float64).reshape(-1, 3)
    for surface in surfaces:
        stones = gocad_section(surface.metadata).get("bstones") or []
        if not stones:
            continue
        at = surface.vertices[np.asarray(stones, dtype=np.int64)]
        if points.shape[0]:
            gaps = np.abs(at[:, None, :] - points[None, :, :]).max(axis=2).min(axis=1)
            idle = [int(v) for v, gap in zip(stones, gaps, strict=True) if gap > tolerance]
        else:
            idle = [int(v) for v in stones]
        if idle:
            warn(
                f"surface {surface.name!r}: {len(idle)} BSTONE(s) not on a border of the model "
                f"(vertex index {idle[0]}{', ...' if len(idle) > 1 else ''}) mark no corner"
            )


def border_topology(surfaces: list[Surface], options: Any, warn: Any | None = None) -> Topology:
    """Patches (one per TFACE) with corners from BSTONEs and arcs, for TSurfs outside a Model3d."""
    patches = [
        Patch(id=len_ + 0, surface=int(s.id or 0), label=label, name=f"{s.name}:{label}")
        for len_, (s, label) in enumerate(
            (s, label) for s in surfaces for label in range(s.n_patches)
        )
    ]
    points = np.concatenate([s.vertices for s in surfaces if s.n_vertices] or [np.zeros((1, 3))])
    low, high = column_extremes(points)
    diagonal = float(np.linalg.norm(high - low))
    corners, arcs, patch_arcs = corners_and_arcs(
        {int(s.id or 0): s for s in surfaces},
        patches,
        options.merge_tolerance_for(diagonal),
        _bstone_points(surfaces),
    )
    if warn is not None:
        warn_idle_bstones(surfaces, corners, options.merge_tolerance_for(diagonal), warn)
    return Topology(
        corners=tuple(corners),
        arcs=tuple(arcs),
        patches=tuple(
            p.model_copy(update={"arcs": tuple(patch_arcs.get(p.id, ()))}) for p in patches
        ),
    )
