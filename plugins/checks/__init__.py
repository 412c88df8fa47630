"""The built-in inspection checks, registered like a third-party plugin's.

Registers one :class:`~geobrep.plugins.CheckSpec` per criterion through the
``geobrep_register_checks`` hook; :func:`geobrep.inspect` and ``geobrep check`` run them. The
families follow OpenGeode-Inspector's (colocation, degeneration, manifoldness, adjacency,
negative elements, intersections, B-Rep topology) plus the geological conformity of contacts;
see ``docs/inspection.md``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from geobrep.plugins import hookimpl

if TYPE_CHECKING:
    from geobrep.plugins import CheckRegistry

__all__ = ["BUILTIN_CHECKS", "geobrep_register_checks"]

#: (name, family, function in module, title, options model, repair action, run by default)
BUILTIN_CHECKS: tuple[tuple[str, str, str, str, str | None, str | None], ...] = (
    ("colocated_vertices", "colocation", "_mesh", "Colocated vertices", None, "weld"),
    (
        "degenerate_elements",
        "degeneration",
        "_mesh",
        "Degenerate elements",
        None,
        "drop_degenerate",
    ),
    (
        "duplicated_elements",
        "degeneration",
        "_mesh",
        "Duplicated elements",
        None,
        "drop_duplicates",
    ),
    ("isolated_vertices", "degeneration", "_mesh", "Isolated vertices", None, "drop_isolated"),
    ("non_manifold_edges", "manifold", "_mesh", "Non-manifold edges", None, None),
    ("non_manifold_vertices", "manifold", "_mesh", "Non-manifold vertices", None, None),
    (
        "inconsistent_orientation",
        "adjacency",
        "_mesh",
        "Inconsistently oriented faces",
        None,
        "orient",
    ),
    ("inverted_tets", "negative elements", "_mesh", "Inverted tets", None, "orient"),
    (
        "self_intersections",
        "intersections",
        "_intersections",
        "Self-intersecting surfaces",
        "IntersectionOptions",
        None,
    ),
    ("surface_intersections", "intersections", "_intersections", "Surfaces crossing", None, None),
    (
        "polyline_intersections",
        "intersections",
        "_intersections",
        "Polylines crossing surfaces",
        "IntersectionOptions",
        None,
    ),
    ("t_junctions", "conformity", "_conformal", "T-junctions", None, "split_t_junctions"),
    ("gaps", "conformity", "_conformal", "Gaps along contacts", "GapOptions", None),
    ("patch_boundaries", "brep", "_brep", "Patches bounded by arcs", None, None),
    ("arc_ends", "brep", "_brep", "Arcs between corners", None, None),
    (
        "arc_patch_order",
        "brep",
        "_radial",
        "Patches around each arc in right-hand order",
        None,
        None,
    ),
    ("patch_sides", "brep", "_brep", "A block on each side of each patch", None, None),
    ("block_closure", "brep", "_brep", "Blocks closed", None, None),
    (
        "block_orientation",
        "brep",
        "_brep",
        "Blocks outward, positive volume",
        None,
        "orient_blocks",
    ),
    ("universe_closure", "brep", "_brep", "Universe closed", None, None),
    (
        "volume_balance",
        "brep",
        "_brep",
        "Block volumes add up to the universe",
        "VolumeBalanceOptions",
        None,
    ),
    ("region_sides", "brep", "_brep", "Block sides agree with the geometry", None, "orient_blocks"),
)


def _on_first_use(module: str, name: str) -> Callable[..., Any]:
    """``module.name``, imported when the check first runs (discovery stays cheap)."""

    def run(scene: Any, options: Any, context: Any) -> Any:
        code = importlib.import_module(f"geobrep.plugins.checks.{module}")
        return getattr(code, name)(scene, options, context)

    run.__name__ = run.__qualname__ = name
    return run


@hookimpl
def geobrep_register_checks(registry: CheckRegistry) -> None:
    from geobrep.plugins import CheckSpec, NoOptions
    from geobrep.plugins.checks import options as option_models

    for name, family, module, title, options, repairs in BUILTIN_CHECKS:
        registry.add(
            CheckSpec(
                name=name,
                description=title,
                title=title,
                family=family,
                function=_on_first_use(module, name),
                options=getattr(option_models, options) if options else NoOptions,
                repairs=repairs,
            )
        )
