"""``geobrep clip IN OUT``: cut a model by a plane (or to a box) and write what is kept.

The plane is ``--plane a,b,c,d`` (``a·x + b·y + c·z + d = 0``, negative side ``< 0``) or one of
the shortcuts ``--x``, ``--y``, ``--z`` (the plane ``x = value``, etc.); ``--box
xmin,xmax,ymin,ymax,zmin,zmax`` keeps the inside of a box instead. ``--keep both`` writes two files
beside ``OUT``: ``NAME-negative.EXT`` and ``NAME-positive.EXT``. The other options are those of
the ``clip`` operation (:class:`~geobrep.batch.pipeline.ClipStep`), ``--box`` those of ``clip_box``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

from geobrep.batch.pipeline import ClipBoxStep, ClipStep
from geobrep.cli.common import is_empty, read_input, refuse_empty, warn
from geobrep.cli.operation import SceneCommand
from geobrep.errors import OptionsError
from geobrep.geometry import Plane
from geobrep.host.operations import Cli, comma_numbers, options_from_args

__all__ = [
    "COMMAND",
    "DESCRIPTION",
    "OPERATION",
    "OPTIONS_FOR",
    "ClipCommand",
    "PlaneShortcuts",
    "both_paths",
    "clip_options",
    "plane_text",
    "run",
    "span_text",
]

OPERATION = "clip"
DESCRIPTION = (
    "Cut a model by a plane (keeping one side or both) or to a box; cut blocks "
    "are closed again by caps. --keep both writes NAME-negative.EXT and NAME-positive.EXT."
)


class PlaneShortcuts(SceneCommand):
    """``--x X``, ``--y Y``, ``--z Z``: the planes ``x = X``, ... (instead of ``--plane``)."""

    x: Annotated[float | None, Cli(group="plane", metavar="X")] = None
    """the plane x = X"""
    y: Annotated[float | None, Cli(group="plane", metavar="Y")] = None
    """the plane y = Y"""
    z: Annotated[float | None, Cli(group="plane", metavar="Z")] = None
    """the plane z = Z"""

    def shortcut(self) -> Plane | None:
        """The plane a shortcut names, if one was given."""
        for axis in ("x", "y", "z"):
            value = getattr(self, axis)
            if value is not None:
                return getattr(Plane, axis)(value)  # type: ignore[no-any-return]
        return None

    def operation_data(self) -> dict[str, Any]:
        plane = self.shortcut()
        return {} if plane is None else {"plane": plane.coefficients.tolist()}


class ClipCommand(PlaneShortcuts):
    """The files and command-line-only options of ``geobrep clip``."""

    box: Annotated[
        tuple[float, float, float, float, float, float] | None,
        Cli(group="plane", parse=comma_numbers(6), metavar="XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX"),
    ] = None
    """keep the inside of this box"""


def clip_options(command: Any, given: Mapping[str, Any]) -> ClipStep | ClipBoxStep:
    """The options of ``clip`` (or of ``clip_box`` for ``--box``) the arguments give."""
    if getattr(command, "box", None) is not None:
        if given.get("keep", "negative") != "negative":
            raise OptionsError("--box keeps the inside of the box: --keep does not apply")
        data = {key: value for key, value in given.items() if key not in ("plane", "keep")}
        return options_from_args(ClipBoxStep, {**data, "bounds": command.box})  # type: ignore[no-any-return]
    return options_from_args(ClipStep, {**given, **command.operation_data()})  # type: ignore[no-any-return]


def plane_text(args: PlaneShortcuts, options: Any = None) -> str:
    """The plane or box as the user gave it, for messages: ``the plane x = 1e+09``."""
    for axis in ("x", "y", "z"):
        value = getattr(args, axis)
        if value is not None:
            return f"the plane {axis} = {value:g}"
    box = getattr(args, "box", None)
    if box is not None:
        return f"the box {','.join(f'{v:g}' for v in box)}"
    plane = getattr(options, "plane", None)
    return f"the plane {','.join(f'{v:g}' for v in plane or ())} (a,b,c,d)"


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


def _describe(scene: Any) -> str:
    caps = [s for s in scene.surfaces if s.kind == "cap"]
    return (
        f"{len(scene.entities)} entities, {len(scene.blocks)} blocks, "
        f"{sum(c.n_patches for c in caps)} cap patches"
    )


def run(options: ClipStep | ClipBoxStep, args: ClipCommand) -> int:
    from geobrep.ops.clipping import clip, clip_box
    from geobrep.ops.io import as_scene, write

    scene = read_input(args, args.input, format=args.format)
    output = Path(args.output)
    cut: dict[str, Any] = {
        "tolerance": options.tolerance,
        "options": options.options,
        "clippers": options.clippers,
    }
    results: list[tuple[Path, Any, str]] = []
    plane = None
    if isinstance(options, ClipBoxStep):
        result = clip_box(scene, list(options.bounds or ()), **cut)
        results.append((output, as_scene(result if result is not None else []), "inside of"))
    else:
        plane = Plane(*options.plane)
        if options.keep == "both":
            negative, positive = clip(scene, plane, keep="both", **cut)
            for path, part, side in zip(
                both_paths(output), (negative, positive), ("negative", "positive"), strict=True
            ):
                results.append((path, part, f"{side} side of"))
        else:
            kept = clip(scene, plane, keep=options.keep, **cut)
            results.append((output, kept, f"{options.keep} side of"))
    where = f"{plane_text(args, options)} ({span_text(scene)})"
    refuse_empty(
        args,
        [
            f"{path}: nothing on the {side} {where}"
            for path, part, side in results
            if is_empty(part)
        ],
        consequence="no file written",
    )
    one_side = isinstance(options, ClipStep) and options.keep != "both"
    if plane is not None and one_side and _misses(plane, scene):
        warn(f"{output}: {plane_text(args, options)} does not meet the model ({span_text(scene)})")
    for path, part, _ in results:
        write(part, path, format=args.output_format)
        print(f"{path}: {_describe(part)}")
    return 0


COMMAND = ClipCommand
OPTIONS_FOR = clip_options
