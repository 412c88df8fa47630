"""Run every benchmark script in this folder (``make bench``)."""

from __future__ import annotations

import os
import sys

# benchmarks/inspect.py is named after the stdlib module: keep this folder off sys.path so that
# `import inspect` (numpy, pydantic) finds the standard one.
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != os.path.dirname(__file__)]

import runpy  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).parent

# The issue-17 table first; modules named _*.py are helpers, not benchmarks.
FIRST = HERE / "user_work.py"
OTHERS = [p for p in sorted(HERE.glob("*.py")) if p not in (FIRST, Path(__file__))]
for script in [FIRST, *OTHERS]:
    if script.name.startswith("_"):
        continue
    print(f"== {script.name}", flush=True)
    runpy.run_path(str(script), run_name="__main__")
sys.stdout.flush()
