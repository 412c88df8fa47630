"""Arcs of the builder's patch split, by the rule of :mod:`geobrep.model.arcs`.

The builder's arc edges are those of :func:`~geobrep.plugins.blocks._patches.split_patches`
(where a surface stops, where surfaces meet, where more than two triangles meet, orientation
seams); corners and arcs then follow the one rule geobrep uses everywhere (the GOCAD reader and
the sample model too), written in :mod:`geobrep.model.arcs` and docs/concepts.md. Each arc has one
direction, from its start corner to its end corner, for all patches around it — the paper's
"arc direction consistency" holds by construction.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.plugins import ArcChains, chain_arc_edges
from geobrep.plugins.blocks._patches import PatchSplit, split_patches
from geobrep.plugins.blocks._soup import Soup, build_soup

__all__ = ["ArcChains", "chain_arcs", "sample_model_arcs"]


def chain_arcs(
    split: PatchSplit, n_vertices: int, vertices: NDArray[np.float64] | None = None
) -> ArcChains:
    """Group the arc edges of ``split`` into ordered arcs between corners.

    ``vertices`` (the soup's) order corners and arcs geometrically, as every reader of the
    rule does; without them the order follows vertex ids (the counts are the same).

    >>> import geobrep
    >>> from geobrep.plugins.blocks._patches import split_patches
    >>> from geobrep.plugins.blocks._soup import build_soup
    >>> soup = build_soup(geobrep.datasets.faulted_layer_cake().surfaces, None, 1e-7)
    >>> chains = chain_arcs(split_patches(soup), soup.vertices.shape[0], soup.vertices)
    >>> chains.n_arcs, len(chains.corners)
    (52, 28)
    """
    return chain_arc_edges(
        split.edges,
        split.offsets,
        split.triangle_patch[split.incident_triangles],
        split.arc_edges,
        n_vertices,
        vertices,
    )


def sample_model_arcs() -> tuple[Soup, PatchSplit, ArcChains]:
    """The built-in sample model as a soup, its patches and its arcs (the docstrings' example).

    >>> soup, split, chains = sample_model_arcs()
    >>> split.n_patches > 0, chains.n_arcs
    (True, 52)
    """
    import geobrep

    soup = build_soup(geobrep.datasets.faulted_layer_cake().surfaces, None, 1e-7)
    split = split_patches(soup)
    return soup, split, chain_arcs(split, soup.vertices.shape[0])
