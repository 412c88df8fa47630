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

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._model_records import (
    Model3dHeader,
    ModelList,
    RegionEntry,
    TFaceEntry,
)
from geobrep.adapters.gocad._objects import gocad_section
from geobrep.adapters.gocad._parser import GocadObject
from geobrep.adapters.gocad._records import Diagnostics
from geobrep.adapters.gocad.options import GocadOptions
from geobrep.geometry.bbox import column_extremes
from geobrep.model.arcs import JoinedPatches, corners_and_arcs_of
from geobrep.model.entities import UNIVERSE_KIND, Block, Entity, PatchSide, Surface
from geobrep.model.orientation import orient_patches
from geobrep.model.scene import Group
from geobrep.model.topology import Corner, Patch, Topology

__all__ = ["Model3dParts", "attach_model3d", "border_topology", "find_key_triangle"]

_LIST_KINDS = {
    "LAYER": "layer",
    "FAULT_BLOCK": "fault_block",
    "SURFACE": "feature",
    "FAULT": "fault",
    "BOUNDARY": "boundary",
    "UNIT": "unit",
}


class Model3dParts(NamedTuple):
    """What a Model3d header adds to a scene."""

    topology: Topology
    blocks: list[Entity]
    groups: list[Group]
    metadata: dict[str, Any]  # the scene's metadata["gocad"]["model3d"]
    surfaces: list[Surface]  # the member surfaces (turned to agree with their key triangles)
    joined: JoinedPatches | None  # the mesh the corners and arcs were found on


def find_key_triangle(
    surface: Surface, label: int, key: NDArray[np.float64], tolerance: float
) -> tuple[int | None, bool]:
    """``(face index, reversed)`` of the triangle of patch ``label`` matching ``key`` (3, 3).

    A match keeps the vertex order up to a cyclic rotation; ``reversed`` is true when only the
    opposite order matches. ``(None, False)`` when no triangle matches.
    """
    faces = surface.patch_faces(label)
    return _match_key(faces, surface.faces[faces][:, :3], surface.vertices, key, tolerance)


def _match_key(
    faces: NDArray[np.int64],
    corners: NDArray[np.integer[Any]],
    vertices: NDArray[np.float64],
    key: NDArray[np.float64],
    tolerance: float,
    first: NDArray[np.float64] | None = None,
) -> tuple[int | None, bool]:
    """:func:`find_key_triangle` among ``faces`` (their first three vertices ``corners``): a
    corner matches a key point when each coordinate is within ``tolerance``; the faces whose
    first corner matches are found first, and only those are checked whole. ``first``: the
    coordinates of the faces' first corners as columns (3, M), when known."""
    if faces.size == 0:
        return None, False
    if first is None:
        first = np.ascontiguousarray(vertices[corners[:, 0]].T)
    near_first: dict[int, NDArray[np.int64]] = {}
    for reverse in (False, True):
        for shift in range(3):
            # corner j of the face against target[(j - shift) % 3], target = key (reversed)
            which = [(j - shift) % 3 for j in range(3)]
            if reverse:
                which = [2 - w for w in which]
            if which[0] not in near_first:
                near_first[which[0]] = np.flatnonzero(_near(first, key[which[0]], tolerance))
            hit = near_first[which[0]]
            for j in (1, 2):
                if not hit.size:
                    break
                at = vertices[corners[hit, j]]
                hit = hit[(np.abs(at - key[which[j]]) <= tolerance).all(axis=1)]
            if hit.size:
                return int(faces[hit[0]]), reverse
    return None, False


def _near(
    columns: NDArray[np.float64], point: NDArray[np.float64], tolerance: float
) -> NDArray[np.bool_]:
    """Which of the points ``columns`` (3, M) lie within ``tolerance`` of ``point`` in each
    coordinate (a column at a time: a reduction across the rows of (M, 3) is slow)."""
    close: NDArray[np.bool_] = np.abs(columns[0] - point[0]) <= tolerance
    close &= np.abs(columns[1] - point[1]) <= tolerance
    close &= np.abs(columns[2] - point[2]) <= tolerance
    return close


class _PatchCorners:
    """Each patch's faces (ascending) and their first three vertices, for one surface."""

    def __init__(self, surface: Surface) -> None:
        labels = (
            np.zeros(surface.n_faces, dtype=np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, dtype=np.int64)
        )
        self.vertices = surface.vertices
        if labels.shape[0] < 2 or bool((labels[1:] >= labels[:-1]).all()):
            # the faces are grouped by patch already (the stable sort would keep them)
            self.order = np.arange(labels.shape[0], dtype=np.int64)
            self.bounds = np.searchsorted(labels, np.arange(surface.n_patches + 1))
            self.corners = surface.faces[:, :3]
        else:
            self.order = np.argsort(labels, kind="stable").astype(np.int64)
            self.bounds = np.searchsorted(labels[self.order], np.arange(surface.n_patches + 1))
            self.corners = surface.faces[self.order][:, :3]
        self.first = np.take(np.ascontiguousarray(surface.vertices.T), self.corners[:, 0], axis=1)

    def find(
        self, label: int, key: NDArray[np.float64], tolerance: float
    ) -> tuple[int | None, bool]:
        """:func:`find_key_triangle` of patch ``label``."""
        lo, hi = int(self.bounds[label]), int(self.bounds[label + 1])
        return _match_key(
            self.order[lo:hi],
            self.corners[lo:hi],
            self.vertices,
            key,
            tolerance,
            self.first[:, lo:hi],
        )


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
    options: GocadOptions,
    builder: Diagnostics,
) -> Model3dParts:
    """Topology, blocks, groups, scene metadata and the member surfaces of a Model3d header.

    With ``options.repair`` (the default) each TFACE's triangles are turned to agree with its
    key triangle, so the surfaces returned may differ from those given.
    """
    header = model.model3d
    diagonal = _diagonal(surfaces)
    matched = _TFaceMatcher(surfaces, z_sign, 1e-9 * max(diagonal, 1.0), builder)
    matched.match_all(header)
    if options.repair:
        surfaces = _orient_by_key_triangles(surfaces, matched.key_faces, matched.patches, builder)
    blocks, region_block = _region_blocks(header, matched, first_id, builder)
    sides = _with_blocks(matched.patches, blocks)
    groups = _groups(header.lists, region_block, matched.patches, builder)
    topology, joined = _rebuilt_topology(
        surfaces, matched.patches, options.merge_tolerance_for(diagonal), builder.warn, sides
    )
    return Model3dParts(topology, blocks, groups, _model_metadata(model), surfaces, joined)


def _diagonal(surfaces: Sequence[Surface]) -> float:
    """The bounding-box diagonal of the surfaces' vertices (1 when they have none)."""
    points = [s.vertices for s in surfaces if s.n_vertices]
    if not points:
        return 1.0
    return _box_diagonal(np.concatenate(points))


def _box_diagonal(points: NDArray[np.float64]) -> float:
    """The bounding-box diagonal of ``points``, finite even when coordinates near the float64
    limit (``1e308``) make it overflow (it is then the largest float, so tolerances derived
    from it stay finite)."""
    low, high = column_extremes(points)
    with np.errstate(over="ignore", invalid="ignore"):
        diagonal = float(np.hypot.reduce(high - low))
    return diagonal if np.isfinite(diagonal) else float(np.finfo(np.float64).max)


class _TFaceMatcher:
    """Header TFACEs matched to the TFACE parts of the member TSurfs, one patch each (a plain
    class: a dataclass costs about 0.4 ms to make at import)."""

    def __init__(
        self, surfaces: list[Surface], z_sign: float, key_tolerance: float, builder: Diagnostics
    ) -> None:
        self.surfaces = surfaces
        self.z_sign = z_sign
        self.key_tolerance = key_tolerance
        self.builder = builder
        self.patches: list[Patch] = []
        self.flipped: dict[int, bool] = {}  # TFACE id -> key triangle reversed
        self.key_faces: dict[int, dict[int, int | None]] = {}
        """surface id -> patch label -> face index of its key triangle (None: not found)."""
        self._corners: dict[int, _PatchCorners] = {}

    def match_all(self, header: Model3dHeader) -> None:
        by_name: dict[str, Surface] = {}
        listed: set[str] = set()  # names given by name_in_model_list
        for surface in self.surfaces:
            names = _tsurf_names(surface)
            if len(names) > 1:
                listed.add(names[0])
            for name in names:
                by_name.setdefault(name, surface)
        declared = set(header.tsurfs)
        seen_parts: dict[str, int] = {}
        for entry in header.tfaces:
            surface = self._surface_of(entry, by_name, listed, declared)
            label = seen_parts.get(entry.tsurf, 0)
            seen_parts[entry.tsurf] = label + 1
            self._match(entry, surface, label)

    def _surface_of(
        self, entry: TFaceEntry, by_name: dict[str, Surface], listed: set[str], declared: set[str]
    ) -> Surface:
        """The TSurf a header TFACE names (warnings when the header does not declare it well)."""
        builder = self.builder
        if entry.tsurf not in declared:
            builder.warn(
                f"TFACE {entry.id} names {entry.tsurf!r}, which has no TSURF line", entry.line
            )
            declared.add(entry.tsurf)
        found = by_name.get(entry.tsurf)
        if found is None:
            raise builder.error(
                f"TFACE {entry.id} names TSurf {entry.tsurf!r}, which is not in the file",
                entry.line,
            )
        if entry.tsurf not in listed:
            builder.warn(
                f"TSurf {entry.tsurf!r} has no name_in_model_list: matched by its name", entry.line
            )
            listed.add(entry.tsurf)
        return found

    def _match(self, entry: TFaceEntry, surface: Surface, label: int) -> None:
        """The patch of TFACE ``entry``: part ``label`` of ``surface``, its key triangle found."""
        if label >= surface.n_patches:
            raise self.builder.error(
                f"TFACE {entry.id} is part {label + 1} of TSurf {entry.tsurf!r}, "
                f"which has {surface.n_patches} TFACE part(s)",
                entry.line,
            )
        key = np.asarray(entry.key, dtype=np.float64)
        key[:, 2] *= self.z_sign
        sid = int(surface.id or 0)
        if sid not in self._corners:
            self._corners[sid] = _PatchCorners(surface)
        face, reverse = self._corners[sid].find(label, key, self.key_tolerance)
        if face is None:
            self.builder.warn(
                f"the key triangle of TFACE {entry.id} is not a triangle of part {label + 1} "
                f"of {entry.tsurf!r}; its REGION signs are taken as they are",
                entry.line,
            )
        self.flipped[entry.id] = reverse
        self.key_faces.setdefault(int(surface.id or 0), {})[label] = face
        gocad: dict[str, Any] = {"geological_type": entry.type, "key_triangle": face}
        if reverse:
            gocad["key_reversed"] = True
        self.patches.append(
            Patch(
                id=entry.id,
                surface=int(surface.id or 0),
                label=label,
                name=f"{entry.tsurf}:{label}",
                metadata={"gocad": gocad},
            )
        )


def _region_sides(
    region: RegionEntry, matched: _TFaceMatcher, patch_ids: set[int], builder: Diagnostics
) -> tuple[PatchSide, ...]:
    """A REGION's signed TFACE ids as patch sides (turned with their flipped TFACEs), each
    once, in the order first listed: one warning for all the ids a REGION repeats."""
    values = np.asarray(region.items, dtype=np.int64)
    unique, first = np.unique(values, return_index=True)
    order = np.sort(first)
    sides: list[PatchSide] = []
    for value in values[order].tolist():
        tface = abs(value)
        if tface not in patch_ids:
            raise builder.error(
                f"REGION {region.name!r} refers to TFACE {tface}, which is not defined",
                region.line,
            )
        side = 1 if value > 0 else -1
        if matched.flipped.get(tface):
            side = -side
        sides.append(PatchSide(tface, side))  # type: ignore[arg-type]
    if unique.shape[0] < values.shape[0]:
        again = np.ones(values.shape[0], dtype=bool)
        again[first] = False
        builder.warn(
            f"REGION {region.name!r} lists {values.shape[0] - unique.shape[0]} side(s) again "
            f"(the first {int(values[np.argmax(again)]):+d}); each is kept once",
            region.line,
        )
    return tuple(sides)


def _region_blocks(
    header: Model3dHeader, matched: _TFaceMatcher, first_id: int, builder: Diagnostics
) -> tuple[list[Entity], dict[int, int]]:
    """One block per REGION (sides as the key triangles say) and ``{REGION id: block id}``."""
    patch_ids = {p.id for p in matched.patches}
    layer_of: dict[int, str] = {}
    for entry in header.lists:
        if entry.keyword == "LAYER":
            for region_id in entry.items:
                layer_of.setdefault(region_id, entry.name)
    n_tfaces = len(matched.patches)
    blocks: list[Entity] = []
    region_block: dict[int, int] = {}
    for region in header.regions:
        if region.id <= n_tfaces or region.id in region_block:
            builder.warn(
                f"REGION id {region.id} should follow the TFACE ids and be unique; "
                "it is renumbered when written",
                region.line,
            )
        sides = _region_sides(region, matched, patch_ids, builder)
        block_id = first_id + len(blocks)
        region_block[region.id] = block_id
        universe = region.name.strip().lower() == "universe"
        blocks.append(
            Block(
                id=block_id,
                name=region.name,
                kind=UNIVERSE_KIND if universe else "unit",
                sides=sides,
                unit_name=None if universe else layer_of.get(region.id),
                metadata={"gocad": {"region_id": region.id}},
            )
        )
    return blocks, region_block


def _with_blocks(patches: list[Patch], blocks: list[Entity]) -> dict[int, dict[str, Any]]:
    """The first block on each side of every patch, as updates of the patches."""
    positive: dict[int, int] = {}
    negative: dict[int, int] = {}
    for block in blocks:
        assert isinstance(block, Block)
        for patch_id, side in block.sides:
            (positive if side == 1 else negative).setdefault(patch_id, int(block.id or 0))
    return {
        p.id: {"positive_block": positive.get(p.id), "negative_block": negative.get(p.id)}
        for p in patches
    }


def _rebuilt_topology(
    surfaces: list[Surface],
    patches: list[Patch],
    tolerance: float,
    warn: Callable[[str], None] | None,
    updates: dict[int, dict[str, Any]] | None = None,
) -> tuple[Topology, JoinedPatches | None]:
    """Corners and arcs rebuilt from the patches (BSTONEs as extra corners) around them; each
    patch is copied once, with its arcs and its ``updates`` (the blocks on its sides); and
    the joined mesh they were found on."""
    corners, arcs, patch_arcs, joined = corners_and_arcs_of(
        {int(s.id or 0): s for s in surfaces}, patches, tolerance, _bstone_points(surfaces)
    )
    if warn is not None:
        warn_idle_bstones(surfaces, corners, tolerance, warn)
    # The patches were validated when matched; what is added to them here is made from
    # checked data (arc ids numbered from 0, block ids of validated blocks, or None), so
    # each copy is built as its validation would leave it.
    fields = tuple(Patch.model_fields)
    topology = Topology(
        corners=tuple(corners),
        arcs=tuple(arcs),
        patches=tuple(
            Patch.model_construct(
                **{
                    **{name: getattr(p, name) for name in fields},
                    "arcs": tuple(patch_arcs.get(p.id, ())),
                    **(updates or {}).get(p.id, {}),
                }
            )
            for p in patches
        ),
    )
    return topology, joined


def _model_metadata(model: GocadObject) -> dict[str, Any]:
    """What the scene keeps of the Model3d object (JSON, for the writer)."""
    kept: dict[str, Any] = {
        "version": model.version,
        "header": [[k, v] for k, v in model.header],
        "tsurfs": list(model.model3d.tsurfs),
    }
    if model.extra_lines:
        kept["extra_lines"] = model.extra_lines
    return {"gocad": {"model3d": kept}}


def _orient_by_key_triangles(
    surfaces: list[Surface],
    key_faces: dict[int, dict[int, int | None]],
    patches: list[Patch],
    builder: Diagnostics,
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
    lists: Sequence[ModelList],
    region_block: dict[int, int],
    patches: list[Patch],
    builder: Diagnostics,
) -> list[Group]:
    surface_of_tface = {p.id: p.surface for p in patches}
    groups: list[Group] = []
    for entry in lists:
        items = list(entry.items)
        if entry.keyword in ("LAYER", "FAULT_BLOCK"):
            unknown = [i for i in items if i not in region_block]
            if unknown:
                builder.warn(
                    f"{entry.keyword} {entry.name!r}: id {unknown[0]} does not match a REGION",
                    entry.line,
                )
            members = [region_block[i] for i in items if i in region_block]
            # "unmatched": ids the file itself lists without a REGION (kept when written)
            raw = {"keyword": entry.keyword, "regions": items, "unmatched": unknown}
        else:
            members = list(
                dict.fromkeys(surface_of_tface[i] for i in items if i in surface_of_tface)
            )
            raw = {"keyword": entry.keyword, "tfaces": items}
        groups.append(
            Group(
                name=entry.name,
                kind=_LIST_KINDS[entry.keyword],
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
    surfaces: list[Surface],
    corners: Sequence[Corner],
    tolerance: float,
    warn: Callable[[str], None],
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
            # the largest coordinate gap to each corner (a coordinate at a time: a reduction
            # over an axis of 3 is slow), the smallest over the corners
            gap = np.abs(at[:, 0:1] - points[:, 0])
            np.maximum(gap, np.abs(at[:, 1:2] - points[:, 1]), out=gap)
            np.maximum(gap, np.abs(at[:, 2:3] - points[:, 2]), out=gap)
            far = np.flatnonzero(gap.min(axis=1) > tolerance).tolist()
            idle = [int(stones[k]) for k in far]
        else:
            idle = [int(v) for v in stones]
        if idle:
            warn(
                f"surface {surface.name!r}: {len(idle)} BSTONE(s) not on a border of the model "
                f"(vertex index {idle[0]}{', ...' if len(idle) > 1 else ''}) mark no corner"
            )


def border_topology(
    surfaces: list[Surface],
    options: GocadOptions,
    warn: Callable[[str], None] | None = None,
) -> Topology:
    """Patches (one per TFACE) with corners from BSTONEs and arcs, for TSurfs outside a Model3d."""
    patches = [
        Patch(id=number, surface=int(s.id or 0), label=label, name=f"{s.name}:{label}")
        for number, (s, label) in enumerate(
            (s, label) for s in surfaces for label in range(s.n_patches)
        )
    ]
    points = np.concatenate([s.vertices for s in surfaces if s.n_vertices] or [np.zeros((1, 3))])
    diagonal = _box_diagonal(points)
    return _rebuilt_topology(surfaces, patches, options.merge_tolerance_for(diagonal), warn)[0]
