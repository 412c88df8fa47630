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

from geobrep.errors import OptionsError
from geobrep.geometry import Plane

__all__ = ["add_parser", "add_plane_arguments", "both_paths", "plane_from_args", "run"]


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
    parser.add_argument("--format", help="input format name, when the extension is not enough")
    parser.add_argument("--output-format", help="output format name")
    parser.set_defaults(run=run)


def _describe(scene: Any) -> str:
    caps = [s for s in scene.surfaces if s.kind == "cap"]
    return (
        f"{len(scene.entities)} entities, {len(scene.blocks)} blocks, "
        f"{sum(c.n_patches for c in caps)} cap patches"
    )


def run(args: argparse.Namespace) -> int:
    from geobrep.clipping import clip, clip_box
    from geobrep.io import as_scene, read, write

    scene = read(args.input, format=args.format)
    output = Path(args.output)
    plane = plane_from_args(args)
    if plane is None:
        if args.keep != "negative":
            raise OptionsError("--box keeps the inside of the box: --keep does not apply")
        result = clip_box(scene, _numbers(args.box, 6, "--box"), tolerance=args.tolerance)
        kept = as_scene(result if result is not None else [])
        write(kept, output, format=args.output_format)
        print(f"{output}: {_describe(kept)}")
        return 0
    if args.keep == "both":
        negative, positive = clip(scene, plane, keep="both", tolerance=args.tolerance)
        for path, part in zip(both_paths(output), (negative, positive), strict=True):
            write(part, path, format=args.output_format)
            print(f"{path}: {_describe(part)}")
        return 0
    kept = clip(scene, plane, keep=args.keep, tolerance=args.tolerance)
    write(kept, output, format=args.output_format)
    print(f"{output}: {_describe(kept)}")
    return 0
