"""Write a scene as GOCAD ASCII: TSurf, PLine, VSet, TSolid, Model3d or a group file.

The object type comes from the extension (``.ts`` TSurf, ``.pl`` PLine, ``.vs`` VSet, ``.so``
TSolid, ``.ml`` Model3d, ``.gp`` HeterogeneousGroup) or the ``object_type`` option. Entities
the chosen type cannot hold are reported with a :class:`GocadWarning` (never dropped silently).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._grid_members import MemberFiles
from geobrep.adapters.gocad._headers import quote_rest
from geobrep.adapters.gocad._numbers import format_float, format_rows, row_pieces
from geobrep.adapters.gocad._objects import (
    _TYPE_OF_KIND,
    CTETRA_PROPERTY,
    FLAG_PROPERTY,
    ObjectText,
    VertexWriter,
    class_header_lines,
    crs_block,
    geology_lines,
    gocad_metadata,
    gocad_section,
    header_lines,
    object_crs,
    part_vertex_ranges,
    property_header,
    report,
    value_columns,
    z_sign_of,
)
from geobrep.adapters.gocad.options import GocadOptions
from geobrep.errors import FormatError
from geobrep.geometry.bbox import column_extremes
from geobrep.model.arcs import DEFAULT_RELATIVE_TOLERANCE
from geobrep.model.entities import Block, Entity, PointSet, PolyLine, Surface, TetMesh
from geobrep.model.properties import Property
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Arc, Patch

__all__ = ["OBJECT_TYPES", "write_gocad"]

#: Object type written for each extension.
OBJECT_TYPES = {
    ".ts": "TSurf",
    ".pl": "PLine",
    ".vs": "VSet",
    ".so": "TSolid",
    ".ml": "Model3d",
    ".gp": "HeterogeneousGroup",
}
_ENTITY_OF = {"TSurf": Surface, "PLine": PolyLine, "VSet": PointSet, "TSolid": TetMesh}
_GROUP_KINDS = ("HeterogeneousGroup", "HomogeneousGroup")
#: TSurf HEADER key holding the geobrep ``kind`` when no GOCAD type says it (``cap``, ...).
KIND_KEY = "geobrep_kind"


def _version(entity: Entity | None) -> str:
    return str(gocad_metadata(entity).get("version", "1"))


class _Writer:
    def __init__(self, scene: Scene, path: Path, options: GocadOptions) -> None:
        self.scene = scene
        self.path = path
        self.options = options
        self.members = MemberFiles(path)

    # -- shared head ------------------------------------------------------------------------
    def head(
        self,
        out: ObjectText,
        object_type: str,
        entity: Entity,
        props: dict[str, Property],
        cell_props: dict[str, Property],
        cell_prefix: str,
        extra_header: tuple[tuple[str, str], ...] = (),
    ) -> tuple[list[tuple[str, Property]], list[tuple[str, Property]], float]:
        in_model = object_type == "TSurf" and any(
            k == "name_in_model_list" for k, _ in extra_header
        )  # a Model3d member: its TFACE lines carry the type
        meta = gocad_metadata(entity)
        if any(k == KIND_KEY for k, _ in meta.get("header", [])):
            meta = {**meta, "header": [kv for kv in meta["header"] if kv[0] != KIND_KEY]}
        out.add(f"GOCAD {object_type} {_version(entity)}")
        out.add(
            *header_lines(
                object_type, entity.name, meta, entity.metadata.get("color"), extra_header
            )
        )
        crs = object_crs(entity, self.scene.crs)
        out.add(*crs_block(crs))
        out.add(*geology_lines(meta, entity.kind, object_type, not in_model))
        where = entity.label
        lines, chosen = property_header(props, "", (FLAG_PROPERTY,), where)
        out.add(*lines)
        cell_lines, cell_chosen = property_header(
            cell_props, cell_prefix, (CTETRA_PROPERTY,), where
        )
        out.add(*cell_lines)
        out.add(*class_header_lines(meta))
        return chosen, cell_chosen, z_sign_of(crs)

    def vertex_writer(
        self,
        entity: Surface | PolyLine | PointSet | TetMesh,
        chosen: list[tuple[str, Property]],
        z_sign: float,
        atom: str = "ATOM",
    ) -> VertexWriter:
        values = value_columns(chosen, entity.n_points)
        flags = entity.point_data.get(FLAG_PROPERTY)
        return VertexWriter(
            entity.vertices, values, None if flags is None else np.asarray(flags), z_sign, atom
        )

    def tail(self, out: ObjectText, entity: Entity) -> None:
        out.add(*(gocad_metadata(entity).get("extra_lines") or []))
        out.add("END")

    # -- TSurf ----------------------------------------------------------------------------------
    def tsurf(
        self,
        surface: Surface,
        extra_header: tuple[tuple[str, str], ...] = (),
        tface_type: str | None = None,
        in_model: bool = False,
    ) -> bytes:
        """A TSurf (a Model3d member when ``in_model``); its TFACEs' vertices as the
        ``tface_vertices`` option says (see :func:`_own_tface_vertices`)."""
        layout = self.options.tface_vertices or ("own" if in_model else "shared")
        if layout == "own":
            surface = _own_tface_vertices(surface)
        out = ObjectText()
        if surface.faces.shape[1] == 4:
            report(f"{surface.label}: quads are written as two triangles each")
        extra_header = (*extra_header, *_kind_header(surface, tface_type))
        chosen, cell_chosen, z_sign = self.head(
            out,
            "TSurf",
            surface,
            dict(surface.point_data),
            dict(surface.cell_data),
            "TRGL_",
            extra_header,
        )
        faces, source = _triangles(surface)
        labels = (
            np.zeros(faces.shape[0], dtype=np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, dtype=np.int64)[source]
        )
        if (np.diff(labels) < 0).any():
            report(f"{surface.label}: faces are reordered to group them by patch (TFACE)")
            order = np.argsort(labels, kind="stable")
            faces, labels, source = faces[order], labels[order], source[order]
        present = _written_labels(surface)  # a patch without triangles is no TFACE
        labels = np.searchsorted(present, labels)
        n_parts = int(present.shape[0])
        starts = part_vertex_ranges(surface.n_vertices, faces, labels, n_parts)
        vw = self.vertex_writer(surface, chosen, z_sign)
        cell_values = value_columns(cell_chosen, surface.n_faces)[source] if cell_chosen else None
        bounds = np.searchsorted(labels, np.arange(n_parts + 1))
        for part in range(n_parts):
            name = surface.patch_name(int(present[part]))
            out.add("TFACE" if name in (str(part), str(int(present[part]))) else f"TFACE {name}")
            out.add_pieces(vw.lines(int(starts[part]), int(starts[part + 1])))
            lo, hi = int(bounds[part]), int(bounds[part + 1])
            values = cell_values[lo:hi] if cell_values is not None else None
            out.add_pieces(row_pieces(b"TRGL", faces[lo:hi] + 1, values))
        if n_parts == 0:  # no triangles: one TFACE holds the vertices (the patch's name kept)
            name = surface.patch_name(0) if surface.n_patches else "0"
            out.add("TFACE" if name == "0" else f"TFACE {name}")
            out.add_pieces(vw.lines(0, surface.n_vertices))
        self.borders(out, surface)
        self.tail(out, surface)
        return out.text()

    def borders(self, out: ObjectText, surface: Surface) -> None:
        """BSTONE / BORDER lines: the source's when they still fit the scene's corners and
        arcs, else derived from them (a corner at every BSTONE, a BORDER along every arc)."""
        meta = gocad_metadata(surface)
        n = surface.n_vertices
        bstones = [int(v) for v in meta.get("bstones", []) if 0 <= int(v) < n]
        borders = [
            (int(a), int(b)) for a, b in meta.get("borders", []) if 0 <= a < n and 0 <= b < n
        ]
        places = self._border_places(surface)
        if places is not None and not places.fit(bstones, borders):
            bstones, borders = places.derived()
        for v in bstones:
            out.add(f"BSTONE {v + 1}")
        for k, (a, b) in enumerate(borders):
            out.add(f"BORDER {n + k + 1} {a + 1} {b + 1}")

    def _border_places(self, surface: Surface) -> _BorderPlaces | None:
        """The scene's corners and arcs on this surface's patches (None: it has none)."""
        topology = self.scene.topology
        mine = {p.id for p in topology.patches if p.surface == surface.id}
        if not mine or not topology.corners or surface.n_vertices == 0:
            return None
        arcs = [a for a in topology.arcs if mine.intersection(a.patches)]
        return _BorderPlaces(surface, self._tolerance(), [c.point for c in topology.corners], arcs)

    def _tolerance(self) -> float:
        if not hasattr(self, "_joining"):
            points = [s.vertices for s in self.scene.surfaces if s.n_vertices]
            diagonal = 1.0
            if points:
                low, high = column_extremes(np.concatenate(points))
                diagonal = float(np.linalg.norm(high - low)) or 1.0
            self._joining = DEFAULT_RELATIVE_TOLERANCE * diagonal
        return self._joining

    # -- PLine ----------------------------------------------------------------------------------
    def pline(self, line: PolyLine) -> bytes:
        out = ObjectText()
        chosen, cell_chosen, z_sign = self.head(
            out, "PLine", line, dict(line.point_data), dict(line.cell_data), "SEG_"
        )
        segments = np.asarray(line.segments, dtype=np.int64)
        lengths = line.part_lengths - 1 + line.closed.astype(np.int64)
        seg_part = np.repeat(np.arange(line.n_parts), lengths)
        meta = gocad_metadata(line)
        groups = meta.get("iline_parts")
        if not (isinstance(groups, list) and sum(groups) == line.n_parts):
            groups = [1] * line.n_parts
        names = meta.get("iline_names") or []
        iline_of_part = np.repeat(np.arange(len(groups)), groups)
        seg_iline = iline_of_part[seg_part] if seg_part.size else seg_part
        n_ilines = len(groups)
        starts = part_vertex_ranges(line.n_points, segments, seg_iline, n_ilines)
        vw = self.vertex_writer(line, chosen, z_sign)
        cell_values = value_columns(cell_chosen, line.n_cells) if cell_chosen else None
        bounds = np.searchsorted(seg_iline, np.arange(n_ilines + 1))
        for k in range(n_ilines):
            name = names[k] if k < len(names) and names[k] else ""
            out.add(f"ILINE {name}".rstrip())
            out.add_pieces(vw.lines(int(starts[k]), int(starts[k + 1])))
            lo, hi = int(bounds[k]), int(bounds[k + 1])
            values = cell_values[lo:hi] if cell_values is not None else None
            out.add_pieces(row_pieces(b"SEG", segments[lo:hi] + 1, values))
        if n_ilines == 0:
            out.add("ILINE")
            out.add_pieces(vw.lines(0, line.n_points))
        self.tail(out, line)
        return out.text()

    # -- VSet -----------------------------------------------------------------------------------
    def vset(self, points: PointSet) -> bytes:
        out = ObjectText()
        chosen, _, z_sign = self.head(out, "VSet", points, dict(points.point_data), {}, "")
        vw = self.vertex_writer(points, chosen, z_sign)
        starts = gocad_metadata(points).get("subvset_starts") or []
        cuts = [int(s) for s in starts if 0 <= int(s) <= points.n_points]
        if cuts != sorted(cuts):
            cuts = []
        bounds = [0, *cuts, points.n_points] if cuts else [0, points.n_points]
        for k in range(len(bounds) - 1):
            if cuts:
                out.add("SUBVSET")
            out.add_pieces(vw.lines(bounds[k], bounds[k + 1]))
        self.tail(out, points)
        return out.text()

    # -- TSolid ---------------------------------------------------------------------------------
    def tsolid(self, tets: TetMesh) -> bytes:
        out = ObjectText()
        chosen, cell_chosen, z_sign = self.head(
            out, "TSolid", tets, dict(tets.point_data), dict(tets.cell_data), "TETRA_"
        )
        cells = np.asarray(tets.cells, dtype=np.int64)
        labels = (
            np.zeros(cells.shape[0], dtype=np.int64)
            if tets.region_labels is None
            else np.asarray(tets.region_labels, dtype=np.int64)
        )
        order = np.argsort(labels, kind="stable")
        if (np.diff(labels) < 0).any():
            report(f"{tets.label}: tetrahedra are reordered to group them by region (TVOLUME)")
        cells, labels = cells[order], labels[order]
        n_parts = tets.n_regions
        starts = part_vertex_ranges(tets.n_points, cells, labels, n_parts)
        vw = self.vertex_writer(tets, chosen, z_sign)
        cell_values = value_columns(cell_chosen, tets.n_cells)[order] if cell_chosen else None
        ctetra = self._ctetra_lines(tets, order, labels)
        bounds = np.searchsorted(labels, np.arange(n_parts + 1))
        names = tets.region_names or tuple(str(k) for k in range(n_parts))
        for part in range(n_parts):
            name = names[part]
            out.add(f"TVOLUME {name}".rstrip() if name != str(part) else "TVOLUME")
            out.add_pieces(vw.lines(int(starts[part]), int(starts[part + 1])))
            lo, hi = int(bounds[part]), int(bounds[part + 1])
            values = cell_values[lo:hi] if cell_values is not None else None
            text = format_rows(b"TETRA", cells[lo:hi] + 1, values)
            if ctetra is not None and text:
                rows = text.split(b"\n")
                text = b"\n".join(r + b"\n" + c for r, c in zip(rows, ctetra[lo:hi], strict=True))
            out.add_bytes(text)
        self._tsolid_model(out, tets)
        self.tail(out, tets)
        return out.text()

    def _ctetra_lines(
        self, tets: TetMesh, order: NDArray[np.int64], labels: NDArray[np.int64]
    ) -> list[bytes] | None:
        prop = tets.cell_data.get(CTETRA_PROPERTY)
        if prop is None:
            return None
        codes = np.asarray(prop.values, dtype=np.int64).reshape(-1, 4)[order]
        surfaces = [str(s) for s in gocad_section(prop.metadata).get("surfaces", [])]
        names = tets.region_names or tuple(str(k) for k in range(tets.n_regions))
        region_override = dict(gocad_metadata(tets).get("ctetra_regions") or [])
        inverse = np.empty_like(order)
        inverse[order] = np.arange(order.shape[0])
        lines = []
        for row, (label, faces) in enumerate(zip(labels.tolist(), codes.tolist(), strict=True)):
            region = region_override.get(int(order[row]), names[label])
            entries = []
            for code in faces:
                if code == 0 or abs(code) > len(surfaces):
                    entries.append("none")
                else:
                    entries.append(("+" if code > 0 else "-") + surfaces[abs(code) - 1])
            lines.append(f"# CTETRA {region} {' '.join(entries)}".encode())
        return lines

    def _tsolid_model(self, out: ObjectText, tets: TetMesh) -> None:
        members = [
            s
            for s in self.scene.surfaces
            if gocad_metadata(s).get("tsolid") == tets.id
            and gocad_metadata(s).get("type") == "TSolid.SURFACE"
        ]
        regions = gocad_metadata(tets).get("model_regions") or []
        if not members and not regions:
            return
        bits = np.ascontiguousarray(tets.vertices).view(np.int64).reshape(-1, 3)
        lookup = {tuple(row): i for i, row in enumerate(bits.tolist())}
        out.add("MODEL")
        for surface in members:
            meta = gocad_metadata(surface)
            sbits = np.ascontiguousarray(surface.vertices).view(np.int64).reshape(-1, 3)
            kept = np.asarray(meta.get("tsolid_vertices") or [], dtype=np.int64)
            if (
                kept.shape[0] == surface.n_vertices
                and (kept >= 0).all()
                and (kept < tets.n_points).all()
                and np.array_equal(bits[kept], sbits)
            ):
                mapping = kept
            else:
                try:
                    mapping = np.array([lookup[tuple(r)] for r in sbits.tolist()], dtype=np.int64)
                except KeyError:
                    report(
                        f"{surface.label}: its vertices are not vertices of {tets.label}; skipped"
                    )
                    continue
            out.add(f"SURFACE {quote_rest(surface.name)}")
            ids = meta.get("tface_ids") or []
            keys = meta.get("key_triangles") or []
            for label in range(surface.n_patches):
                faces = surface.patch_faces(label)
                tface = ids[label] if label < len(ids) else label + 1
                out.add(f"TFACE {tface}")
                key = keys[label] if label < len(keys) else None
                if key is None and faces.size:
                    key = int(faces[0])
                if key is not None and 0 <= key < surface.n_faces:
                    a, b, c = (mapping[surface.faces[key]] + 1).tolist()[:3]
                    out.add(f"KEYVERTICES {a} {b} {c}")
                out.add_pieces(row_pieces(b"TRGL", mapping[surface.faces[faces]] + 1, None))
        for name, signed in regions:
            out.add(f"MODEL_REGION {name} {int(signed):+d}")

    # -- Model3d --------------------------------------------------------------------------------
    def model3d(self) -> bytes:
        scene = self.scene
        patch_of = {(p.surface, p.label): p for p in scene.topology.patches}
        surfaces = [
            s
            for s in scene.surfaces
            if any((int(s.id or 0), k) in patch_of for k in range(s.n_patches))
        ] or list(scene.surfaces)
        names = _unique_names([_model_name(s) for s in surfaces])
        ordered = self._tface_order(surfaces, patch_of)
        out = ObjectText()
        model_meta = gocad_section(scene.metadata).get("model3d") or {}
        out.add(f"GOCAD Model3d {model_meta.get('version', '1')}")
        out.add(*header_lines("Model3d", scene.name, model_meta, None))
        out.add(*crs_block(scene.crs))
        for name in names:
            out.add(f"TSURF {quote_rest(name)}")
        name_of = {int(s.id or 0): n for s, n in zip(surfaces, names, strict=True)}
        tfaces = _TFaceLines(patch_of, name_of, z_sign_of(scene.crs))
        for number, (surface, label) in enumerate(ordered, start=1):
            tfaces.add(out, number, surface, label)
        blocks = list(scene.of_type(Block))
        region_of = _region_ids(blocks, len(ordered) + 1)
        for block in blocks:
            _region_lines(out, block, region_of[int(block.id or 0)], tfaces)
        self._model_lists(out, region_of, tfaces.tface_of, blocks)
        out.add("END")  # unparsed header lines were reported on reading and are not written
        pieces = [out.text()]
        for surface in scene.surfaces:  # scene order; surfaces outside the model too
            # a TSolid's SURFACEs too: the TSolid itself is not written in a Model3d
            member = name_of.get(int(surface.id or 0))
            extra = (("name_in_model_list", member),) if member is not None else ()
            tface_type = tfaces.type_of.get(int(surface.id or 0))
            pieces.append(self.tsurf(surface, extra, tface_type, in_model=True))
        skipped = [e.label for e in scene.entities if not isinstance(e, Surface | Block)]
        if skipped:
            report(f"a Model3d holds surfaces and regions only; not written: {', '.join(skipped)}")
        return b"".join(pieces)

    def _tface_order(
        self, surfaces: list[Surface], patch_of: dict[tuple[int, int], Patch]
    ) -> list[tuple[Surface, int]]:
        """``(surface, patch label)`` of each header TFACE: in patch-id order, each surface's
        labels increasing (a patch without triangles is no TFACE)."""
        written = {int(s.id or 0): _written_labels(s).tolist() for s in surfaces}
        for empty in self.scene.topology.patches:
            if empty.label not in written.get(empty.surface, [empty.label]):
                report(f"patch {empty.id} has no triangle: no TFACE is written for it")
        entries = [(s, k) for s in surfaces for k in written[int(s.id or 0)]]
        big = 1 << 62
        entries.sort(
            key=lambda e: (
                patch_of[(int(e[0].id or 0), e[1])].id
                if (int(e[0].id or 0), e[1]) in patch_of
                else big
            )
        )
        slots: dict[int, list[int]] = {}
        for position, (s, _) in enumerate(entries):
            slots.setdefault(int(s.id or 0), []).append(position)
        ordered: list[tuple[Surface, int]] = [entries[0]] * len(entries) if entries else []
        for s in surfaces:
            labels = written[int(s.id or 0)]
            for k, position in enumerate(slots.get(int(s.id or 0), [])):
                ordered[position] = (s, labels[k])
        return ordered

    def _model_lists(
        self,
        out: ObjectText,
        region_of: dict[int, int],
        tface_of: dict[int, int],
        blocks: list[Block],
    ) -> None:
        keyword_of = {
            "layer": "LAYER",
            "fault_block": "FAULT_BLOCK",
            "feature": "SURFACE",
            "fault": "FAULT",
            "boundary": "BOUNDARY",
            "unit": "UNIT",
        }
        groups = [g for root in self.scene.groups for g in root.walk() if g.kind in keyword_of]
        by_surface: dict[int, list[int]] = {}
        for patch in self.scene.topology.patches:
            if patch.id in tface_of:
                by_surface.setdefault(patch.surface, []).append(tface_of[patch.id])
        if not any(g.kind == "layer" for g in groups):
            units: dict[str, list[int]] = {}
            for block in blocks:
                if block.unit_name and not block.is_universe:
                    units.setdefault(block.unit_name, []).append(region_of[int(block.id or 0)])
            for name, regions in units.items():
                out.add(f"LAYER {quote_rest(name)}")
                out.add(*_id_lines([str(r) for r in regions]))
        for group in groups:
            keyword = keyword_of[str(group.kind)]
            raw = gocad_section(group.metadata)
            if keyword in ("LAYER", "FAULT_BLOCK"):
                # the REGIONs of its blocks still written; of the source's list, the ids that
                # named no REGION there are kept, a dropped block's are not
                ids = [region_of[m] for m in group.members if m in region_of]
                kept = raw.get("regions")
                unmatched = raw.get("unmatched")
                if isinstance(kept, list) and isinstance(unmatched, list):
                    stay = set(ids) | set(unmatched)
                    if [i for i in kept if i in region_of.values()] == ids:
                        ids = [i for i in kept if i in stay]
                elif isinstance(kept, list) and [i for i in kept if i in region_of.values()] == ids:
                    ids = kept  # a scene from before "unmatched" was recorded
            else:
                ids = [t for m in group.members for t in by_surface.get(m, [])]
                kept = raw.get("tfaces")
                if isinstance(kept, list) and sorted(set(kept)) == sorted(set(ids)):
                    ids = kept
            out.add(
                f"{keyword} {quote_rest(group.name)}"
                if keyword != "SURFACE"
                else f"SURFACE {group.name}"
            )
            out.add(*_id_lines([str(i) for i in ids]))

    # -- groups and dispatch --------------------------------------------------------------------
    def entity(self, entity: Entity) -> bytes | None:
        if isinstance(entity, Surface):
            if gocad_metadata(entity).get("type") == "TSolid.SURFACE":
                return None  # written inside its TSolid's MODEL section
            return self.tsurf(entity)
        if isinstance(entity, PolyLine):
            return self.pline(entity)
        if isinstance(entity, PointSet):
            return self.vset(entity)
        if isinstance(entity, TetMesh):
            return self.tsolid(entity)
        return self.members.text(entity, self.scene.crs)  # a grid or a well: a group member

    def group(self, group: Group, written: set[int]) -> bytes:
        out = ObjectText()
        meta = gocad_section(group.metadata)
        kind = group.kind if group.kind in _GROUP_KINDS else "HeterogeneousGroup"
        out.add(f"GOCAD {kind} {meta.get('version', '1')}")
        out.add(*header_lines(str(kind), group.name, meta, None))
        if "member_type" in meta:
            out.add(f"TYPE {meta['member_type']}")
        out.add("BEGIN_MEMBERS")
        pieces = [out.text()]
        items: list[tuple[int, int | Group]] = [(m, m) for m in group.members]
        for child in group.children:
            ids = [m for g in child.walk() for m in g.members]
            items.append((min(ids) if ids else 1 << 62, child))
        items.sort(key=lambda item: item[0])
        for _, item in items:
            if isinstance(item, Group):
                pieces.append(self.group(item, written))
                continue
            text = self.entity(self.scene.get(item))
            written.add(item)
            if text is not None:
                pieces.append(text)
        pieces.append(b"END_MEMBERS\nEND\n")
        return b"".join(pieces)


class _BorderPlaces:
    """Where one surface's vertices meet the scene's corners and arcs (within ``tolerance``)."""

    def __init__(
        self,
        surface: Surface,
        tolerance: float,
        corner_points: list[NDArray[np.float64]],
        arcs: list[Arc],
    ) -> None:
        from scipy.spatial import cKDTree

        self.surface = surface
        self.arcs = arcs
        self.tolerance = tolerance
        vertices = np.asarray(surface.vertices, dtype=np.float64)
        self.centre = 0.5 * np.add(*column_extremes(vertices))
        self.tree = cKDTree(vertices - self.centre)
        n = surface.n_vertices
        self.is_corner = self._mask(np.asarray(corner_points).reshape(-1, 3), n)
        arc_points = [np.asarray(a.points) for a in arcs]
        self.on_arc = self._mask(np.concatenate(arc_points) if arc_points else np.zeros((0, 3)), n)
        triangles, _ = _triangles(surface)
        pairs = np.sort(triangles[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
        self.edge_keys = np.unique(pairs[:, 0] * n + pairs[:, 1])

    def _near(self, points: NDArray[np.float64]) -> list[list[int]]:
        found: list[list[int]] = self.tree.query_ball_point(
            points - self.centre, r=self.tolerance, return_sorted=True
        ).tolist()
        return found

    def _mask(self, points: NDArray[np.float64], n: int) -> NDArray[np.bool_]:
        mask = np.zeros(n, dtype=np.bool_)
        if points.shape[0]:
            hits = [v for near in self._near(points) for v in near]
            mask[np.asarray(hits, dtype=np.int64)] = True
        return mask

    def _is_edge(self, a: int, b: int) -> bool:
        n = self.surface.n_vertices
        key = min(a, b) * n + max(a, b)
        at = int(np.searchsorted(self.edge_keys, key))
        return at < self.edge_keys.shape[0] and int(self.edge_keys[at]) == key

    def fit(self, bstones: list[int], borders: list[tuple[int, int]]) -> bool:
        """Whether the source's BSTONE/BORDER lines still describe the scene's corners/arcs.

        A BSTONE on an arc must be at a corner (else it would make one); a BORDER must run
        along an arc edge (where it starts does not change the corners a reader finds). A
        surface not read from GOCAD without any gets them.
        """
        if not bstones and not borders:
            return gocad_metadata(self.surface).get("type") == "TSurf"
        if any(self.on_arc[v] and not self.is_corner[v] for v in bstones):
            return False
        return all(self.on_arc[a] and self.on_arc[b] and self._is_edge(a, b) for a, b in borders)

    def derived(self) -> tuple[list[int], list[tuple[int, int]]]:
        """A BSTONE at every corner, a BORDER from one end of every arc, in this surface."""
        near_start = self._near(np.array([a.points[0] for a in self.arcs]).reshape(-1, 3))
        near_next = self._near(np.array([a.points[1] for a in self.arcs]).reshape(-1, 3))
        borders: list[tuple[int, int]] = []
        for starts, nexts in zip(near_start, near_next, strict=True):
            pair = next(((a, b) for a in starts for b in nexts if self._is_edge(a, b)), None)
            if pair is not None:
                borders.append(pair)
        bstones = set(np.flatnonzero(self.is_corner).tolist()) | {a for a, _ in borders}
        return sorted(bstones), borders


class _TFaceLines:
    """Writes a Model3d header's TFACE lines and remembers what each patch became."""

    def __init__(
        self, patch_of: dict[tuple[int, int], Patch], name_of: dict[int, str], z_sign: float
    ) -> None:
        self.patch_of = patch_of
        self.name_of = name_of
        self.z_sign = z_sign
        self.tface_of: dict[int, int] = {}  # patch id -> TFACE number
        self.flipped: dict[int, bool] = {}  # patch id -> key triangle written reversed
        self.type_of: dict[int, str] = {}  # surface id -> geological type of its first TFACE

    def add(self, out: ObjectText, number: int, surface: Surface, label: int) -> None:
        """``TFACE <number> <type> <TSurf>`` and its key triangle (z as the CRS wants it)."""
        sid = int(surface.id or 0)
        patch = self.patch_of.get((sid, label))
        pmeta = gocad_section(patch.metadata) if patch is not None else {}
        geo_type = pmeta.get("geological_type") or _surface_type(surface)
        self.type_of.setdefault(sid, str(geo_type))
        out.add(f"TFACE {number}  {geo_type} {quote_rest(self.name_of[sid])}")
        faces = surface.patch_faces(label)  # never empty: empty patches are not written
        key = pmeta.get("key_triangle")
        if not (isinstance(key, int) and key in set(faces.tolist())):
            key = int(faces[0])
        corners = np.array(surface.vertices[surface.faces[key][:3]], dtype=np.float64)
        reverse = bool(pmeta.get("key_reversed"))
        if reverse:
            corners = corners[::-1]
        corners[:, 2] *= self.z_sign
        for point in corners.tolist():
            out.add("  " + " ".join(format_float(c) for c in point))
        if patch is not None:
            self.tface_of[patch.id] = number
            self.flipped[patch.id] = reverse


def _region_ids(blocks: list[Block], first_region: int) -> dict[int, int]:
    """REGION id of each block (by block id): the source's when still valid, else numbered
    after the TFACEs."""
    region_of = {int(b.id or 0): first_region + offset for offset, b in enumerate(blocks)}
    kept = [gocad_metadata(b).get("region_id") for b in blocks]
    valid = [k for k in kept if isinstance(k, int) and k >= first_region]
    if len(valid) == len(kept) and len(set(valid)) == len(valid):
        region_of = {int(b.id or 0): k for b, k in zip(blocks, valid, strict=True)}
    return region_of


def _region_lines(out: ObjectText, block: Block, region_id: int, tfaces: _TFaceLines) -> None:
    """``REGION <id> <name>`` and its signed TFACE numbers."""
    values = []
    for patch_id, side in block.sides:
        if patch_id not in tfaces.tface_of:
            report(f"{block.label}: patch {patch_id} has no TFACE; left out of its REGION")
            continue
        sign = -side if tfaces.flipped.get(patch_id) else side
        values.append(sign * tfaces.tface_of[patch_id])
    name = "Universe" if block.is_universe else (block.name or f"region_{block.id}")
    out.add(f"REGION {region_id}  {quote_rest(name)}")
    out.add(*_id_lines([f"{v:+d}" for v in values]))


def _written_labels(surface: Surface) -> NDArray[np.int64]:
    """The patch labels that have triangles, ascending (one TFACE each)."""
    if surface.n_faces == 0:
        return np.zeros(0, dtype=np.int64)
    if surface.patch_labels is None:
        return np.zeros(1, dtype=np.int64)
    return np.unique(np.asarray(surface.patch_labels, dtype=np.int64))


def _kind_header(surface: Surface, tface_type: str | None) -> tuple[tuple[str, str], ...]:
    """``geobrep_kind`` when the GOCAD type written for ``surface`` does not say its kind."""
    from geobrep.adapters.gocad._reader import kind_of

    if surface.kind is None:
        return ()
    geology = gocad_metadata(surface).get("geology") or {}
    written = geology.get("GEOLOGICAL_TYPE")
    if written is None:
        written = tface_type if tface_type is not None else _TYPE_OF_KIND.get(surface.kind)
    if kind_of(written) == surface.kind:
        return ()
    return ((KIND_KEY, surface.kind),)


def _model_name(surface: Surface) -> str:
    """The TSURF name: the source's ``name_in_model_list``, else the entity name."""
    for key, value in gocad_metadata(surface).get("header", []):
        if key == "name_in_model_list" and str(value).strip():
            return " ".join(str(value).split())
    return " ".join(surface.name.split()) or f"surface_{surface.id}"


def _surface_type(surface: Surface) -> str:
    geology = gocad_metadata(surface).get("geology") or {}
    if "GEOLOGICAL_TYPE" in geology:
        return str(geology["GEOLOGICAL_TYPE"])
    return {"fault": "fault", "horizon": "top", "boundary": "boundary"}.get(
        str(surface.kind), "none"
    )


def _unique_names(names: list[str]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for name in names:
        if name in seen:
            seen[name] += 1
            new = f"{name}_{seen[name]}"
            report(f"TSurf name {name!r} is used twice; the second is written as {new!r}")
            out.append(new)
        else:
            seen[name] = 0
            out.append(name)
    return out


def _id_lines(values: list[str]) -> list[str]:
    """Ids five per line, the list ended by 0."""
    values = [*values, "0"]
    return ["  " + "  ".join(values[i : i + 5]) for i in range(0, len(values), 5)]


def _patch_vertices(surface: Surface) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
    """The sorted ``patch label * n_vertices + vertex`` keys of the vertices each patch uses
    and each face corner's index among them; None when no vertex is used by two patches."""
    faces = np.asarray(surface.faces, dtype=np.int64)
    n = surface.n_vertices
    if surface.patch_labels is None or faces.shape[0] == 0 or n == 0:
        return None
    labels = np.asarray(surface.patch_labels, dtype=np.int64)
    keys = (labels[:, None] * n + faces).ravel()
    unique_keys, corners = np.unique(keys, return_inverse=True)
    if unique_keys.shape[0] == np.unique(unique_keys % n).shape[0]:
        return None
    return unique_keys, corners.reshape(faces.shape)


def tface_copies_sentence(surface: Surface, n_points: int) -> str:
    """What writing ``surface`` with a vertex of its own in each TFACE does to it: ``n_points``
    points read back (the format's losses and the writer's warning say it alike)."""
    return (
        f"{surface.label}: {n_points - surface.n_vertices} copies of vertices its patches share "
        "are written, one in each TFACE that uses them (ATOM lines, as GOCAD writes a Model3d; "
        f"tface_vertices='shared' writes each once): {n_points} points read back"
    )


def model3d_copies(scene: Scene) -> list[str]:
    """:func:`tface_copies_sentence` of each surface a Model3d write gives copies to."""
    sentences = []
    for surface in scene.surfaces:
        split = _patch_vertices(surface)
        if split is not None:  # copies + the vertices no triangle uses
            used = np.unique(split[0] % surface.n_vertices).shape[0]
            n_points = split[0].shape[0] + surface.n_vertices - used
            sentences.append(tface_copies_sentence(surface, n_points))
    return sentences


def _own_tface_vertices(surface: Surface) -> Surface:
    """``surface`` with a vertex of its own in each patch (TFACE) that uses it.

    GOCAD writes a Model3d member so, carrying a vertex an earlier TFACE declared into the next
    as an ``ATOM`` line (an exact duplicate, which the vertex writer turns into ``ATOM``), and
    the Model3d readers of OpenGeode-GeosciencesIO and RINGMesh need it: they build each TFACE
    from its own vertex range (OpenGeode-GeosciencesIO crashed on triangles that use an
    earlier TFACE's vertex). The vertices of each patch keep their order; vertices no triangle
    uses come last; BSTONEs and BORDERs read from a file follow their vertex into every copy.
    The surface itself is returned when no vertex is used by two patches.
    """
    split = _patch_vertices(surface)
    if split is None:
        return surface  # each vertex is in one patch already
    unique_keys, new_faces = split
    n = surface.n_vertices
    copied = unique_keys % n
    used = np.zeros(n, dtype=np.bool_)
    used[copied] = True
    source = np.concatenate([copied, np.flatnonzero(~used)])
    report(tface_copies_sentence(surface, source.shape[0]))
    changes: dict[str, Any] = {
        "vertices": np.asarray(surface.vertices)[source],
        "faces": new_faces,
        "point_data": surface.point_data.take(source),
    }
    meta = gocad_metadata(surface)
    if meta.get("bstones") or meta.get("borders"):
        order = np.argsort(source, kind="stable")
        ranked = source[order]
        part_of = np.concatenate([unique_keys // n, np.full(source.shape[0] - copied.shape[0], -1)])

        def copies(vertex: int) -> list[int]:
            low, high = np.searchsorted(ranked, [vertex, vertex + 1])
            found: list[int] = order[low:high].tolist()
            return found

        bstones = [c for v in meta.get("bstones", []) if 0 <= int(v) < n for c in copies(int(v))]
        borders = [
            [a2, b2]
            for a, b in meta.get("borders", [])
            if 0 <= int(a) < n and 0 <= int(b) < n
            for a2 in copies(int(a))
            for b2 in copies(int(b))
            if part_of[a2] == part_of[b2]
        ]
        gocad = {**meta, "bstones": bstones, "borders": borders}
        changes["metadata"] = {**surface.metadata, "gocad": gocad}
    return surface.replace(**changes)


def _triangles(surface: Surface) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    faces = np.asarray(surface.faces, dtype=np.int64)
    if faces.shape[1] == 3:
        return faces, np.arange(faces.shape[0], dtype=np.int64)
    triangles = np.stack([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
    return triangles, np.repeat(np.arange(faces.shape[0], dtype=np.int64), 2)


def write_gocad(scene: Scene, path: Path, options: GocadOptions | None = None) -> None:
    """Write ``scene`` to ``path`` as GOCAD ASCII (the caller makes the write atomic)."""
    options = options or GocadOptions()
    target = Path(path)
    object_type = options.object_type or OBJECT_TYPES.get(target.suffix.lower())
    if object_type is None:
        raise FormatError(
            "cannot tell the GOCAD object type from the extension: use object_type=", target
        )
    writer = _Writer(scene, target, options)
    pieces: list[bytes] = []
    if object_type == "Model3d":
        pieces.append(writer.model3d())
    elif object_type in _GROUP_KINDS:
        written: set[int] = set()
        roots = [g for g in scene.groups if g.kind in _GROUP_KINDS]
        if not roots:
            roots = [
                Group(
                    name=scene.name or "group",
                    kind=object_type,
                    members=tuple(
                        int(e.id or 0) for e in scene.entities if not isinstance(e, Block)
                    ),
                )
            ]
        for root in roots:
            pieces.append(writer.group(root, written))
        rest = [
            e for e in scene.entities if int(e.id or 0) not in written and not isinstance(e, Block)
        ]
        for entity in rest:
            text = writer.entity(entity)
            if text is not None:
                pieces.append(text)
    else:
        wanted = _ENTITY_OF.get(object_type)
        if wanted is None:
            raise FormatError(f"unknown GOCAD object type {object_type!r}", target)
        for item in scene.entities:
            if isinstance(item, wanted):
                # a TSolid's SURFACEs are TSurfs of their own when the TSolid is not written
                text = writer.tsurf(item) if isinstance(item, Surface) else writer.entity(item)
                if text is not None:
                    pieces.append(text)
        others = [
            e.label
            for e in scene.entities
            if not isinstance(e, wanted)
            and not (
                isinstance(e, Surface)
                and gocad_metadata(e).get("type") == "TSolid.SURFACE"
                and wanted is TetMesh
            )
        ]
        if others:
            report(
                f"a {object_type} file holds {wanted.__name__} entities only; "
                f"not written: {', '.join(others[:10])}" + (" ..." if len(others) > 10 else "")
            )
        if not pieces:
            raise FormatError(
                f"the scene has no {wanted.__name__} to write as {object_type}", target
            )
        if scene.topology.patches and object_type == "TSurf" and scene.blocks:
            report("blocks (REGIONs) need a Model3d (.ml) file; a .ts holds the surfaces only")
    with target.open("wb") as handle:
        for piece in pieces:
            handle.write(piece)
