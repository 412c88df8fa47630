"""Triangulated (or quad) surfaces: horizons, faults, model boundaries, TSurfs."""

from __future__ import annotations

from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from geobrep.geometry import mesh
from geobrep.model.arrays import FaceArray, IndexArray, Points
from geobrep.model.entities.base import VertexEntity

__all__ = ["Surface"]


class Surface(VertexEntity):
    """A surface mesh: ``vertices (N, 3)`` float64, ``faces (M, 3)`` triangles or ``(M, 4)`` quads.

    Faces may be grouped into named patches (GOCAD TFACE parts, the patches of a B-Rep):
    ``patch_labels[i]`` is the patch of face ``i`` and ``patch_names[label]`` its name. Without
    labels the surface is one patch. ``cell_data`` holds one value per face.

    >>> import numpy as np
    >>> quad = Surface(vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
    ...                faces=[[0, 1, 2], [0, 2, 3]], name="plate")
    >>> quad.area, quad.is_closed
    (1.0, False)
    """

    type: Literal["Surface"] = "Surface"
    cell_noun = "faces"
    vertices: Points
    faces: FaceArray
    patch_labels: IndexArray | None = None
    patch_names: tuple[str, ...] = Field(default=())

    @property
    def n_vertices(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def n_faces(self) -> int:
        return int(self.faces.shape[0])

    @property
    def n_cells(self) -> int:
        return self.n_faces

    @property
    def n_patches(self) -> int:
        """Number of patches (1 when the surface is not split)."""
        if self.patch_names:
            return len(self.patch_names)
        if self.patch_labels is None or self.patch_labels.size == 0:
            return 1
        return int(self.patch_labels.max()) + 1

    def patch_name(self, label: int) -> str:
        """Name of patch ``label`` (its number when patches are unnamed)."""
        return self.patch_names[label] if self.patch_names else str(label)

    def patch_faces(self, label: int) -> NDArray[np.int64]:
        """Indices of the faces of patch ``label``."""
        if not 0 <= label < self.n_patches:
            raise self.fail("patch_labels", f"no patch {label} (surface has {self.n_patches})")
        if self.patch_labels is None:
            return np.arange(self.n_faces, dtype=np.int64)
        return np.flatnonzero(self.patch_labels == label).astype(np.int64)

    def extract_faces(self, face_indices: NDArray[np.integer[Any]], **fields: Any) -> Surface:
        """A new surface with the given faces and only the vertices they use (properties kept)."""
        faces = self.faces[face_indices]
        used, inverse = np.unique(faces, return_inverse=True)
        labels = None if self.patch_labels is None else self.patch_labels[face_indices]
        return Surface(
            vertices=self.vertices[used],
            faces=inverse.reshape(faces.shape).astype(self.faces.dtype),
            patch_labels=labels,
            patch_names=self.patch_names,
            point_data=self.point_data.take(used),
            cell_data=self.cell_data.take(face_indices),
            **{"name": self.name, "kind": self.kind, **fields},
        )

    # -- derived geometry (cached: entities are immutable) -----------------------------------
    @cached_property
    def face_normals(self) -> NDArray[np.float64]:
        """Unit normal of every face (right-hand rule on the vertex order)."""
        return mesh.face_normals(self.vertices, self.faces)

    @cached_property
    def face_areas(self) -> NDArray[np.float64]:
        return mesh.face_areas(self.vertices, self.faces)

    @cached_property
    def area(self) -> float:
        """Total area."""
        return float(self.face_areas.sum())

    @cached_property
    def volume(self) -> float:
        """Signed volume enclosed (positive when closed and outward-oriented).

        Meaningful only for a closed surface; computed about the bounding-box centre so that
        UTM-scale coordinates keep full precision.
        """
        return float(mesh.signed_volume(self.vertices, self.faces))

    @cached_property
    def is_closed(self) -> bool:
        """Every edge is shared by exactly two faces."""
        return bool(mesh.is_closed(self.faces))

    @cached_property
    def is_consistently_oriented(self) -> bool:
        """Neighbouring faces traverse their shared edge in opposite directions."""
        return bool(mesh.is_consistently_oriented(self.faces))

    def flipped(self) -> Surface:
        """The same surface with every face's winding (and so its normal) reversed."""
        return self.replace(faces=mesh.flip_faces(self.faces))

    def _check(self) -> None:
        n = self.n_vertices
        faces = self.faces
        # One pass over the faces: as unsigned integers, negative indices are huge ones.
        if faces.size and int(faces.view(f"u{faces.dtype.itemsize}").max()) >= n:
            lo, hi = int(faces.min()), int(faces.max())
            if lo < 0:
                row = int(np.argmax((faces < 0).any(axis=1)))
                raise self.fail(
                    "faces", f"face {row} has a negative vertex index ({lo} is the smallest)"
                )
            if hi >= n:
                row = int(np.argmax((faces >= n).any(axis=1)))
                raise self.fail(
                    "faces", f"face {row} refers to vertex {hi} but there are only {n} vertices"
                )
        labels = self.patch_labels
        if labels is not None:
            if labels.shape[0] != faces.shape[0]:
                raise self.fail(
                    "patch_labels", f"has {labels.shape[0]} labels for {faces.shape[0]} faces"
                )
            if labels.size and labels.min() < 0:
                raise self.fail("patch_labels", "labels must be ≥ 0")
            if self.patch_names and labels.size and labels.max() >= len(self.patch_names):
                raise self.fail(
                    "patch_labels",
                    f"label {int(labels.max())} has no name ({len(self.patch_names)} patch_names)",
                )
        elif len(self.patch_names) > 1:
            raise self.fail("patch_names", "several patch names need patch_labels")
