"""Turn parsed GOCAD objects into a geobrep :class:`~geobrep.Scene`.

* TSurf → :class:`Surface` with one patch per TFACE; PLine → :class:`PolyLine` with one part per
  ILINE (split where its SEGs do not chain); VSet → :class:`PointSet`; TSolid / LightTSolid →
  :class:`TetMesh` with one region per TVOLUME, or, without TVOLUMEs, per volume enclosed by the
  faces ``# CTETRA`` and the MODEL triangles put on surfaces, named by MODEL_REGION seeds (plus
  one :class:`Surface` per SURFACE of its MODEL section); Model3d → its member TSurfs,
  ``scene.topology`` (one patch per TFACE) and a :class:`Block` per REGION; groups →
  :class:`~geobrep.model.scene.Group` s.
* ``ZPOSITIVE Depth`` negates z (triangle winding is kept); the scene's CRS records it.
* Everything else the file says is kept in ``metadata["gocad"]`` so that a writer can restore it.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._checks import bad_triangles, borders_on_patch_borders
from geobrep.adapters.gocad._headers import PropertyHeader, color_from_text
from geobrep.adapters.gocad._lexer import Source
from geobrep.adapters.gocad._objects import gocad_section
from geobrep.adapters.gocad._parser import GROUP_TYPES, GocadObject, GocadWarning, parse_source
from geobrep.adapters.gocad._records import CrsBlock, ErrorFactory
from geobrep.adapters.gocad._regions import TetFaces, root_vertices
from geobrep.adapters.gocad._tables import IdLookup, ResolvedVertices
from geobrep.adapters.gocad.options import GocadOptions
from geobrep.errors import EntityValidationError, FormatError, TopologyError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.arrays import as_readonly
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface
from geobrep.model.properties import Property, PropertyMap
from geobrep.model.scene import Group, Scene

if TYPE_CHECKING:
    from geobrep.adapters.gocad._model_records import SolidSurface  # a TSolid read only
    from geobrep.model.arcs import JoinedPatches

__all__ = ["FLAG_PROPERTY", "GocadReadOptions", "crs_from_block", "read_gocad"]

#: Point property holding per-vertex GOCAD flags (1 = CNXYZ, 2 = XYZ) when a file has any.
FLAG_PROPERTY = "gocad_vertex_flag"
#: Cell property of a TSolid holding its ``# CTETRA`` face codes (0: none, ±(k+1): surface k).
CTETRA_PROPERTY = "gocad_ctetra_faces"
#: Point property with the file's vertex ids (reader option ``vertex_ids=True``).
VERTEX_ID_PROPERTY = "gocad_vertex_id"

_COLOR_KEYS = ("*solid*color", "*line*color", "*atoms*color", "color")
_KIND_OF_TYPE = {
    "top": "horizon",
    "none": "horizon",
    "topographic": "horizon",
    "unconformity": "unconformity",
    "boundary": "boundary",
    "lease": "boundary",
    "intrusive": "intrusion",
}


GocadReadOptions = GocadOptions


class _EntityFields(TypedDict):
    """The fields every entity read from a GOCAD object gets."""

    id: int
    name: str
    kind: str | None
    metadata: dict[str, Any]  # JSON: "gocad" (what a writer restores) and "color"


def kind_of(geological_type: str | None) -> str | None:
    """geobrep ``kind`` for a GOCAD GEOLOGICAL_TYPE (``*fault`` → ``fault``, ``top`` → horizon)."""
    if geological_type is None:
        return None
    lowered = geological_type.lower()
    if "fault" in lowered:
        return "fault"
    return _KIND_OF_TYPE.get(lowered, lowered)


def crs_from_block(block: CrsBlock) -> CRS:
    """A :class:`CRS` from a parsed ``GOCAD_ORIGINAL_COORDINATE_SYSTEM`` block."""
    extra = {
        key.lower(): value
        for key, value in block.items()
        if key not in ("NAME", "AXIS_NAME", "AXIS_UNIT", "ZPOSITIVE")
    }
    name = block.get("NAME")
    return CRS(
        name=name if isinstance(name, str) else None,
        axis_names=tuple(block.get("AXIS_NAME", ("X", "Y", "Z"))),
        axis_units=tuple(block.get("AXIS_UNIT", ("m", "m", "m"))),
        z_positive="down" if block.get("ZPOSITIVE") == "Depth" else "up",
        metadata={"gocad": extra} if extra else {},
    )


def _properties(
    header: PropertyHeader,
    values: NDArray[np.float64],
    class_headers: dict[str, dict[str, str]],
    where: str,
    error: ErrorFactory,
) -> dict[str, Property]:
    out: dict[str, Property] = {}
    column = 0
    for spec in header.specs:
        block = values[:, column : column + spec.esize]
        column += spec.esize
        data = block[:, 0] if spec.esize == 1 else block
        name = spec.name
        if name in out or name in (FLAG_PROPERTY, CTETRA_PROPERTY, VERTEX_ID_PROPERTY):
            renamed = f"{name}_{len(out)}"
            warnings.warn(f"{where}: property {name!r} renamed {renamed!r}", GocadWarning, 3)
            name = renamed
        metadata: dict[str, Any] = {"gocad": spec.metadata()} if spec.metadata() else {}
        out[name] = Property(
            values=np.ascontiguousarray(data),
            unit=spec.unit,
            no_data_value=spec.no_data,
            metadata=metadata,
        )
    return out


class _Builder:
    def __init__(self, source: Source, options: GocadReadOptions) -> None:
        self.source = source
        self.options = options
        self.path = source.path
        self.entities: list[Entity] = []
        self.scene_crs: CrsBlock | None = None
        self._scene_crs_model: CRS | None = None
        self._tface_types: dict[str, str] = {}
        """TSurf name -> the type of its first header TFACE in the Model3d (see
        :meth:`_kinds_from_model`), for TSurfs to take when they are made."""
        self.surface_of_object: dict[int, int] = {}
        self.skipped: list[str] = []

    def error(self, message: str, line: int | None) -> FormatError:
        return FormatError(message, self.path, line)

    def warn(self, message: str, line: int | None = None) -> None:
        where = f"{self.path.name}:{line}: " if line is not None else f"{self.path.name}: "
        warnings.warn(where + message, GocadWarning, stacklevel=4)

    def next_id(self) -> int:
        return len(self.entities)

    # -- the whole file -----------------------------------------------------------------------
    def build(self, objects: list[GocadObject]) -> Scene:
        self.scene_crs = _first_crs(objects)
        self._tface_types = _tface_types(objects)
        groups: list[Group] = []
        models: list[GocadObject] = []
        for obj in objects:
            group = self.add_object(obj, None, models)
            if group is not None:
                groups.append(group)
        crs = self._scene_crs() if self.scene_crs is not None else None
        surfaces = [e for e in self.entities if isinstance(e, Surface)]
        topology = None
        joined: JoinedPatches | None = None
        blocks: list[Entity] = []
        model_groups: list[Group] = []
        name = objects[0].name
        metadata: dict[str, Any] = {}
        if models:
            from geobrep.adapters.gocad._model3d import attach_model3d  # Model3d files only

            if len(models) > 1:
                self.warn(
                    f"{len(models)} Model3d objects: only the first with TFACEs defines "
                    "the topology"
                )
            model = next((m for m in models if m.model3d.tfaces), models[0])
            name = model.name
            self._kinds_from_model(model)
            surfaces = [e for e in self.entities if isinstance(e, Surface)]
            topology, blocks, model_groups, metadata, surfaces, joined = attach_model3d(
                model, surfaces, self.next_id(), self._z_sign(model), self.options, self
            )
            by_id = {int(s.id or 0): s for s in surfaces}
            self.entities = [by_id.get(int(e.id or 0), e) for e in self.entities]
        elif any(gocad_section(e.metadata).get("borders") for e in surfaces):
            from geobrep.adapters.gocad._model3d import border_topology

            topology = border_topology(surfaces, self.options, self.warn)
        try:
            scene = Scene.from_validated(  # the parts are validated models already
                entities=[*self.entities, *blocks],
                groups=[*groups, *model_groups],
                crs=crs,
                topology=topology,
                name=name,
                metadata=metadata,
            )
        except (EntityValidationError, TopologyError) as exc:
            raise self.error(f"the file's objects do not form a valid scene: {exc}", None) from exc
        if blocks and self.options.repair:
            scene = self._orient_blocks(scene, joined)
        return scene

    def _scene_crs(self) -> CRS:
        """The CRS of :attr:`scene_crs` (made once)."""
        assert self.scene_crs is not None
        if self._scene_crs_model is None:
            self._scene_crs_model = crs_from_block(self.scene_crs)
        return self._scene_crs_model

    def _orient_blocks(self, scene: Scene, joined: JoinedPatches | None) -> Scene:
        """REGION sides reversed where the geometry contradicts them (one warning each)."""
        from geobrep.model.orientation import orient_blocks  # a model with blocks only

        try:
            scene, notes = orient_blocks(scene, joined)
        except TopologyError as exc:
            raise self.error(
                f"{exc} (read with repair=False to load the model as written)", None
            ) from exc
        for note in notes:
            self.warn(note)
        return scene

    def _kinds_from_model(self, model: GocadObject) -> None:
        """Surfaces without a GEOLOGICAL_TYPE take the type of their header TFACEs."""
        types: dict[str, str] = {}
        for entry in model.model3d.tfaces:
            types.setdefault(entry.tsurf, entry.type)
        for index, entity in enumerate(self.entities):
            if not isinstance(entity, Surface) or entity.kind is not None:
                continue
            names = [entity.name]
            for key, value in gocad_section(entity.metadata).get("header", []):
                if key == "name_in_model_list":
                    names.insert(0, str(value))
            found = next((types[n] for n in names if n in types), None)
            if found is not None:
                self.entities[index] = entity.replace(kind=kind_of(found))

    def add_object(
        self, obj: GocadObject, parent_crs: CrsBlock | None, models: list[GocadObject]
    ) -> Group | None:
        if obj.crs is None and parent_crs is not None:
            obj = replace(obj, crs=dict(parent_crs), inherited_crs=True)
        if obj.type in GROUP_TYPES:
            start = self.next_id()
            children = []
            members: list[int] = []
            for member in obj.members:
                before = self.next_id()
                child = self.add_object(member, obj.crs, models)
                if child is not None:
                    children.append(child)
                members.extend(range(before, self.next_id()))
            direct = [
                m for m in members if not any(m in c.members for g in children for c in g.walk())
            ]
            return Group(
                name=obj.name,
                kind=obj.type,
                members=tuple(direct),
                children=tuple(children),
                metadata={"gocad": self._object_metadata(obj, start)},
            )
        if obj.type == "Model3d":
            models.append(obj)
            return None
        if obj.grid is not None:  # a Voxet, SGrid or Well member, read by its own reader
            self.entities.append(obj.grid.replace(id=self.next_id()))
            return None
        try:
            self._add_entity(obj)
        except EntityValidationError as exc:
            raise self.error(f"{obj.type} {obj.name!r}: {exc}", obj.line) from exc
        return None

    def _z_sign(self, obj: GocadObject) -> float:
        return -1.0 if obj.crs is not None and obj.crs.get("ZPOSITIVE") == "Depth" else 1.0

    def _object_metadata(self, obj: GocadObject, _: int = 0) -> dict[str, Any]:
        meta: dict[str, Any] = {"type": obj.type, "version": obj.version}
        meta["header"] = [[k, v] for k, v in obj.header]
        if (
            obj.crs is not None
            and not obj.inherited_crs
            and (
                self.scene_crs is None
                # equal blocks (text only) make equal CRSs: built only when they differ
                or (obj.crs != self.scene_crs and crs_from_block(obj.crs) != self._scene_crs())
            )
        ):
            meta["crs"] = obj.crs
        if obj.crs is None and self.scene_crs is not None:
            meta["crs"] = None
        if obj.geology:
            meta["geology"] = obj.geology
        if obj.class_headers:
            meta["class_headers"] = obj.class_headers
        if obj.extra_lines:
            meta["extra_lines"] = obj.extra_lines
        if obj.member_type is not None:
            meta["member_type"] = obj.member_type
        return meta

    def _common_fields(self, obj: GocadObject) -> _EntityFields:
        metadata: dict[str, Any] = {"gocad": self._object_metadata(obj)}
        for key in _COLOR_KEYS:
            value = obj.header_value(key)
            if value is not None:
                color = color_from_text(value)
                if color is not None:
                    metadata["color"] = color
                break
        geo_type = obj.geology.get("GEOLOGICAL_TYPE")
        geo_type = geo_type if isinstance(geo_type, str) else None
        kind = obj.header_value("geobrep_kind") or kind_of(geo_type)  # kinds GOCAD has no type for
        return {"id": self.next_id(), "name": obj.name, "kind": kind, "metadata": metadata}

    # -- one object -----------------------------------------------------------------------------
    def _add_entity(self, obj: GocadObject) -> None:
        vertices = obj.vertices
        assert vertices is not None
        xyz = vertices.xyz
        if self._z_sign(obj) < 0 and xyz.size:
            xyz = xyz.copy()
            xyz[:, 2] = -xyz[:, 2]
        where = f"{self.path.name}:{obj.line}"
        if not np.isfinite(xyz).all():
            row = int(np.argmax(~np.isfinite(xyz).all(axis=1)))
            raise self.error("vertex coordinates must be finite numbers", int(vertices.lines[row]))
        point_data = _properties(
            obj.point_header, vertices.values, obj.class_headers, where, self.error
        )
        if vertices.flags.any():
            point_data[FLAG_PROPERTY] = Property(
                values=vertices.flags.astype(np.int8),
                description="GOCAD vertex flags",
                metadata={"gocad": {"codes": {"1": "CNXYZ", "2": "XYZ"}}},
            )
        if self.options.vertex_ids:
            point_data[VERTEX_ID_PROPERTY] = Property(
                values=vertices.ids, description="vertex ids of the GOCAD file"
            )
        fields = self._common_fields(obj)
        lookup = vertices.lookup
        cells = obj.cells
        if obj.type == "VSet":
            if obj.part_vertex_starts:
                fields["metadata"]["gocad"]["subvset_starts"] = list(obj.part_vertex_starts)
            self.entities.append(PointSet(vertices=xyz, point_data=point_data, **fields))
            return
        assert cells is not None
        ids, values, parts, lines = cells
        keyword = {"TSurf": "TRGL", "PLine": "SEG"}.get(obj.type, "TETRA")
        index = lookup.require(ids, lines, keyword, self.error)
        cell_data = _properties(obj.cell_header, values, obj.class_headers, where, self.error)
        names = tuple(name or str(i) for i, name in enumerate(obj.part_names))
        if obj.type == "TSurf":
            if fields["kind"] is None and self._tface_types:  # as _kinds_from_model gives it
                called = [obj.name]
                for key, value in obj.header:
                    if key == "name_in_model_list":
                        called.insert(0, str(value))
                types = self._tface_types
                found = next((types[n] for n in called if n in types), None)
                if found is not None:
                    fields["kind"] = kind_of(found)
            self._warn_empty_tfaces(obj, parts)
            self._warn_bad_triangles(obj, xyz, index, lines)
            self._hints(obj, lookup, fields)
            self._warn_inner_borders(obj, index, parts, fields)
            self.entities.append(
                _surface(xyz, index, parts, names or ("0",), point_data, cell_data, fields)
            )
        elif obj.type == "PLine":
            self.entities.append(
                self._polyline(obj, xyz, index, parts, point_data, cell_data, fields)
            )
        else:
            self._tsolid(
                obj, xyz, index, parts, names, point_data, cell_data, fields, lookup, vertices
            )

    def _warn_empty_tfaces(self, obj: GocadObject, parts: NDArray[np.int64]) -> None:
        """One warning per TFACE without triangles: a writer writes no TFACE for an empty patch
        (except the one TFACE of a surface without any triangle), so it does not come back."""
        n_parts = len(obj.part_names)
        if n_parts <= 1 and parts.size == 0:
            return
        counts = np.bincount(parts, minlength=n_parts)
        for label in np.flatnonzero(counts == 0).tolist():
            self.warn(
                f"TSurf {obj.name!r}: TFACE {label + 1} has no triangles (an empty patch, "
                "which is not written back)",
                obj.part_lines[label],
            )

    def _warn_bad_triangles(
        self,
        obj: GocadObject,
        xyz: NDArray[np.float64],
        faces: NDArray[np.int64],
        lines: NDArray[np.int64],
    ) -> None:
        """One warning per TSurf with duplicated triangles (the three vertices of an earlier
        TRGL, in any order) or zero-area ones (a repeated vertex, or three collinear points);
        the triangles are kept as read."""
        bad = bad_triangles(xyz, faces)
        if bad is None:
            return
        self.warn(
            f"TSurf {obj.name!r}: {bad.duplicated} duplicated triangle(s) (the same "
            f"three vertices as an earlier TRGL) and {bad.flat} zero-area triangle(s) "
            "(the first on this line); kept as read",
            int(lines[bad.first]),
        )

    def _warn_inner_borders(
        self,
        obj: GocadObject,
        faces: NDArray[np.int64],
        parts: NDArray[np.int64],
        fields: _EntityFields,
    ) -> None:
        """One warning per surface whose BORDERs do not all run along a border edge of its
        TFACEs (an edge of one triangle of a patch): a writer then derives its BSTONE and
        BORDER lines from the corners and arcs, so they need not come back as they were."""
        borders = fields["metadata"]["gocad"].get("borders")
        if not borders:
            return
        on_border = borders_on_patch_borders(faces, parts, np.asarray(borders, dtype=np.int64))
        if on_border.all():
            return
        first = int(np.argmin(on_border))
        self.warn(
            f"TSurf {obj.name!r}: {int((~on_border).sum())} BORDER(s) not along a border edge "
            "of its TFACEs (this one first); BSTONE/BORDER lines are derived from the corners "
            "and arcs when written",
            obj.borders[first].line,
        )

    def _hints(self, obj: GocadObject, lookup: IdLookup, fields: _EntityFields) -> None:
        """BSTONE / BORDER lines as vertex indices in ``metadata["gocad"]``."""
        gocad = fields["metadata"]["gocad"]
        if obj.bstones:
            ids = np.array([b.vertex_id for b in obj.bstones], dtype=np.int64)
            lines = np.array([b.line for b in obj.bstones], dtype=np.int64)
            gocad["bstones"] = lookup.require(ids[:, None], lines, "BSTONE", self.error)[
                :, 0
            ].tolist()
        if obj.borders:
            ids = np.array([[b.v0, b.v1] for b in obj.borders], dtype=np.int64)
            lines = np.array([b.line for b in obj.borders], dtype=np.int64)
            gocad["borders"] = lookup.require(ids, lines, "BORDER", self.error).tolist()

    def _polyline(
        self,
        obj: GocadObject,
        xyz: NDArray[np.float64],
        segments: NDArray[np.int64],
        parts: NDArray[np.int64],
        point_data: dict[str, Property],
        cell_data: dict[str, Property],
        fields: _EntityFields,
    ) -> PolyLine:
        n_seg = segments.shape[0]
        if n_seg == 0:
            indices = np.zeros(0, dtype=np.int64)
            offsets = np.zeros(1, dtype=np.int64)
            closed = np.zeros(0, dtype=bool)
            chain_of_iline = np.zeros(len(obj.part_names), dtype=np.int64)
        else:
            a, b = segments[:, 0], segments[:, 1]
            starts = np.ones(n_seg, dtype=bool)
            starts[1:] = (parts[1:] != parts[:-1]) | (a[1:] != b[:-1])
            chain = np.cumsum(starts) - 1
            first = np.flatnonzero(starts)
            last = np.append(first[1:] - 1, n_seg - 1)
            n_chain = first.shape[0]
            indices = np.empty(n_seg + n_chain, dtype=np.int64)
            indices[np.arange(n_seg) + chain + 1] = b
            indices[first + np.arange(n_chain)] = a[first]
            lengths = last - first + 2
            closed = (b[last] == a[first]) & (lengths >= 4)
            keep = np.ones(indices.shape[0], dtype=bool)
            keep[(last + np.arange(n_chain) + 1)[closed]] = False
            indices = indices[keep]
            lengths = lengths - closed
            offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
            chain_of_iline = np.bincount(parts[first], minlength=len(obj.part_names))
        if len(chain_of_iline) and not (chain_of_iline == 1).all():
            fields["metadata"]["gocad"]["iline_parts"] = chain_of_iline.tolist()
        if obj.part_names and any(obj.part_names):
            fields["metadata"]["gocad"]["iline_names"] = list(obj.part_names)
        return PolyLine(
            vertices=xyz,
            indices=indices,
            part_offsets=offsets,
            closed=closed,
            point_data=point_data,
            cell_data=cell_data,
            **fields,
        )

    def _tsolid(
        self,
        obj: GocadObject,
        xyz: NDArray[np.float64],
        tetra: NDArray[np.int64],
        parts: NDArray[np.int64],
        names: tuple[str, ...],
        point_data: dict[str, Property],
        cell_data: dict[str, Property],
        fields: _EntityFields,
        lookup: IdLookup,
        vertices: ResolvedVertices,
    ) -> None:
        gocad = fields["metadata"]["gocad"]
        model = obj.solid_model
        codes: NDArray[np.int64] | None = None
        ctetra_names: list[tuple[int, str]] = []
        if obj.ctetra:
            codes, surfaces, ctetra_names = _ctetra_codes(obj, tetra.shape[0], self.error)
            cell_data[CTETRA_PROPERTY] = Property(
                values=codes,
                description="GOCAD '# CTETRA' faces: 0 none, +k/-k side of surface k-1",
                metadata={"gocad": {"surfaces": surfaces}},
            )
        if model.regions:
            gocad["model_regions"] = [[r.name, r.signed_tface] for r in model.regions]
        if (codes is not None or model.regions) and tetra.shape[0]:
            faces = TetFaces(tetra, root_vertices(vertices.atom_of))
            seeds = self._seeds(obj, faces, xyz, lookup)
            if not obj.declared_parts:  # no TVOLUME: the regions are what faces and seeds say
                parts, names = self._regions_from_faces(obj, faces, codes, seeds, lookup)
            else:
                self._check_seeds(obj, seeds, parts, names)
        if ctetra_names:
            region_of = np.array([names[p] if p < len(names) else "" for p in parts.tolist()])
            mismatched = [(c, n) for c, n in ctetra_names if n != region_of[c]]
            if mismatched:
                gocad["ctetra_regions"] = [[int(c), str(n)] for c, n in ctetra_names]
                self.warn(
                    f"{len(mismatched)} '# CTETRA' region name(s) differ from the regions of "
                    f"{obj.name!r} (first: tetrahedron {mismatched[0][0]} says "
                    f"{mismatched[0][1]!r}, its region is {region_of[mismatched[0][0]]!r}); "
                    "kept in metadata['gocad']['ctetra_regions']",
                    obj.line,
                )
        from geobrep.model.entities.tetmesh import TetMesh

        tet_id = self.next_id()
        self.entities.append(
            TetMesh(
                vertices=xyz,
                cells=tetra,
                region_labels=parts,
                region_names=names or ("0",),
                point_data=point_data,
                cell_data=cell_data,
                **fields,
            )
        )
        for surface in model.surfaces:
            if not surface.tfaces:
                self.warn(f"MODEL surface {surface.name!r} has no TFACE; skipped", obj.line)
                self.skipped.append(f"MODEL surface {surface.name!r} of {obj.name!r}: no TFACE")
                continue
            self._tsolid_surface(obj, surface, xyz, lookup, tet_id)

    def _seeds(
        self, obj: GocadObject, faces: TetFaces, xyz: NDArray[np.float64], lookup: IdLookup
    ) -> list[tuple[str, int]]:
        """``(name, tetrahedron)`` of each MODEL_REGION whose seed face is found."""
        tfaces = {t.id: t for surface in obj.solid_model.surfaces for t in surface.tfaces}
        found: list[tuple[str, int]] = []
        for region in obj.solid_model.regions:
            name, signed = region.name, region.signed_tface
            tface = tfaces.get(abs(signed))
            what = f"MODEL_REGION {name!r} {signed:+d}"
            if tface is None or tface.key is None or signed == 0:
                self.warn(f"{what}: no TFACE {abs(signed)} with KEYVERTICES; ignored", obj.line)
                continue
            ids, line = tface.key
            key = lookup.require(
                np.asarray([ids], dtype=np.int64), np.asarray([line]), "KEYVERTICES", self.error
            )[0]
            cell = faces.seed(xyz, key, 1 if signed > 0 else -1)
            if cell is None:
                self.warn(
                    f"{what}: no tetrahedron on that side of TFACE {abs(signed)}'s key "
                    "triangle; ignored",
                    line,
                )
                continue
            found.append((str(name), cell))
        return found

    def _regions_from_faces(
        self,
        obj: GocadObject,
        faces: TetFaces,
        codes: NDArray[np.int64] | None,
        seeds: list[tuple[str, int]],
        lookup: IdLookup,
    ) -> tuple[NDArray[np.int64], tuple[str, ...]]:
        """Regions as connected sets of tetrahedra separated by model-surface faces (``#
        CTETRA`` codes and ``MODEL`` triangles), named by their MODEL_REGION seeds, else by the
        ``# CTETRA`` region most of their tetrahedra name; sets with one name are one region."""
        barrier = codes != 0 if codes is not None else np.zeros((faces.n_cells, 4), dtype=bool)
        triangles = [
            triangle
            for surface in obj.solid_model.surfaces
            for tface in surface.tfaces
            for triangle in tface.triangles
        ]
        if triangles:
            ids = np.asarray([t for t, _ in triangles], dtype=np.int64)
            lines = np.asarray([line for _, line in triangles], dtype=np.int64)
            barrier = barrier | faces.on_triangles(lookup.require(ids, lines, "TRGL", self.error))
        count, component = faces.components(barrier)
        named: dict[int, str] = {}
        for name, cell in seeds:
            c = int(component[cell])
            if named.setdefault(c, name) != name:
                self.warn(
                    f"MODEL_REGION {name!r} seeds the region already named {named[c]!r} "
                    "(their tetrahedra are connected); it keeps that name",
                    obj.line,
                )
        order = [n for n in dict.fromkeys(named.values())]
        if len(named) < count:
            majority = _majority_names(obj, component, count)
            for c in range(count):
                if c not in named:
                    named[c] = majority[c] or f"region_{c}"
                    if not majority[c]:
                        self.warn(
                            f"a connected set of {int((component == c).sum())} tetrahedra of "
                            f"{obj.name!r} has no MODEL_REGION seed nor '# CTETRA' region; "
                            f"named {named[c]!r}",
                            obj.line,
                        )
        order += [n for n in dict.fromkeys(named[c] for c in range(count)) if n not in order]
        index = {name: k for k, name in enumerate(order)}
        label_of = np.array([index[named[c]] for c in range(count)], dtype=np.int64)
        return label_of[component], tuple(order)

    def _check_seeds(
        self,
        obj: GocadObject,
        seeds: list[tuple[str, int]],
        parts: NDArray[np.int64],
        names: tuple[str, ...],
    ) -> None:
        """With TVOLUMEs, the regions are the TVOLUMEs; a seed in another one is reported."""
        for name, cell in seeds:
            part = int(parts[cell])
            own = names[part] if part < len(names) else ""
            if own != name:
                self.warn(
                    f"MODEL_REGION {name!r} seeds tetrahedron {cell} of TVOLUME {own!r}; "
                    "the TVOLUMEs are kept as the regions",
                    obj.line,
                )

    def _tsolid_surface(
        self,
        obj: GocadObject,
        surface: SolidSurface,
        xyz: NDArray[np.float64],
        lookup: IdLookup,
        tet_id: int,
    ) -> None:
        rows: list[tuple[int, int, int]] = []
        lines: list[int] = []
        labels: list[int] = []
        for label, tface in enumerate(surface.tfaces):
            for tri, line in tface.triangles:
                rows.append(tri)
                lines.append(line)
                labels.append(label)
        ids = np.asarray(rows, dtype=np.int64).reshape(-1, 3)
        index = lookup.require(ids, np.asarray(lines, dtype=np.int64), "TRGL", self.error)
        used, compact = np.unique(index, return_inverse=True)
        key_faces: list[int | None] = []
        for label, tface in enumerate(surface.tfaces):
            key = tface.key
            if key is None:
                self.warn(f"TFACE {tface.id} of MODEL surface {surface.name!r} has no KEYVERTICES")
                key_faces.append(None)
                continue
            key_index = lookup.require(
                np.asarray([key.ids], dtype=np.int64),
                np.asarray([key.line]),
                "KEYVERTICES",
                self.error,
            )[0]
            match = np.flatnonzero((index == key_index).all(axis=1) & (np.asarray(labels) == label))
            if not match.size:
                self.warn(f"KEYVERTICES of TFACE {tface.id} is no TRGL of it", key.line)
            key_faces.append(int(match[0]) if match.size else None)
        self.entities.append(
            Surface(
                id=self.next_id(),
                name=surface.name,
                vertices=xyz[used],
                faces=compact.reshape(-1, 3),
                patch_labels=np.asarray(labels, dtype=np.int64),
                patch_names=tuple(str(t.id) for t in surface.tfaces) or ("0",),
                metadata={
                    "gocad": {
                        "type": "TSolid.SURFACE",
                        "tsolid": tet_id,
                        "tface_ids": [t.id for t in surface.tfaces],
                        "tsolid_vertices": used.tolist(),
                        "key_triangles": key_faces,
                    }
                },
            )
        )


def _surface(
    xyz: NDArray[np.float64],
    faces: NDArray[np.int64],
    labels: NDArray[np.int64],
    names: tuple[str, ...],
    point_data: dict[str, Property],
    cell_data: dict[str, Property],
    fields: _EntityFields,
) -> Surface:
    """The Surface of a TSurf, built as its validation would build it when the reader made
    its parts so (float64 (N, 3) finite vertices, int64 (M, 3) faces of vertex indices the
    id lookup resolved, int64 (M,) labels, validated properties under non-empty names,
    JSON metadata of text, numbers and lists): the entity's own checks (vertex indices,
    labels against the patch names, property lengths) are still run, with its errors.
    Anything else goes through the validating constructor."""
    made_so = (
        xyz.dtype == np.float64
        and xyz.ndim == 2
        and xyz.shape[1] == 3
        and faces.dtype == np.int64
        and faces.ndim == 2
        and faces.shape[1] == 3
        and labels.dtype == np.int64
        and labels.shape == (faces.shape[0],)
        and all(
            isinstance(name, str) and name and isinstance(prop, Property)
            for data in (point_data, cell_data)
            for name, prop in data.items()
        )
    )
    if not made_so:
        return Surface(
            vertices=xyz,
            faces=faces,
            patch_labels=labels,
            patch_names=names,
            point_data=point_data,
            cell_data=cell_data,
            **fields,
        )
    surface = Surface.model_construct(
        vertices=as_readonly(xyz),
        faces=as_readonly(faces),
        patch_labels=as_readonly(labels),
        patch_names=names,
        point_data=PropertyMap(point_data),
        cell_data=PropertyMap(cell_data),
        **fields,
    )
    surface.check_fields()
    return surface


def _majority_names(obj: GocadObject, component: NDArray[np.int64], count: int) -> list[str]:
    """For each connected set, the ``# CTETRA`` region most of its tetrahedra name ("" if
    none)."""
    if not obj.ctetra:
        return [""] * count
    cells = np.array([c.cell for c in obj.ctetra], dtype=np.int64)
    labels, which = np.unique([c.region for c in obj.ctetra], return_inverse=True)
    votes = np.zeros((count, labels.shape[0]), dtype=np.int64)
    np.add.at(votes, (component[cells], which), 1)
    best = votes.argmax(axis=1)
    return [str(labels[b]) if votes[c, b] else "" for c, b in enumerate(best.tolist())]


def _ctetra_codes(
    obj: GocadObject, n_cells: int, error: ErrorFactory
) -> tuple[NDArray[np.int64], list[str], list[tuple[int, str]]]:
    surfaces: list[str] = []
    position: dict[str, int] = {}
    codes = np.zeros((n_cells, 4), dtype=np.int64)
    regions: list[tuple[int, str]] = []
    for cell, region, faces, line in obj.ctetra:
        regions.append((cell, region))
        if len(faces) != 4:
            raise error("'# CTETRA' needs a region and 4 face entries", line)
        for k, entry in enumerate(faces):
            if entry.lower() == "none":
                continue
            sign = -1 if entry.startswith("-") else 1
            body = entry[1:] if entry[:1] in "+-" else entry
            if body not in position:
                position[body] = len(surfaces)
                surfaces.append(body)
            codes[cell, k] = sign * (position[body] + 1)
    return codes, surfaces, regions


def _model3d_objects(objects: list[GocadObject]) -> Iterator[GocadObject]:
    """The Model3d objects in the order :meth:`_Builder.add_object` meets them."""
    for obj in objects:
        if obj.type in GROUP_TYPES:
            yield from _model3d_objects(obj.members)
        elif obj.type == "Model3d":
            yield obj


def _tface_types(objects: list[GocadObject]) -> dict[str, str]:
    """TSurf name -> the type of its first header TFACE, in the Model3d that defines the
    topology (:meth:`_Builder.build`); empty without one."""
    models = list(_model3d_objects(objects))
    if not models:
        return {}
    model = next((m for m in models if m.model3d.tfaces), models[0])
    types: dict[str, str] = {}
    for entry in model.model3d.tfaces:
        types.setdefault(entry.tsurf, entry.type)
    return types


def _first_crs(objects: list[GocadObject]) -> CrsBlock | None:
    for obj in objects:
        if obj.crs is not None:
            return obj.crs
        found = _first_crs(obj.members)
        if found is not None:
            return found
    return None


def read_gocad(path: Path, options: GocadReadOptions | None = None) -> Scene:
    """Read any GOCAD ASCII file (.ts .pl .vs .so .ml .gp) into a scene.

    >>> import geobrep  # doctest: +SKIP
    >>> geobrep.read("modelA4.ml").topology.patches  # doctest: +SKIP
    """
    source = Source.read(Path(path))
    skipped: list[str] = []
    objects = parse_source(source, skipped)
    builder = _Builder(source, options or GocadReadOptions())
    scene = builder.build(objects)
    skipped.extend(builder.skipped)
    if not skipped:
        return scene
    metadata = {**scene.metadata, SKIPPED_ON_READ: skipped}  # reported as lost by convert
    return scene.model_copy(update={"metadata": metadata})
