"""Shared builders for the fitter tests: random B-spline surfaces and their geomdl twins."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep import NurbsSurface

UTM = np.array([450_000.0, 6_700_000.0, 0.0])


def random_knots(rng: np.random.Generator, degree: int, n_ctrl: int) -> NDArray[np.float64]:
    """Clamped knots on [0, 1] with random interior values (one repeated when possible)."""
    inner = np.sort(rng.uniform(0.05, 0.95, n_ctrl - degree - 1))
    if inner.size >= 2:
        inner[1] = inner[0]
    return np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])


def random_surface(rng: np.random.Generator, rational: bool) -> NurbsSurface:
    p, q = (int(d) for d in rng.integers(1, 5, 2))
    nu, nv = p + int(rng.integers(1, 7)), q + int(rng.integers(1, 7))
    weights = rng.uniform(0.3, 3.0, (nu, nv)) if rational else np.ones((nu, nv))
    return NurbsSurface(
        degree_u=p,
        degree_v=q,
        knots_u=random_knots(rng, p, nu),
        knots_v=random_knots(rng, q, nv),
        control_points=rng.normal(size=(nu, nv, 3)),
        weights=weights,
    )


def geomdl_twin(surface: NurbsSurface):  # type: ignore[no-untyped-def]
    """The same surface as a geomdl object (NURBS when rational)."""
    from geomdl import NURBS, BSpline

    nu, nv = surface.shape
    twin = NURBS.Surface() if surface.is_rational else BSpline.Surface()
    twin.degree_u, twin.degree_v = surface.degree_u, surface.degree_v
    twin.ctrlpts_size_u, twin.ctrlpts_size_v = nu, nv
    net = np.asarray(surface.control_points).reshape(-1, 3)
    if surface.is_rational:
        w = np.asarray(surface.weights).reshape(-1, 1)
        twin.ctrlptsw = np.hstack([net * w, w]).tolist()
    else:
        twin.ctrlpts = net.tolist()
    twin.knotvector_u = np.asarray(surface.knots_u).tolist()
    twin.knotvector_v = np.asarray(surface.knots_v).tolist()
    return twin


def sphere_octant(radius: float = 2.0, centre: NDArray[np.float64] | None = None) -> NurbsSurface:
    """An exact rational octant of a sphere (quadratic × quadratic, 3 × 3 net)."""
    c = np.zeros(3) if centre is None else centre
    s = np.sqrt(0.5)
    arc = [(np.array([1.0, 0.0]), 1.0), (np.array([1.0, 1.0]), s), (np.array([0.0, 1.0]), 1.0)]
    net = np.zeros((3, 3, 3))
    weights = np.zeros((3, 3))
    meridian = [(np.array([0.0, 1.0]), 1.0), (np.array([1.0, 1.0]), s), (np.array([1.0, 0.0]), 1.0)]
    for i, (m, wm) in enumerate(meridian):  # m = (sin θ-ish radial, z)
        for j, (a, wa) in enumerate(arc):
            net[i, j] = radius * np.array([m[0] * a[0], m[0] * a[1], m[1]]) + c
            weights[i, j] = wm * wa
    knots = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    return NurbsSurface(
        degree_u=2, degree_v=2, knots_u=knots, knots_v=knots, control_points=net, weights=weights
    )
