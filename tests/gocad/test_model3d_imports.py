"""Reading a Model3d rebuilds corners, arcs and orientations without scipy (numpy kernels of
geobrep.geometry.graph): a first read in a fresh process does not pay scipy's import."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

PROBE = """
import json, sys, warnings
warnings.simplefilter("ignore")
import geobrep
scene = geobrep.read(sys.argv[1])
print(json.dumps({"modules": sorted(sys.modules), "arcs": len(scene.topology.arcs)}))
"""


def test_reading_a_model3d_does_not_import_scipy() -> None:
    path = Path(__file__).parent.parent / "data" / "gocad" / "modelA1.ml"
    result = subprocess.run(
        [sys.executable, "-c", PROBE, str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    report = json.loads(result.stdout)
    assert report["arcs"] > 0
    assert not [m for m in report["modules"] if m == "scipy" or m.startswith("scipy.")]
