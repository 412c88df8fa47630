"""Print pip constraints pinning every requirement of pyproject.toml to its declared floor.

``python tools/floors.py [--build] [--requirements] [EXTRA ...]`` prints ``name==floor`` lines
for the core dependencies and the named extras (``--build``: the build-system requirements
instead; ``--requirements``: the requirement strings themselves), so ``make test-min`` can install
the lowest versions the project claims to support. A requirement
without a ``>=`` floor is an error: every supported range must have a tested bottom.
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
_REQUIREMENT = re.compile(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*(?:\[([^\]]*)\])?\s*(.*)$")


def split(requirement: str) -> tuple[str, list[str], str | None]:
    """``(name, extras, floor)`` of a PEP 508 requirement string (floor None when missing)."""
    match = _REQUIREMENT.match(requirement.split(";")[0])
    if match is None:
        raise ValueError(f"cannot parse requirement {requirement!r}")
    name, extras, spec = match.groups()
    floor = re.search(r">=\s*([0-9][A-Za-z0-9.]*)", spec)
    listed = [e.strip() for e in (extras or "").split(",") if e.strip()]
    return name.lower().replace("_", "-"), listed, floor.group(1) if floor else None


def requirements(
    extras: list[str], build: bool = False, pyproject: Path | None = None
) -> list[str]:
    """Requirement strings of the core (plus ``extras``), or of the build system."""
    config = tomllib.loads((pyproject or ROOT / "pyproject.toml").read_text())
    if build:
        return list(config["build-system"]["requires"])
    project = config["project"]
    optional: dict[str, list[str]] = project.get("optional-dependencies", {})
    own = project["name"].lower()
    found: list[str] = list(project["dependencies"])
    pending, seen = list(extras), set()
    while pending:
        extra = pending.pop()
        if extra in seen:
            continue
        if extra not in optional:
            raise ValueError(f"pyproject.toml has no extra {extra!r}")
        seen.add(extra)
        for item in optional[extra]:
            name, nested, _ = split(item)
            if name == own:  # e.g. all = ["geobrep[viz,gis]"]
                pending.extend(nested)
            else:
                found.append(item)
    return found


def constraints(items: list[str]) -> list[str]:
    """``name==floor`` for each requirement (extras dropped: pip constraints take none)."""
    pins: dict[str, str] = {}
    for item in items:
        name, _, floor = split(item)
        if floor is None:
            raise ValueError(f"requirement {item!r} has no >= floor")
        if pins.get(name, floor) != floor:
            raise ValueError(f"{name} has two floors: {pins[name]} and {floor}")
        pins[name] = floor
    return [f"{name}=={floor}" for name, floor in sorted(pins.items())]


def main(argv: list[str]) -> int:
    flags = {"--build", "--requirements"}
    extras = [a for a in argv if a not in flags]
    items = requirements(extras, build="--build" in argv)
    print("\n".join(items if "--requirements" in argv else constraints(items)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
