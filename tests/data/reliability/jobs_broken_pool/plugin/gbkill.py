"""A reader that kills its worker process (a stand-in for a segfault or the OOM killer)."""

import os
from pathlib import Path
from typing import Any

from geobrep.plugins import FormatSpec, hookimpl


def rd(p: Path, o: Any) -> None:
    os._exit(9)


@hookimpl
def geobrep_register_formats(registry: Any) -> None:
    registry.add(FormatSpec(name="killer", extensions=(".kill",), reader=rd))
