"""A plugin the tests disable: importing it at all is a test failure."""

from __future__ import annotations

raise AssertionError("geobrep_fake_disabled was imported although it is disabled")
