"""A plugin whose import fails."""

from __future__ import annotations

import geobrep_fake_no_such_module  # type: ignore[import-not-found]  # noqa: F401
