"""A conformal, faulted and folded layer-cake model with its exact B-Rep topology.

The model is built from a vertical cross-section in the x–z plane: a box cut by a dipping normal
fault and by ``n_horizons`` dipping horizons offset by the fault's throw. Every section edge is
subdivided once and extruded along y, and every section cell becomes the south (y = 0) and north
(y = length) faces of a block, so surfaces meeting along a line share those vertices exactly.
A volume-preserving fold ``z += A sin(πx/X) sin(πy/Y)`` then bends horizons, fault and top while
the walls stay planar. Because the construction knows every patch and block, the scene carries
its patches with their positive/negative blocks and the blocks with their signed patch lists;
corners and arcs (patches in right-hand order) follow geobrep's one rule
(:mod:`geobrep.model.arcs`), the rule of the GOCAD reader and the block builder — a ground
truth for the block builder and a test bed for clipping and voxelization.
"""

from __future__ import annotations

import itertools
import math
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry import mesh
from geobrep.model.arcs import corners_and_arcs
from geobrep.model.crs import CRS
from geobrep.model.entities import UNIVERSE_KIND, Block, PatchSide, Surface
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Patch, Topology

__all__ = ["faulted_layer_cake"]

Point2 = tuple[float, float]


@dataclass
class _Section:
    """The x–z cross-section as a planar straight-line graph with named edges."""

    points: list[Point2] = field(default_factory=list)
    edges: list[tuple[str, int, int]] = field(default_factory=list)  # (surface, from, to)

    def point(self, x: float, z: float) -> int:
        for index, (px, pz) in enumerate(self.points):
            if math.isclose(px, x, abs_tol=1e-9) and math.isclose(pz, z, abs_tol=1e-9):
                return index
        self.points.append((x, z))
        return len(self.points) - 1

    def polyline(self, surface: str, chain: list[int]) -> None:
        self.edges.extend((surface, a, b) for a, b in itertools.pairwise(chain))


def _section(
    width: float,
    height: float,
    horizons: list[float],
    dip: float,
    fault_top: float,
    fault_slope: float,
    throw: float,
) -> _Section:
    section = _Section()
    top_left, top_right = section.point(0, 0), section.point(width, 0)
    bottom_left, bottom_right = section.point(0, -height), section.point(width, -height)
    fault_top_point = section.point(fault_top, 0)
    fault_bottom_point = section.point(fault_top - fault_slope * height, -height)

    def on_fault(depth_at_zero: float) -> Point2:
        # Horizon z = c + dip·x meets the fault x = fault_top + fault_slope·z.
        x = (fault_top + fault_slope * depth_at_zero) / (1 - fault_slope * dip)
        return x, depth_at_zero + dip * x

    west, east, fault_points = [bottom_left], [top_right], []
    for index, level in enumerate(horizons, start=1):
        left = section.point(0, level)
        foot = section.point(*on_fault(level))
        hanging = section.point(*on_fault(level - throw))
        right = section.point(width, level - throw + dip * width)
        section.polyline(f"H{index}", [left, foot])
        section.polyline(f"H{index}", [hanging, right])
        west.insert(1, left)
        east.append(right)
        fault_points += [foot, hanging]
    west.append(top_left)
    east.append(bottom_right)
    fault_points.sort(key=lambda i: -section.points[i][1])
    section.polyline("top", [top_left, fault_top_point, top_right])
    section.polyline("bottom", [bottom_right, fault_bottom_point, bottom_left])
    section.polyline("west", west)
    section.polyline("east", east)
    section.polyline("fault", [fault_top_point, *fault_points, fault_bottom_point])
    return section


def _cells(section: _Section) -> list[list[tuple[int, int]]]:
    """Bounded faces of the section as counter-clockwise cycles of (edge, +1/-1 direction)."""
    pts = np.asarray(section.points)
    outgoing: dict[int, list[tuple[float, int, int]]] = defaultdict(list)
    for edge, (_, a, b) in enumerate(section.edges):
        for start, end, direction in ((a, b, 1), (b, a, -1)):
            dx, dz = pts[end] - pts[start]
            outgoing[start].append((math.atan2(dz, dx), edge, direction))
    for spokes in outgoing.values():
        spokes.sort()
    visited: set[tuple[int, int]] = set()
    cells = []
    for edge in range(len(section.edges)):
        for direction in (1, -1):
            if (edge, direction) in visited:
                continue
            cycle, current = [], (edge, direction)
            while current not in visited:
                visited.add(current)
                cycle.append(current)
                _, a, b = section.edges[current[0]]
                head = b if current[1] == 1 else a
                spokes = outgoing[head]
                back = next(
                    i for i, s in enumerate(spokes) if s[1] == current[0] and (s[2] == -current[1])
                )
                _, next_edge, next_dir = spokes[(back - 1) % len(spokes)]  # turn most right
                current = (next_edge, next_dir)
            area = 0.0
            for e, d in cycle:
                _, a, b = section.edges[e]
                (x0, z0), (x1, z1) = (pts[a], pts[b]) if d == 1 else (pts[b], pts[a])
                area += x0 * z1 - x1 * z0
            if area > 0:
                cells.append(cycle)
    return cells


def _subdivide(p: NDArray[np.float64], q: NDArray[np.float64], step: float) -> NDArray[np.float64]:
    count = max(1, math.ceil(float(np.linalg.norm(q - p)) / step))
    t = np.linspace(0.0, 1.0, count + 1)[:, None]
    points = p + t * (q - p)
    points[-1] = q
    return points


@dataclass(frozen=True)
class _Faulting:
    """Layout of the section: horizon levels at x = 0, their dip, the fault and its throw."""

    levels: list[float]
    dip: float
    fault_top: float
    fault_slope: float
    throw: float


def _faulting(n_horizons: int, width: float, height: float, throw: float) -> _Faulting:
    """Evenly spaced dipping horizons and a normal fault through the box (checks the throw)."""
    spacing = height / (n_horizons + 1)
    dip = -0.05
    fault_top, fault_slope = 0.55 * width, 0.3
    levels = [-spacing * (i + 1) + 0.25 * spacing for i in range(n_horizons)]
    lowest = min([lv - throw + dip * width for lv in levels], default=0.0)
    if lowest <= -height or throw >= spacing * 0.75:
        raise ValueError("throw too large for the layer thickness")
    return _Faulting(levels, dip, fault_top, fault_slope, throw)


#: Vertices and triangles of each patch of one surface, before merging.
_Parts = tuple[list[NDArray[np.float64]], list[NDArray[np.int64]]]


def _strip_parts(
    edge_points: list[NDArray[np.float64]], edges: list[int], ys: NDArray[np.float64]
) -> _Parts:
    """One patch per section edge: the edge's polyline extruded along y at ``ys``."""
    n_y = ys.shape[0] - 1
    vertex_parts: list[NDArray[np.float64]] = []
    face_parts: list[NDArray[np.int64]] = []
    for edge in edges:
        line = edge_points[edge]
        n_s = len(line)
        grid = np.empty((n_y + 1, n_s, 3))
        grid[:, :, 0] = line[None, :, 0]
        grid[:, :, 1] = ys[:, None]
        grid[:, :, 2] = line[None, :, 1]
        i, j = np.meshgrid(np.arange(n_s - 1), np.arange(n_y), indexing="xy")
        a = (j * n_s + i).ravel()
        quads = np.stack([a, a + 1, a + 1 + n_s, a + n_s], axis=1)
        vertex_parts.append(grid.reshape(-1, 3))
        face_parts.append(np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]))
    return vertex_parts, face_parts


def _cap_parts(
    cells: list[list[tuple[int, int]]],
    edge_points: list[NDArray[np.float64]],
    at_y: float,
    flip: bool,
) -> _Parts:
    """One patch per section cell: a fan about its centre in the plane y = ``at_y``."""
    vertex_parts: list[NDArray[np.float64]] = []
    face_parts: list[NDArray[np.int64]] = []
    for cycle in cells:
        ring = np.concatenate(
            [(edge_points[e] if d == 1 else edge_points[e][::-1])[:-1] for e, d in cycle]
        )
        centre = ring.mean(axis=0)
        k = len(ring)
        fan = np.stack(
            [np.zeros(k, np.int64), np.arange(1, k + 1), np.roll(np.arange(k), -1) + 1], axis=1
        )
        xyz = np.column_stack(
            [np.r_[centre[0], ring[:, 0]], np.full(k + 1, at_y), np.r_[centre[1], ring[:, 1]]]
        )
        vertex_parts.append(xyz)
        face_parts.append(fan[:, ::-1] if flip else fan)
    return vertex_parts, face_parts


@dataclass(frozen=True)
class _Fold:
    """The volume-preserving fold ``z += A sin(πx/X) sin(πy/Y)``, then the shift to ``origin``."""

    amplitude: float
    width: float
    length: float
    origin: tuple[float, float, float]

    def __call__(self, xyz: NDArray[np.float64]) -> NDArray[np.float64]:
        out = xyz.copy()
        out[:, 2] += (
            self.amplitude
            * np.sin(np.pi * xyz[:, 0] / self.width)
            * np.sin(np.pi * xyz[:, 1] / self.length)
        )
        return np.asarray(out + np.asarray(self.origin), dtype=np.float64)


def _surfaces(
    builders: dict[str, _Parts],
    strip_surfaces: dict[str, list[int]],
    n_cells: int,
    n_horizons: int,
    fold: _Fold,
) -> tuple[list[Surface], dict[int, tuple[int, int]]]:
    """The folded surfaces (ids in ``builders`` order) and the (surface, patch) of each edge."""
    kinds = {"fault": "fault", **{f"H{i}": "horizon" for i in range(1, n_horizons + 1)}}
    entities: list[Surface] = []
    patch_of_edge: dict[int, tuple[int, int]] = {}
    for surface_id, (surface, (vertex_parts, face_parts)) in enumerate(builders.items()):
        offsets = np.cumsum([0] + [len(v) for v in vertex_parts])
        faces = np.concatenate([f + o for f, o in zip(face_parts, offsets, strict=False)])
        labels = np.concatenate([np.full(len(f), k) for k, f in enumerate(face_parts)])
        merged, inverse = mesh.merge_close_vertices(np.concatenate(vertex_parts), 0.0)
        if surface in strip_surfaces:
            names = tuple(f"{surface}:{k}" for k in range(len(face_parts)))
            for k, edge in enumerate(strip_surfaces[surface]):
                patch_of_edge[edge] = (surface_id, k)
        else:
            names = tuple(f"{surface}:cell{k}" for k in range(n_cells))
        entities.append(
            Surface(
                id=surface_id,
                name=surface,
                kind=kinds.get(surface, "boundary"),
                vertices=fold(merged),
                faces=inverse[faces],
                patch_labels=labels,
                patch_names=names,
            )
        )
    return entities, patch_of_edge


def _cell_names(
    cells: list[list[tuple[int, int]]],
    edge_points: list[NDArray[np.float64]],
    faulting: _Faulting,
) -> list[tuple[str, int]]:
    """(side of the fault, layer number) of every cell, from its centre."""
    cell_names = []
    for cycle in cells:
        ring = np.concatenate([edge_points[e] for e, _ in cycle])
        cx, cz = ring.mean(axis=0)
        hanging = cx > faulting.fault_top + faulting.fault_slope * cz
        shift = faulting.throw if hanging else 0.0
        layer = 1 + sum(1 for level in faulting.levels if level - shift + faulting.dip * cx > cz)
        cell_names.append(("hanging wall" if hanging else "footwall", layer))
    return cell_names


def faulted_layer_cake(
    n_horizons: int = 2,
    resolution: float = 50.0,
    *,
    width: float = 1000.0,
    length: float = 800.0,
    height: float = 600.0,
    throw: float = 80.0,
    fold_amplitude: float = 40.0,
    origin: tuple[float, float, float] = (450_000.0, 6_700_000.0, 0.0),
) -> Scene:
    """A faulted, folded layer cake: ``2 × (n_horizons + 1)`` blocks with exact topology.

    Surfaces: horizons ``H1..Hn`` (split by the fault into footwall and hanging-wall patches),
    ``fault`` (split at every horizon line), and the six box faces ``top``, ``bottom``, ``west``,
    ``east``, ``south``, ``north`` (normals pointing out of the model). Coordinates are UTM-scale
    (``origin`` is added) in EPSG:32631 metres. ``resolution`` is the target edge length.

    >>> scene = faulted_layer_cake()
    >>> len(scene.blocks), len(scene.patches), scene.universe.name
    (6, 31, 'universe')
    """
    if n_horizons < 0:
        raise ValueError("n_horizons must be ≥ 0")
    if not resolution > 0:
        raise ValueError("resolution must be > 0")
    f = _faulting(n_horizons, width, height, throw)
    section = _section(width, height, f.levels, f.dip, f.fault_top, f.fault_slope, throw)
    cells = _cells(section)
    pts = np.asarray(section.points)
    edge_points = [_subdivide(pts[a], pts[b], resolution) for _, a, b in section.edges]
    n_y = max(1, math.ceil(length / resolution))
    ys = np.linspace(0.0, length, n_y + 1)

    # -- surfaces: one patch per section edge (strips) or per cell (south/north faces) --------
    strip_surfaces: dict[str, list[int]] = defaultdict(list)  # surface -> its edges, in order
    for edge, (surface, _, _) in enumerate(section.edges):
        strip_surfaces[surface].append(edge)
    builders = {
        surface: _strip_parts(edge_points, edges, ys) for surface, edges in strip_surfaces.items()
    }
    builders["south"] = _cap_parts(cells, edge_points, 0.0, flip=False)
    builders["north"] = _cap_parts(cells, edge_points, length, flip=True)
    fold = _Fold(fold_amplitude, width, length, origin)
    entities, patch_of_edge = _surfaces(builders, strip_surfaces, len(cells), n_horizons, fold)
    return _with_topology(
        entities,
        section,
        cells,
        patch_of_edge,
        origin,
        n_horizons,
        _cell_names(cells, edge_points, f),
    )


@dataclass
class _BlockSides:
    """Positive and negative block of every patch (by patch id) and the sides of every block."""

    patch_ids: dict[tuple[int, int], int]
    positive: dict[int, int] = field(default_factory=dict)
    negative: dict[int, int] = field(default_factory=dict)
    sides: dict[int, list[PatchSide]] = field(default_factory=lambda: defaultdict(list))

    def assign(self, patch: int, side: int, block: int) -> None:
        (self.positive if side == 1 else self.negative)[patch] = block
        self.sides[block].append(PatchSide(patch, 1 if side == 1 else -1))


def _block_sides(
    surfaces: list[Surface],
    section: _Section,
    cells: list[list[tuple[int, int]]],
    patch_of_edge: dict[int, tuple[int, int]],
    block_ids: list[int],
    universe_id: int,
) -> _BlockSides:
    """Each cell's block bounded by its edges' strips and its south/north caps; the universe
    by the section's border strips and the caps' other sides."""
    by_name = {s.name: s for s in surfaces}
    patch_ids: dict[tuple[int, int], int] = {}
    for surface in surfaces:
        for label in range(surface.n_patches):
            patch_ids[(int(surface.id or 0), label)] = len(patch_ids)
    sides = _BlockSides(patch_ids)
    edge_cells: dict[int, list[tuple[int, int]]] = defaultdict(list)
    for cell, cycle in enumerate(cells):
        for edge, direction in cycle:
            edge_cells[edge].append((cell, direction))
            sides.assign(patch_ids[patch_of_edge[edge]], direction, block_ids[cell])
        for face_name in ("south", "north"):
            sides.assign(patch_ids[(int(by_name[face_name].id or 0), cell)], -1, block_ids[cell])
    for edge in range(len(section.edges)):
        if len(edge_cells[edge]) == 1:
            sides.assign(patch_ids[patch_of_edge[edge]], -edge_cells[edge][0][1], universe_id)
    for face_name in ("south", "north"):
        for cell in range(len(cells)):
            sides.assign(patch_ids[(int(by_name[face_name].id or 0), cell)], 1, universe_id)
    return sides


def _blocks(
    block_ids: list[int],
    universe_id: int,
    cell_names: list[tuple[str, int]],
    sides: _BlockSides,
) -> list[Block]:
    """One block per cell, named by side of the fault and layer; then the universe."""
    blocks = [
        Block(
            id=block_id,
            name=f"{side} unit {layer}",
            unit_name=f"unit {layer}",
            sides=tuple(sides.sides[block_id]),
            metadata={"fault_side": side, "layer": layer},
        )
        for block_id, (side, layer) in zip(block_ids, cell_names, strict=True)
    ]
    blocks.append(
        Block(
            id=universe_id,
            name="universe",
            kind=UNIVERSE_KIND,
            sides=tuple(sides.sides[universe_id]),
        )
    )
    return blocks


def _groups(surfaces: list[Surface], blocks: list[Block]) -> tuple[Group, ...]:
    """The horizons, faults, boundaries and blocks groups."""

    def of_kind(kind: str) -> tuple[int, ...]:
        return tuple(int(s.id or 0) for s in surfaces if s.kind == kind)

    return (
        Group(name="horizons", kind="horizons", members=of_kind("horizon")),
        Group(name="faults", kind="faults", members=of_kind("fault")),
        Group(name="boundaries", kind="boundaries", members=of_kind("boundary")),
        Group(name="blocks", kind="blocks", members=tuple(b.id or 0 for b in blocks)),
    )


def _with_topology(
    surfaces: list[Surface],
    section: _Section,
    cells: list[list[tuple[int, int]]],
    patch_of_edge: dict[int, tuple[int, int]],
    origin: tuple[float, float, float],
    n_horizons: int,
    cell_names: list[tuple[str, int]],
) -> Scene:
    """The scene of ``surfaces`` with its blocks, patches, corners and arcs."""
    next_id = len(surfaces)
    block_ids = list(range(next_id, next_id + len(cells)))
    universe_id = next_id + len(cells)
    sides = _block_sides(surfaces, section, cells, patch_of_edge, block_ids, universe_id)
    patches = [
        Patch(
            id=pid,
            surface=sid,
            label=label,
            name=by_name_label(surfaces, sid, label),
            positive_block=sides.positive.get(pid),
            negative_block=sides.negative.get(pid),
        )
        for (sid, label), pid in sides.patch_ids.items()
    ]
    # Corners and arcs by geobrep's one rule (geobrep.model.arcs), as readers and the builder
    # find them.
    corners, arcs, patch_arcs = corners_and_arcs({int(s.id or 0): s for s in surfaces}, patches)
    patches = [p.model_copy(update={"arcs": tuple(patch_arcs.get(p.id, ()))}) for p in patches]
    blocks = _blocks(block_ids, universe_id, cell_names, sides)
    return Scene(
        name="faulted layer cake",
        entities=[*surfaces, *blocks],
        groups=_groups(surfaces, blocks),
        crs=CRS(epsg=32631, name="WGS 84 / UTM zone 31N"),
        topology=Topology(corners=tuple(corners), arcs=tuple(arcs), patches=tuple(patches)),
        metadata={
            "dataset": "faulted_layer_cake",
            "n_horizons": n_horizons,
            "origin": list(origin),
        },
    )


def by_name_label(surfaces: list[Surface], surface_id: int, label: int) -> str:
    surface = next(s for s in surfaces if s.id == surface_id)
    return surface.patch_name(label)
