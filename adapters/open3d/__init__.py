"""open3d bridge (extra ``open3d``): :func:`to_open3d` and :func:`from_open3d`.

open3d's own file readers and writers are not registered as formats: its PLY path drops
properties and its tensor API turns coordinates into float32, so geobrep's ``ply`` format
(plyfile) is the lossless route. open3d is imported only when a function is called.
"""

from __future__ import annotations

from geobrep.adapters.open3d._bridge import (
    Open3dLossWarning,
    from_open3d,
    open3d_losses,
    to_open3d,
)

__all__ = ["Open3dLossWarning", "from_open3d", "open3d_losses", "to_open3d"]
