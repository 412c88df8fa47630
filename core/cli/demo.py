"""``geobrep demo``: build the built-in sample model and run every demo stage on it."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["add_parser"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "demo",
        description="Build the faulted layer-cake sample, check its blocks, write the results.",
    )
    parser.add_argument(
        "-o", "--output", default="demo-output", help="output folder (default: demo-output)"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.demo import run_demo

    context = run_demo(args.output)
    print("\n".join(context.lines))
    return 0
