"""Run every benchmark script in this folder (``make bench``)."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

HERE = Path(__file__).parent
# the scripts import their helpers (_inputs.py, formats_io.py) from this folder
sys.path.insert(0, str(HERE))

# The issue-17 table first; modules named _*.py are helpers, not benchmarks.
FIRST = HERE / "user_work.py"
OTHERS = [p for p in sorted(HERE.glob("*.py")) if p not in (FIRST, Path(__file__))]
for script in [FIRST, *OTHERS]:
    if script.name.startswith("_"):
        continue
    print(f"== {script.name}", flush=True)
    runpy.run_path(str(script), run_name="__main__")
sys.stdout.flush()
