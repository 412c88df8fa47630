"""The glTF reader's one-pass y-up → world conversion gives the two-step values bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pygltflib")

from geobrep.adapters.gltf._frame import OffsetFrame, from_y_up


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (512_345.125, 6_712_345.5, -1_234.0625)])
def test_world_from_y_up_equals_to_world_of_from_y_up(origin: tuple[float, float, float]) -> None:
    rng = np.random.default_rng(7)
    points = (rng.normal(size=(10_000, 3)) * 3000).astype(np.float32)
    points[::5] = [-0.0, 1e-45, 3.4e38]  # signed zero, a subnormal, near the float32 maximum
    frame = OffsetFrame(origin)
    fused = frame.world_from_y_up(points)
    assert fused.dtype == np.float64
    assert fused.flags.c_contiguous
    two_steps = frame.to_world(from_y_up(points.astype(np.float64)))
    assert fused.tobytes() == two_steps.tobytes()


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (512_345.125, 6_712_345.5, -1_234.0625)])
def test_y_up_from_world_equals_to_y_up_of_to_local(origin: tuple[float, float, float]) -> None:
    from geobrep.adapters.gltf._frame import to_y_up

    rng = np.random.default_rng(8)
    world = rng.normal(size=(10_000, 3)) * 3000 + np.asarray(origin)
    world[::5] = origin  # coordinates at the origin: zeros (and their signs) as before
    frame = OffsetFrame(origin)
    fused = frame.y_up_from_world(world)
    assert fused.flags.c_contiguous
    assert fused.tobytes() == to_y_up(frame.to_local(world)).tobytes()
