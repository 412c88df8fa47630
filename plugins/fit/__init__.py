"""Built-in fitters: NURBS skinning, least-squares approximation, kriging, and the hybrid workflow.

Registered through ``geobrep_register_fitters`` like any third-party plugin; ``geobrep.fit(points,
method=...)`` dispatches to them. Every fitter returns a :class:`geobrep.FitResult` with the
surface and its accuracy report. Heavy modules are imported when a fitter runs, so loading the
plugin stays cheap.

* ``skinning``: interpolate ordered sections (rows), then across them; exact (NurbsSurface);
* ``approximation``: least squares + bending energy, boundary curves held exactly (NurbsSurface);
* ``kriging``: ordinary / universal kriging onto a grid, with the kriging variance (Surface);
* ``hybrid``: skin the dense core, approximate the sparse rim against it (NurbsSurface).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from geobrep.plugins import FitterRegistry, FitterSpec, hookimpl
from geobrep.plugins.fit.options import (
    ApproximationOptions,
    HybridOptions,
    KrigingOptions,
    SkinningOptions,
)

__all__ = ["geobrep_register_fitters"]


def _run_skinning(entities: list[Any], options: SkinningOptions) -> Any:
    from geobrep.plugins.fit._skinning_fitter import fit_skinning

    return fit_skinning(entities, options)


def _run_approximation(entities: list[Any], options: ApproximationOptions) -> Any:
    from geobrep.plugins.fit._approximation import fit_approximation

    return fit_approximation(entities, options)


def _run_kriging(entities: list[Any], options: KrigingOptions) -> Any:
    from geobrep.plugins.fit.kriging import fit_kriging

    return fit_kriging(entities, options)


def _run_hybrid(entities: list[Any], options: HybridOptions) -> Any:
    from geobrep.plugins.fit._hybrid import fit_hybrid

    return fit_hybrid(entities, options)


@hookimpl
def geobrep_register_fitters(registry: FitterRegistry) -> None:
    """Register ``skinning``, ``approximation``, ``kriging`` and ``hybrid``."""
    both = ("PointSet", "PolyLine")
    # name, function, input types, options model, description
    table: list[tuple[str, Callable[..., Any], tuple[str, ...], type, str]] = [
        ("skinning", _run_skinning, both, SkinningOptions,
         "NURBS skinning: interpolate ordered sections, exact at every point"),
        ("approximation", _run_approximation, both, ApproximationOptions,
         "NURBS least squares with smoothing, ε-driven net size, boundary curves"),
        ("kriging", _run_kriging, both, KrigingOptions,
         "Ordinary/universal kriging onto a grid (prediction + variance)"),
        ("hybrid", _run_hybrid, ("PointSet",), HybridOptions,
         "Skin the dense core, approximate the sparse rim against it (Li 2011)"),
    ]  # fmt: skip
    for name, function, input_types, options, description in table:
        registry.add(
            FitterSpec(
                name=name,
                description=description,
                function=function,
                input_types=input_types,
                options=options,
            )
        )
