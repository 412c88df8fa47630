"""``geobrep plugins``: which plugins are loaded, from which distribution, and what they add."""

from __future__ import annotations

import argparse
import json
from typing import Any

__all__ = ["add_parser"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "plugins",
        description="List discovered plugins, their distribution and version, and their items.",
    )
    parser.add_argument("--json", action="store_true", help="print JSON for machines")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.host import list_plugins

    infos = list_plugins()
    if args.json:
        print(json.dumps([info.model_dump(mode="json") for info in infos], indent=2))
        return 0
    if not infos:
        print("no plugins found (is geobrep installed? entry-point group 'geobrep.plugins')")
    for info in infos:
        version = f" {info.version}" if info.version else ""
        print(f"{info.name}  [{info.status}]  {info.distribution or '?'}{version}  ({info.module})")
        if info.error:
            print(f"    error: {info.error}")
        for kind, names in sorted(info.registered.items()):
            if names:
                print(f"    {kind}: {', '.join(names)}")
    return 0
