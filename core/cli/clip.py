"""``geobrep clip IN OUT``: cut a model by a plane (or to a box) and write what is kept.

The plane is ``--plane a,b,c,d`` (``a·x + b·y + c·z + d = 0``, negative side ``< 0``) or one of
the shortcuts ``--x``, ``--y``, ``--z`` (the plane ``x = value``, etc.); ``--box
xmin,xmax,ymin,ymax,zmin,zmax`` keeps the inside of a box instead. ``--keep both`` writes two files
beside ``OUT``: ``NAME-negative.EXT`` and ``NAME-positive.EXT``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from geobrep.cli.common import (
    add_allow_empty,
    format_name,
    is_empty,
    read_input,
    refuse_empty,
    warn,
)
from geobrep.errors import OptionsError
from geobrep.geometry import Plane

__all__ = [
    "add_parser",
    "add_plane_arguments",
    "both_paths",
    "plane_from_args",
    "plane_text",
    "run",
    "span_text",
]


def _numbers(text: str, count: int, flag: str) -> list[float]:
    try:
        values = [float(part) for part in text.replace(" ", "").split(",")]
    except ValueError:
        raise OptionsError(
            f"{flag}: expected {count} comma-separated numbers, got {text!r}"
        ) from None
    if len(values) != count:
        raise OptionsError(f"{flag}: expected {count} comma-separated numbers, got {len(values)}")
    return values


def add_plane_arguments(parser: argparse.ArgumentParser, box: bool = False) -> None:
    """The mutually exclusive ``--plane``/``--x``/``--y``/``--z`` (and ``--box``) options."""
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--plane", metavar="A,B,C,D", help="the plane a·x + b·y + c·z + d = 0")
    group.add_argument("--x", type=float, metavar="X", help="the plane x = X")
    group.add_argument("--y", type=float, metavar="Y", help="the plane y = Y")
    group.add_argument("--z", type=float, metavar="Z", help="the plane z = Z")
    if box:
        group.add_argument(
            "--box", metavar="XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX", help="keep the inside of this box"
        )


def plane_from_args(args: argparse.Namespace) -> Plane | None:
    """The plane the arguments name (``None`` when ``--box`` was given)."""
    if args.plane is not None:
        return Plane(*_numbers(args.plane, 4, "--plane"))
    for axis in ("x", "y", "z"):
        value = getattr(args, axis)
        if value is not None:
            return getattr(Plane, axis)(value)  # type: ignore[no-any-return]
    return None


def plane_text(args: argparse.Namespace) -> str:
    """The plane or box as the user gave it, for messages: ``the plane x = 1e+09``."""
    if args.plane is not None:
        return f"the plane {args.plane} (a,b,c,d)"
    for axis in ("x", "y", "z"):
        value = getattr(args, axis)
        if value is not None:
            return f"the plane {axis} = {value:g}"
    return f"the box {getattr(args, 'box', '')}"


def span_text(scene: Any) -> str:
    """Where the model is, for messages: ``the model spans x -5291 … 10949, y …, z …``."""
    bounds = scene.bounds
    if bounds is None:
        return "the model has no geometry"
    xmin, xmax, ymin, ymax, zmin, zmax = bounds.as_tuple()
    return (
        f"the model spans x {xmin:.6g} … {xmax:.6g}, y {ymin:.6g} … {ymax:.6g}, "
        f"z {zmin:.6g} … {zmax:.6g}"
    )


def _misses(plane: Plane, scene: Any) -> bool:
    """True when the model's bounding box lies wholly on one side of ``plane``."""
    bounds = scene.bounds
    if bounds is None:
        return False
    xmin, xmax, ymin, ymax, zmin, zmax = bounds.as_tuple()
    corners = [(x, y, z) for x in (xmin, xmax) for y in (ymin, ymax) for z in (zmin, zmax)]
    sides = plane.signed_distance(corners)
    return bool((sides > 0).all() or (sides < 0).all())


def both_paths(output: Path) -> tuple[Path, Path]:
    """Where ``--keep both`` writes: ``NAME-negative.EXT`` and ``NAME-positive.EXT``.

    >>> [p.name for p in both_paths(Path("out/cut.geobrep"))]
    ['cut-negative.geobrep', 'cut-positive.geobrep']
    """
    suffix = output.suffix
    stem = output.name[: len(output.name) - len(suffix)] if suffix else output.name
    return (
        output.with_name(f"{stem}-negative{suffix}"),
        output.with_name(f"{stem}-positive{suffix}"),
    )


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "clip",
        help="cut a model by a plane or to a box",
        description="Cut a model by a plane (keeping one side or both) or to a box; cut blocks "
        "are closed again by caps. --keep both writes NAME-negative.EXT and NAME-positive.EXT.",
    )
    parser.add_argument("input", help="model to cut (any readable format)")
    parser.add_argument("output", help="file to write (its extension picks the format)")
    add_plane_arguments(parser, box=True)
    parser.add_argument(
        "--keep",
        choices=("negative", "positive", "both"),
        default="negative",
        help="side to keep: negative (a·x+b·y+c·z+d < 0, the default), positive, or both",
    )
    parser.add_argument("--tolerance", type=float, help="on-plane distance (model units)")
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument("--output-format", type=format_name("write"), help="output format name")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def _describe(scene: Any) -> str:
    caps = [s for s in scene.surfaces if s.kind == "cap"]
    return (
        f"{len(scene.entities)} entities, {len(scene.blocks)} blocks, "
        f"{sum(c.n_patches for c in caps)} cap patches"
    )


def run(args: argparse.Namespace) -> int:
    from geobrep.ops.clipping import clip, clip_box
    from geobrep.ops.io import as_scene, write

    scene = read_input(args, args.input, format=args.format)
    output = Path(args.output)
    plane = plane_from_args(args)
    results: list[tuple[Path, Any, str]] = []
    if plane is None:
        if args.keep != "negative":
            raise OptionsError("--box keeps the inside of the box: --keep does not apply")
        result = clip_box(scene, _numbers(args.box, 6, "--box"), tolerance=args.tolerance)
        results.append((output, as_scene(result if result is not None else []), "inside of"))
    elif args.keep == "both":
        negative, positive = clip(scene, plane, keep="both", tolerance=args.tolerance)
        for path, part, side in zip(
            both_paths(output), (negative, positive), ("negative", "positive"), strict=True
        ):
            results.append((path, part, f"{side} side of"))
    else:
        kept = clip(scene, plane, keep=args.keep, tolerance=args.tolerance)
        results.append((output, kept, f"{args.keep} side of"))
    where = f"{plane_text(args)} ({span_text(scene)})"
    refuse_empty(
        args,
        [
            f"{path}: nothing on the {side} {where}"
            for path, part, side in results
            if is_empty(part)
        ],
        consequence="no file written",
    )
    if plane is not None and args.keep != "both" and _misses(plane, scene):
        warn(f"{output}: {plane_text(args)} does not meet the model ({span_text(scene)})")
    for path, part, _ in results:
        write(part, path, format=args.output_format)
        print(f"{path}: {_describe(part)}")
    return 0
