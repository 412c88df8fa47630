"""Example geobrep plugin: the XYZ point format (``x y z [value]`` per line) and ``thin``.

Installed, it is found through its entry point (see ``pyproject.toml``)::

    [project.entry-points."geobrep.plugins"]
    example = "geobrep_example_plugin"
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from geobrep.plugins import FormatCapabilities, FormatSpec, hookimpl
from geobrep_example_plugin.thin import THIN, ThinOptions, thin
from geobrep_example_plugin.xyz import XyzOptions, looks_like_xyz, read_xyz, write_xyz

if TYPE_CHECKING:
    from geobrep.plugins import FormatRegistry, OperationRegistry

__all__ = [
    "THIN",
    "ThinOptions",
    "XyzOptions",
    "geobrep_register_formats",
    "geobrep_register_operations",
    "looks_like_xyz",
    "read_xyz",
    "thin",
    "write_xyz",
]

__version__ = "0.1.0"


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register the ``xyz`` format."""
    registry.add(
        FormatSpec(
            name="xyz",
            description="XYZ points: one 'x y z [value]' line per point, '#' comments",
            extensions=(".xyz",),
            reader=read_xyz,
            writer=write_xyz,
            sniff=looks_like_xyz,
            options=XyzOptions,
            capabilities=FormatCapabilities(entity_types=frozenset({"PointSet"}), point_data=True),
        )
    )


@hookimpl
def geobrep_register_operations(registry: OperationRegistry) -> None:
    """Register the ``thin`` operation (a command, a pipeline step and a Python function)."""
    registry.add(THIN)
