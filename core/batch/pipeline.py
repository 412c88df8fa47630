"""Pipeline files: a list of steps (read, clip, fit, build blocks, voxelize, write, ...) per input.

A pipeline is a YAML or JSON document validated by :class:`Pipeline` (its JSON Schema is
``schemas/pipeline.schema.json``)::

    version: 1
    inputs: ["models/*.ml"]          # paths or globs, relative to the pipeline file
    output: out                      # the output folder, relative to the pipeline file
    steps:
      - read: {format: gocad}
      - clip: {plane: [1, 0, 0, -450500], keep: negative}
      - voxelize: {depth: 7}
      - write: {format: native, name: "{stem}_west.geobrep"}

Every step is a mapping with one key, the step kind (:data:`STEP_KINDS`). Formats, clippers,
fitters and builders are looked up in the plugin registries and their options validated by the
plugin's own options model by :meth:`Pipeline.check`, before any file is touched: a typo fails
at once, naming the step (counted from 1), its kind and the option. Running is done by
:func:`geobrep.batch.pipeline_run.run_pipeline`.

>>> pipeline = Pipeline.from_data({"inputs": ["a.geobrep"], "steps": [
...     {"clip": {"plane": [1, 0, 0, -450500]}}, {"write": {"format": "vtu"}}]})
>>> [step.kind for step in pipeline.step_list]
['clip', 'write']
>>> Pipeline.from_data({"steps": [{"clipp": {}}]})
Traceback (most recent call last):
...
geobrep.errors.OptionsError: pipeline: step 1: unknown step kind 'clipp'; step kinds: read, reproject, clip, ..., render, view
"""  # noqa: E501

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping
from os import PathLike
from pathlib import Path, PureWindowsPath
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal, Union

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    FiniteFloat,
    JsonValue,
    NonNegativeFloat,
    PrivateAttr,
    Tag,
    ValidationError,
    field_validator,
    model_validator,
)
from pydantic.json_schema import SkipJsonSchema

from geobrep.batch.limits import MAX_FILE_BYTES, check_json_depth, load_yaml
from geobrep.batch.outputs import NAME_FIELDS, check_name_pattern, format_name, uses_half
from geobrep.errors import FileAccessError, FormatError, GeobrepError, OptionsError
from geobrep.host.operations import (
    Cli,
    as_dict,
    as_nested_dict,
    comma_items,
    comma_numbers,
    key_value,
)

if TYPE_CHECKING:
    from geobrep.host.registry import Registries

__all__ = [
    "NAME_FIELDS",
    "STEP_KINDS",
    "BuildBlocksStep",
    "BuildStep",
    "CheckStep",
    "ClipBoxStep",
    "ClipStep",
    "ConvertStep",
    "FitStep",
    "MapProductsStep",
    "OperationStep",
    "OutputStep",
    "Pipeline",
    "ReadStep",
    "RenderStep",
    "RepairStep",
    "ReprojectStep",
    "SectionStep",
    "StepOptions",
    "ViewStep",
    "VoxelizeStep",
    "WriteStep",
    "confinement_problem",
    "option_names",
]

PathArg = str | PathLike[str]
Plane4 = tuple[FiniteFloat, FiniteFloat, FiniteFloat, FiniteFloat]
Bounds6 = tuple[FiniteFloat, FiniteFloat, FiniteFloat, FiniteFloat, FiniteFloat, FiniteFloat]
Options = dict[str, JsonValue]


class StepOptions(BaseModel):
    """What every step body shares: unknown keys are errors; ``kind`` is the step's key."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    kind: ClassVar[str] = ""

    def check(self, registries: Registries) -> None:
        """Resolve plugin items and validate their options (raises OptionsError)."""


class ReadStep(StepOptions):
    """Read the input file: ``format`` names a registered format (default: from the extension
    and content; points tables ``.csv``/``.xyz``/``.txt``/``.dat`` are the ``csv`` format);
    ``options`` are that format's options. Optional; if present, first."""

    kind: ClassVar[str] = "read"

    format: str | None = None
    options: Options = Field(default_factory=dict)

    def check(self, registries: Registries) -> None:
        if self.format is None:
            if self.options:
                raise OptionsError("options need a format name (options belong to one format)")
            return
        spec = _get(registries.formats, self.format)
        if not spec.can_read:
            raise OptionsError(
                f"format {self.format!r} cannot read; formats that can: "
                + ", ".join(s.name for s in registries.formats.readers())
            )
        spec.validate_options(self.options)


class ReprojectStep(StepOptions):
    """Transform every entity into the CRS ``to`` (EPSG:xxxx or an EPSG code, WKT, PROJ);
    ``from`` overrides (or supplies) the CRS of the input."""

    model_config = ConfigDict(populate_by_name=True)

    kind: ClassVar[str] = "reproject"

    to: Annotated[str | int, Cli(flags=("--to",))]
    """target CRS: EPSG:xxxx, WKT or PROJ string"""
    source: Annotated[str | int | None, Cli(flags=("--from",))] = Field(default=None, alias="from")
    """source CRS, when the file has none (or to override it)"""

    def check(self, registries: Registries) -> None:
        from geobrep.gis.crs_ops import crs_from_user_input

        for label, value in (("to", self.to), ("from", self.source)):
            if value is not None:
                try:
                    crs_from_user_input(value)
                except GeobrepError as exc:
                    raise OptionsError(f"option {label!r}: {exc}") from exc


class _CutStep(StepOptions):
    tolerance: NonNegativeFloat | None = None
    """On-plane distance (default: 1e-9 × the diagonal of the scene's bounding box)."""
    options: Annotated[
        dict[str, Options],
        Cli(
            flags=("--option",),
            append=True,
            parse=key_value,
            collect=as_nested_dict,
            metavar="CLIPPER.KEY=VALUE",
        ),
    ] = Field(default_factory=dict)
    """Options per clipper name, e.g. ``{annotation: {precision: stroke}}``."""
    clippers: Annotated[
        dict[str, str],
        Cli(
            flags=("--clipper",),
            append=True,
            parse=key_value,
            collect=as_dict,
            metavar="TYPE=CLIPPER",
        ),
    ] = Field(default_factory=dict)
    """The clipper to use per entity type, when several are registered."""

    def check(self, registries: Registries) -> None:
        clippers = registries.clippers
        for name, options in self.options.items():
            _get(clippers, name, "options").validate_options(options)
        for entity_type, name in self.clippers.items():
            spec = _get(clippers, name, "clippers")
            if spec.entity_type != entity_type:
                raise OptionsError(
                    f"option 'clippers': clipper {name!r} cuts {spec.entity_type}, "
                    f"not {entity_type}"
                )


class ClipStep(_CutStep):
    """Cut by ``plane`` ``[a, b, c, d]`` and keep one side: ``negative`` (a·x+b·y+c·z+d < 0)
    or ``positive``, or ``both``: the two halves go on as two scenes through the following
    steps, and each write step writes both (named by ``{half}``, or ``NAME-negative.EXT`` and
    ``NAME-positive.EXT`` as ``geobrep clip --keep both``). Cut blocks are closed again by
    caps."""

    kind: ClassVar[str] = "clip"

    plane: Annotated[
        Plane4, Cli(group="plane", required=True, parse=comma_numbers(4), metavar="A,B,C,D")
    ]
    """The plane a·x + b·y + c·z + d = 0."""
    keep: Literal["negative", "positive", "both"] = "negative"
    """The side kept: negative (a·x+b·y+c·z+d < 0), positive, or both (two scenes from here
    on; each output named by {half} or NAME-negative.EXT and NAME-positive.EXT)."""


class ClipBoxStep(_CutStep):
    """Keep the inside of the box ``bounds`` ``[xmin, xmax, ymin, ymax, zmin, zmax]``, or of
    convex ``planes`` (normals pointing out)."""

    kind: ClassVar[str] = "clip_box"

    bounds: Bounds6 | None = None
    """The box [xmin, xmax, ymin, ymax, zmin, zmax] whose inside is kept."""
    planes: tuple[Plane4, ...] | None = Field(default=None, min_length=1)
    """Or convex planes [a, b, c, d] whose negative sides all hold the inside."""

    @model_validator(mode="after")
    def _one_region(self) -> ClipBoxStep:
        if (self.bounds is None) == (self.planes is None):
            raise ValueError("give either bounds [xmin, xmax, ymin, ymax, zmin, zmax] or planes")
        if self.bounds is not None:
            xmin, xmax, ymin, ymax, zmin, zmax = self.bounds
            if not (xmin <= xmax and ymin <= ymax and zmin <= zmax):
                raise ValueError(
                    f"bounds: expected xmin ≤ xmax, ymin ≤ ymax, zmin ≤ zmax: {list(self.bounds)}"
                )
        return self


class SectionStep(_CutStep):
    """Replace the scene by its section on ``plane``: a polygon per cut block, a trace line per
    cut surface (a fence-diagram panel; GeoPackage/GeoJSON layers hold it)."""

    kind: ClassVar[str] = "section"

    plane: Annotated[
        Plane4, Cli(group="plane", required=True, parse=comma_numbers(4), metavar="A,B,C,D")
    ]
    """The plane a·x + b·y + c·z + d = 0."""


def _one_name(text: str) -> tuple[str]:
    return (text,)


def confinement_problem(name: str) -> str | None:
    """Why a file a pipeline step reads may lie outside the pipeline's folder (None: it may
    not). Such paths are relative, with no ``..`` part; symlinks are checked when it is read."""
    if not name or PureWindowsPath(name).anchor or Path(name).is_absolute():
        return "is not a path relative to the pipeline's folder (a step reads files in it only)"
    if ".." in PureWindowsPath(name).parts:
        return "leaves the pipeline's folder (a step reads files in it only; no '..')"
    return None


def _marker_weight(text: str) -> float | str:
    """``--marker-weight``: a number, or ``hard``."""
    if text == "hard":
        return text
    try:
        return float(text)
    except ValueError:
        raise OptionsError(f"--marker-weight: expected a number or 'hard', got {text!r}") from None


class FitStep(StepOptions):
    """Fit a surface to each PointSet (or to the entities named in ``points``) with the
    fitter ``method``; ``options`` are the fitter's (e.g. ``epsilon``). The scene becomes the
    fitted surfaces (plus the points with ``keep_input``); ``check`` fails the file when a fit
    does not meet ε. A later write step whose format cannot hold NURBS writes a mesh whose σ
    and max |d| are within 2 % of the surface's (at most ``max_triangles``); its accuracy is
    noted, and ``check`` judges that mesh too."""

    kind: ClassVar[str] = "fit"

    method: str = "hybrid"
    """fitter: skinning, approximation, kriging, hybrid, ... (default hybrid)"""
    points: Annotated[
        tuple[str, ...] | None, Cli(flags=("--entity",), parse=_one_name, metavar="NAME")
    ] = Field(default=None, min_length=1)
    """names of the PointSets (or PolyLines) to fit (default: every PointSet); on the command
    line, the one to fit when the file holds several"""
    options: Annotated[
        Options,
        Cli(
            flags=("--option",), append=True, parse=key_value, collect=as_dict, metavar="KEY=VALUE"
        ),
    ] = Field(default_factory=dict)
    """a fitter option (VALUE is JSON when it parses, else text); repeatable"""
    keep_input: Annotated[bool, Cli(hidden=True)] = False
    """keep the points and the rest of the scene beside the surfaces"""
    check_epsilon: Annotated[bool, Cli(flags=("--check",))] = Field(default=False, alias="check")
    """fail when what was written does not meet ε (the command: exit status 3)"""
    max_triangles: Annotated[int, Cli(metavar="N")] = Field(default=1_000_000, ge=2)
    """bound on the mesh written of each fitted NURBS surface when the format cannot hold NURBS
    (default 1000000)"""
    markers: Annotated[tuple[str, ...] | None, Cli(nargs="+", metavar="WELLFILE")] = Field(
        default=None, min_length=1
    )
    """well files whose markers join the points (in a pipeline: relative to its folder and
    inside it)"""
    marker_surface: Annotated[str | None, Cli(metavar="NAME")] = None
    """the surface the markers must name (needed when they name several)"""
    marker_weight: Annotated[
        Annotated[FiniteFloat, Field(ge=0)] | Literal["hard"] | None,
        Cli(parse=_marker_weight, metavar="W|hard"),
    ] = None
    """weight of the markers in a least-squares fit, or 'hard': the surface passes through them"""

    model_config = ConfigDict(populate_by_name=True)

    @field_validator("markers", mode="before")
    @classmethod
    def _one_well_file(cls, value: Any) -> Any:
        return [value] if isinstance(value, str | PathLike) else value

    @model_validator(mode="after")
    def _markers_given(self) -> FitStep:
        if self.markers is None and (
            self.marker_surface is not None or self.marker_weight is not None
        ):
            raise ValueError("marker_surface and marker_weight need markers (the well files)")
        return self

    def check(self, registries: Registries) -> None:
        _get(registries.fitters, self.method, "method").validate_options(self.options)


class BuildBlocksStep(StepOptions):
    """Build blocks, patches, arcs and corners from the scene's conformal surfaces (existing
    blocks and topology are replaced) with ``builder`` and its ``options``."""

    kind: ClassVar[str] = "build_blocks"

    builder: str = "blocks"
    """the registered builder (default blocks)"""
    options: Annotated[
        Options,
        Cli(
            flags=("--option",), append=True, parse=key_value, collect=as_dict, metavar="KEY=VALUE"
        ),
    ] = Field(default_factory=dict)
    """a builder option (VALUE is JSON when it parses, else text; the blocks builder's options
    are flags of their own); repeatable"""

    def check(self, registries: Registries) -> None:
        _get(registries.builders, self.builder, "builder").validate_options(self.options)


class BuildStep(BuildBlocksStep):
    """Run any registered builder (a plugin's) on the scene: ``builder`` and its ``options``."""

    kind: ClassVar[str] = "build"

    builder: str
    """the registered builder (a plugin's)"""


class VoxelizeStep(StepOptions):
    """Append the linear octree of the scene's blocks (or closed surfaces) — the options of
    :func:`geobrep.voxelize`."""

    kind: ClassVar[str] = "voxelize"

    depth: int = Field(default=8, ge=0)
    """finest level: 2**depth cells per axis (default 8)"""
    method: Literal["depth-buffer", "exact", "auto"] = "auto"
    """depth buffers, all ray crossings, or auto (default: auto)"""
    fill_rule: Literal["parity", "nonzero"] = "parity"
    """inside test of the exact mode (default: parity)"""
    bodies: Annotated[tuple[str | int, ...] | None, Cli(parse=comma_items)] = None
    """comma-separated names or ids of blocks/surfaces (default: every block)"""
    origin: Annotated[
        tuple[FiniteFloat, FiniteFloat, FiniteFloat] | None,
        Cli(parse=comma_numbers(3), metavar="X,Y,Z"),
    ] = None
    """cube origin X,Y,Z (default: bounds)"""
    size: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    """cube edge (default: largest extent)"""
    block_depth: int | None = Field(default=None, ge=0)
    """process 8**N sub-cubes one at a time (default depth-8)"""
    name: str | None = None
    """name of the octree (default: from the model's name)"""

    def builder_options(self) -> dict[str, Any]:
        """The options of the ``voxelize`` voxelizer."""
        return self.model_dump(exclude_unset=True)

    def check(self, registries: Registries) -> None:
        _get(registries.voxelizers, "voxelize", "voxelizer").validate_options(
            self.builder_options()
        )


class CheckStep(StepOptions):
    """Inspect the scene (:func:`geobrep.inspect`); the scene flows on unchanged. Defects
    ``fail`` the input (default), ``warn`` (a warning naming the counts), or ``continue``
    (noted in the summary only)."""

    kind: ClassVar[str] = "check"

    checks: Annotated[tuple[str, ...] | None, Cli(parse=comma_items)] = None
    """comma-separated check names, or all (default: the default checks)"""
    tolerance: float | None = Field(default=None, ge=0, allow_inf_nan=False)
    """distance under which points count as one (default: from the data's precision)"""
    on_defects: Literal["fail", "warn", "continue"] = "fail"
    """what defects do: fail, warn or continue (default: fail)"""

    def check(self, registries: Registries) -> None:
        for name in self.checks or ():
            if name != "all":
                _get(registries.checks, name, "check")


class RepairStep(StepOptions):
    """Mend what inspection finds (:func:`geobrep.repair`): weld, drop degenerate, duplicated
    and isolated elements, split T-junctions, orient patches and blocks."""

    kind: ClassVar[str] = "repair"

    actions: Annotated[tuple[str, ...] | None, Cli(parse=comma_items)] = None
    """comma-separated repair actions (default: all of them)"""
    tolerance: float | None = Field(default=None, ge=0, allow_inf_nan=False)
    """weld/contact tolerance (default: from the data's precision)"""


def _top(text: str) -> str | int | None:
    """A ``parse`` for ``--top``: a surface's name, its id (digits), or ``none``."""
    text = text.strip()
    if text.lower() == "none":
        return None
    return int(text) if text.isdigit() else text


class MapProductsStep(StepOptions):
    """Map products of a structural model, as GIS layers (:func:`geobrep.map_products`): the
    outline of each block on the map plane (layer ``block_outlines``), where faults and
    horizons meet the ``top`` surface (``traces``), and sections at ``section_levels`` (z) and
    on ``section_planes`` (``sections``, and ``sections_plane`` in a plane's own coordinates).
    The scene becomes the products, in the model's CRS (write it to GeoPackage)."""

    kind: ClassVar[str] = "map_products"

    top: Annotated[str | int | None, Cli(parse=_top, metavar="NAME")] = "top"
    """the top (topographic) surface of the traces, by name or id (none: no traces)"""
    section_levels: Annotated[
        tuple[FiniteFloat, ...], Cli(parse=comma_numbers(None, "levels"), metavar="Z,Z,...")
    ] = ()
    """z values of horizontal sections"""
    section_planes: Annotated[
        tuple[Plane4, ...],
        Cli(
            flags=("--section-plane",),
            append=True,
            parse=comma_numbers(4, "plane coefficients"),
            metavar="A,B,C,D",
        ),
    ] = ()
    """other section planes a·x + b·y + c·z + d = 0 (vertical sections; repeatable)"""
    elevation: FiniteFloat = 0.0
    """z of the block outlines"""
    with_section_lines: bool = False
    """add the lines where horizons, faults and boundaries cross the section planes"""
    section_coordinates: Literal["world", "plane", "both"] = "both"
    """sections of vertical and inclined planes in world coordinates, in their plane's own, or
    both"""


class OutputStep(StepOptions):
    """A step that writes a file (``write``, ``convert``, ``render``, ``view``): the scene as
    it is at this step goes to ``<output>/<name>`` and flows on unchanged. ``name`` is a
    file-name pattern with the bare fields ``{stem}``, ``{name}``, ``{ext}``, ``{index}``,
    ``{half}`` (no attribute access, indexing or format spec, and the file must lie in the
    output folder). After a clip keeping both sides, the step writes each half (see
    :meth:`Pipeline.halves`). Files appear only when the whole pipeline succeeded for that
    input."""

    #: The format every step of this kind writes (None: the step's own ``format``).
    fixed_format: ClassVar[str | None] = None

    name: str | None = None
    """the file-name pattern (default: {stem} and the format's extension)"""
    allow_empty: bool = False
    """Write a scene with nothing in it (by default that fails the input: a clip that missed
    the model should not pass for a result)."""

    @model_validator(mode="after")
    def _pattern(self) -> OutputStep:
        if self.name is not None:
            check_name_pattern(self.name)
        return self

    def writer_format(self) -> str | None:
        """The registered format written (None: from the file name's extension)."""
        return self.fixed_format

    def writer_options(self) -> dict[str, Any]:
        """The keywords of the format's writer."""
        return {}

    def tessellates(self) -> bool:
        """Whether NURBS surfaces become meshes for a format that cannot hold them."""
        return False

    def verifies(self) -> bool:
        """Whether each written file is read back and checked against its report."""
        return False

    def pattern(self, registries: Registries) -> str:
        """The file-name pattern, with the format's extension when ``name`` is not given."""
        if self.name is not None:
            return self.name
        spec = registries.formats.get(str(self.writer_format()))
        return "{stem}" + (spec.extensions[0] if spec.extensions else f".{spec.name}")

    def format_name(self, registries: Registries) -> str:
        """The registered format this step writes with."""
        written = self.writer_format()
        if written is not None:
            return written
        fields: dict[str, str | int] = {
            "stem": "x",
            "name": "x.x",
            "ext": ".x",
            "index": 0,
            "half": "x",
        }
        sample = format_name(self.pattern(registries), fields)
        return registries.formats.choose_writer(Path(sample)).name

    def check(self, registries: Registries) -> None:
        written = self.writer_format()
        if written is not None:
            spec = _get(registries.formats, written)
            if not spec.can_write:
                raise OptionsError(
                    f"format {written!r} cannot write; formats that can: "
                    + ", ".join(s.name for s in registries.formats.writers())
                )
        else:
            spec = registries.formats.get(self.format_name(registries))
        spec.validate_options(self.writer_options())


class WriteStep(OutputStep):
    """Write the scene as it is at this step (the scene flows on unchanged) to
    ``<output>/<name>``: ``format`` names a registered format, ``name`` a file-name pattern
    (see :class:`OutputStep`; default ``{stem}`` + the format's extension); ``options`` are the
    format's. NURBS surfaces are tessellated when the format cannot hold them
    (``tessellate``)."""

    kind: ClassVar[str] = "write"

    format: str | None = None
    options: Options = Field(default_factory=dict)
    tessellate: bool = True
    verify: bool = False
    """Read each written file back: a file that lacks something its report does not list as
    lost fails the input."""

    @model_validator(mode="after")
    def _target(self) -> WriteStep:
        if self.format is None and self.name is None:
            raise ValueError("give a format, a file name pattern (name), or both")
        return self

    def writer_format(self) -> str | None:
        return self.format

    def writer_options(self) -> dict[str, Any]:
        return dict(self.options)

    def tessellates(self) -> bool:
        return self.tessellate

    def verifies(self) -> bool:
        return self.verify


class ConvertStep(WriteStep):
    """Write the scene as it was read, as ``geobrep convert`` does: the same as ``write`` but
    NURBS surfaces the format cannot hold are reported lost rather than tessellated (unless
    ``tessellate``); ``convert: {format: vtu}`` reads naturally after ``read``. On the command
    line ``--to`` gives ``format``, and ``OUT`` or ``-o DIR`` the file ``name``."""

    kind: ClassVar[str] = "convert"

    format: Annotated[str | None, Cli(hidden=True)] = None
    """the format written (geobrep convert: --to)"""
    name: Annotated[str | None, Cli(hidden=True)] = None
    """the file-name pattern (geobrep convert: OUT's name, or {stem} and the extension)"""
    options: Annotated[
        Options,
        Cli(
            flags=("--option",), append=True, parse=key_value, collect=as_dict, metavar="KEY=VALUE"
        ),
    ] = Field(default_factory=dict)
    """the options of the format's writer"""
    tessellate: bool = False
    """write NURBS surfaces as meshes when the format cannot hold them (otherwise they are
    reported lost)"""


def _triple(text: str) -> tuple[float, float, float]:
    """A ``parse`` for three numbers, separated by commas or spaces: ``1,2,3``, ``"0 0 1"``."""
    try:
        values = tuple(float(v) for v in text.replace(",", " ").split())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}") from None
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}")
    return values[0], values[1], values[2]


Triple = tuple[float, float, float]
View = Literal["isometric", "top", "bottom", "north", "south", "east", "west"]


class RenderStep(OutputStep):
    """Render a picture of the scene off-screen (the ``png`` format: pyvista, extra ``viz``),
    as ``geobrep render`` does: colour by entity, block or property, a cut-away plane or a
    section, a legend, axes in world coordinates, a scale bar and the CRS in the title;
    ``name`` defaults to ``{stem}.png``. The scene flows on unchanged."""

    kind: ClassVar[str] = "render"
    fixed_format: ClassVar[str | None] = "png"

    name: Annotated[str | None, Cli(hidden=True)] = None
    """the file-name pattern (default: {stem}.png; geobrep render: OUT)"""
    color_by: Literal["entity", "block", "property"] | None = None
    """colour each entity, each block, or by a property (default: entity; property when
    --property is given)"""
    property: str | None = None
    """property to colour by"""
    clip_origin: Annotated[Triple | None, Cli(parse=_triple, metavar="X,Y,Z")] = None
    """a point of the cut-away plane"""
    clip_normal: Annotated[Triple | None, Cli(parse=_triple, metavar="NX,NY,NZ")] = None
    """normal of the cut-away plane (the side it points to is removed)"""
    section_origin: Annotated[Triple | None, Cli(parse=_triple, metavar="X,Y,Z")] = None
    """a point of the section plane"""
    section_normal: Annotated[Triple | None, Cli(parse=_triple, metavar="NX,NY,NZ")] = None
    """normal of the section plane: the side it points to is removed, blocks are closed by the
    cut, and the picture looks at the cut"""
    view: View | None = None
    """where the camera looks from (default: isometric, or square to the section)"""
    azimuth: Annotated[float, Cli(metavar="DEG")] = 0.0
    """turn the camera about the vertical by DEG degrees"""
    elevation: Annotated[float, Cli(metavar="DEG")] = 0.0
    """raise the camera by DEG degrees"""
    title: str | None = None
    """the picture's title (default: model name and CRS)"""
    legend: Annotated[bool, Cli(negate="--no-legend")] = True
    """no legend of names and colours"""
    axes: Annotated[bool, Cli(negate="--no-axes")] = True
    """no axes with coordinates"""
    scale_bar: Annotated[bool, Cli(negate="--no-scale-bar")] = True
    """no scale bar"""
    size: Annotated[tuple[int, int], Cli(nargs=2, parse=int, metavar=("W", "H"))] = (1200, 900)
    """picture size in pixels"""
    edges: bool = False
    """draw triangle edges"""
    vertical_exaggeration: Annotated[float, Cli(metavar="F")] = 1.0
    """scale of z relative to x and y"""

    def writer_options(self) -> dict[str, Any]:
        """The options of the ``png`` writer these options give.

        Raises:
            OptionsError: a plane's origin without its normal, or its normal without its origin.
        """
        for name in ("clip", "section"):
            if (getattr(self, f"{name}_origin") is None) != (
                getattr(self, f"{name}_normal") is None
            ):
                raise OptionsError(f"--{name}-origin and --{name}-normal go together")
        return {
            "color_by": self.color_by or ("property" if self.property else "entity"),
            "property": self.property,
            "clip_origin": self.clip_origin,
            "clip_normal": self.clip_normal,
            "window_size": tuple(self.size),
            "show_edges": self.edges,
            "vertical_exaggeration": self.vertical_exaggeration,
            "section_origin": self.section_origin,
            "section_normal": self.section_normal,
            "view": self.view,
            "azimuth": self.azimuth,
            "elevation": self.elevation,
            "title": self.title,
            "legend": self.legend,
            "axes": self.axes,
            "scale_bar": self.scale_bar,
        }


class ViewStep(OutputStep):
    """Write the scene as one offline HTML page to look at in a browser (the ``html`` format:
    three.js inlined, blocks, surfaces, grids and wells switchable, a clipping plane, axes in
    world coordinates), as ``geobrep view`` does; ``name`` defaults to ``{stem}.html``. The scene
    flows on unchanged."""

    kind: ClassVar[str] = "view"
    fixed_format: ClassVar[str | None] = "html"

    name: Annotated[str | None, Cli(hidden=True)] = None
    """the file-name pattern (default: {stem}.html; geobrep view: -o)"""
    title: str | None = None
    """the page's title (default: the model's name)"""
    blocks: Annotated[bool, Cli(negate="--no-blocks")] = True
    """do not show blocks (only surfaces, lines, points)"""
    all_surfaces: bool = False
    """with blocks, start with every surface shown too (default: only faults)"""
    property: str | None = None
    """colour the grids by this cell or point property"""

    def writer_options(self) -> dict[str, Any]:
        """The options of the ``html`` writer these options give."""
        return {
            "title": self.title,
            "blocks": self.blocks,
            "surfaces_with_blocks": self.all_surfaces,
            "property": self.property,
        }


class OperationStep(StepOptions):
    """A step of an operation a plugin registered (``geobrep_register_operations``): written
    ``NAME: {option: value, ...}`` like the built-in steps, its options validated by the
    operation's own options model."""

    operation: str
    """The operation's step kind."""
    options: Options = Field(default_factory=dict)
    """The operation's options."""

    @property
    def kind(self) -> str:  # type: ignore[override]
        """The step kind: the operation's."""
        return self.operation

    def check(self, registries: Registries) -> None:
        _operation(registries, self.operation).validate_options(self.options)


def _operation(registries: Registries, kind: str) -> Any:
    spec = registries.operations.for_step(kind)
    if spec is None or kind in _BY_KIND:
        raise OptionsError(
            f"no operation has the step kind {kind!r}; operations: "
            + (", ".join(s.name for s in registries.operations) or "none registered")
        )
    return spec


def plugin_step_kinds() -> list[str]:
    """The step kinds of the operations plugins registered (beside :data:`STEP_KINDS`)."""
    from geobrep.host import registries

    kinds = (spec.step_kind for spec in registries().operations)
    return [kind for kind in kinds if kind is not None and kind not in _BY_KIND]


_STEP_TYPES: tuple[type[StepOptions], ...] = (
    ReadStep,
    ReprojectStep,
    ClipStep,
    ClipBoxStep,
    SectionStep,
    FitStep,
    BuildBlocksStep,
    BuildStep,
    VoxelizeStep,
    CheckStep,
    RepairStep,
    MapProductsStep,
    WriteStep,
    ConvertStep,
    RenderStep,
    ViewStep,
)
STEP_KINDS: tuple[str, ...] = tuple(t.kind for t in _STEP_TYPES)
"""Every step kind, in the order the documentation presents them."""
_BY_KIND = {t.kind: t for t in _STEP_TYPES}


# One wrapper per kind: a step is written as a mapping with one key, the kind.
class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    @property
    def body(self) -> StepOptions:
        value = next(iter(self.__dict__.values()))
        assert isinstance(value, StepOptions)
        return value


class ReadEntry(_Entry):
    read: ReadStep


class ReprojectEntry(_Entry):
    reproject: ReprojectStep


class ClipEntry(_Entry):
    clip: ClipStep


class ClipBoxEntry(_Entry):
    clip_box: ClipBoxStep


class SectionEntry(_Entry):
    section: SectionStep


class FitEntry(_Entry):
    fit: FitStep


class BuildBlocksEntry(_Entry):
    build_blocks: BuildBlocksStep


class BuildEntry(_Entry):
    build: BuildStep


class VoxelizeEntry(_Entry):
    voxelize: VoxelizeStep


class CheckEntry(_Entry):
    check: CheckStep


class RepairEntry(_Entry):
    repair: RepairStep


class MapProductsEntry(_Entry):
    map_products: MapProductsStep


class WriteEntry(_Entry):
    write: WriteStep


class ConvertEntry(_Entry):
    convert: ConvertStep


class RenderEntry(_Entry):
    render: RenderStep


class ViewEntry(_Entry):
    view: ViewStep


class OperationEntry(_Entry):
    operation: OperationStep


def _step_tag(value: Any) -> str | None:
    if isinstance(value, OperationEntry):
        return "operation"
    if isinstance(value, Mapping) and len(value) == 1:
        return str(next(iter(value)))
    if isinstance(value, _Entry):
        return value.body.kind
    return None


Step = Annotated[
    Union[  # noqa: UP007  (the members carry tags)
        Annotated[ReadEntry, Tag("read")],
        Annotated[ReprojectEntry, Tag("reproject")],
        Annotated[ClipEntry, Tag("clip")],
        Annotated[ClipBoxEntry, Tag("clip_box")],
        Annotated[SectionEntry, Tag("section")],
        Annotated[FitEntry, Tag("fit")],
        Annotated[BuildBlocksEntry, Tag("build_blocks")],
        Annotated[BuildEntry, Tag("build")],
        Annotated[VoxelizeEntry, Tag("voxelize")],
        Annotated[CheckEntry, Tag("check")],
        Annotated[RepairEntry, Tag("repair")],
        Annotated[MapProductsEntry, Tag("map_products")],
        Annotated[WriteEntry, Tag("write")],
        Annotated[ConvertEntry, Tag("convert")],
        Annotated[RenderEntry, Tag("render")],
        Annotated[ViewEntry, Tag("view")],
        SkipJsonSchema[Annotated[OperationEntry, Tag("operation")]],
    ],
    Discriminator(_step_tag),
]


class Pipeline(BaseModel):
    """A pipeline document: ``version``, ``inputs``, ``output`` and ``steps``.

    Build one from a file with :meth:`load`, from a mapping with :meth:`from_data`; steps may
    also be given as step bodies (``ClipStep(plane=(1, 0, 0, -5))``). Relative ``inputs`` and
    ``output`` are relative to the pipeline file (:attr:`base_dir`), else to the working folder.
    """

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        use_attribute_docstrings=True,
        title="geobrep pipeline",
        json_schema_extra={
            "description": "A geobrep pipeline: steps applied to every input file "
            "(geobrep run pipeline.yaml)."
        },
    )

    version: Literal[1] = 1
    inputs: tuple[str, ...] = ()
    """Input files: paths or glob patterns (``models/**/*.ts``)."""
    output: str = "output"
    """The folder outputs are written to (created when missing)."""
    steps: tuple[Step, ...] = Field(min_length=1)
    """The steps, applied in order to each input; the scene flows from one to the next."""

    _base_dir: Path | None = PrivateAttr(default=None)
    _source: str = PrivateAttr(default="pipeline")

    @field_validator("inputs", mode="before")
    @classmethod
    def _one_input(cls, value: Any) -> Any:
        return [value] if isinstance(value, str | PathLike) else value

    @field_validator("steps", mode="before")
    @classmethod
    def _step_shapes(cls, value: Any) -> Any:
        if not isinstance(value, list | tuple):
            return value
        return [_shape(number, item) for number, item in enumerate(value, 1)]

    @model_validator(mode="after")
    def _order(self) -> Pipeline:
        kinds = [step.kind for step in self.step_list]
        if "read" in kinds[1:]:
            raise ValueError(
                f"step {kinds.index('read', 1) + 1}: read must be the first step (or left out)"
            )
        if not any(isinstance(step, OutputStep) for step in self.step_list):
            raise ValueError("the pipeline writes nothing: add a write step")
        for number, step in enumerate(self.step_list, 1):
            if isinstance(step, FitStep):
                for name in step.markers or ():
                    problem = confinement_problem(name)
                    if problem:
                        raise ValueError(f"step {number} (fit): markers: {name!r} {problem}")
        return self

    # -- access ---------------------------------------------------------------------------------
    @property
    def step_list(self) -> list[StepOptions]:
        """The step bodies, in order."""
        return [entry.body for entry in self.steps]

    @property
    def base_dir(self) -> Path | None:
        """The folder of the pipeline file (None for a pipeline built in Python)."""
        return self._base_dir

    def allowing_empty(self) -> Pipeline:
        """This pipeline with every write step writing empty results too (``--allow-empty``)."""
        steps = [
            entry.model_copy(
                update={
                    next(iter(type(entry).model_fields)): entry.body.model_copy(
                        update={"allow_empty": True}
                    )
                }
            )
            if isinstance(entry.body, OutputStep)
            else entry
            for entry in self.steps
        ]
        copy = self.model_copy(update={"steps": tuple(steps)})
        copy._base_dir, copy._source = self._base_dir, self._source
        return copy

    def with_base_dir(self, folder: PathArg | None) -> Pipeline:
        """This pipeline with relative paths resolved against ``folder``."""
        copy = self.model_copy()
        copy._base_dir = None if folder is None else Path(folder)
        copy._source = self._source
        return copy

    # -- construction ---------------------------------------------------------------------------
    @classmethod
    def from_data(cls, data: Any, source: str = "pipeline") -> Pipeline:
        """Validate a parsed document; errors are one :class:`OptionsError` naming each step."""
        if isinstance(data, Pipeline):
            return data
        if not isinstance(data, Mapping):
            raise OptionsError(
                f"{source}: a pipeline is a mapping (version, inputs, output, steps), "
                f"not {type(data).__name__}"
            )
        try:
            pipeline = cls.model_validate(data)
        except ValidationError as exc:
            raise OptionsError(f"{source}: {_describe(exc, data)}") from exc
        pipeline._source = source
        return pipeline

    @classmethod
    def load(cls, path: PathArg) -> Pipeline:
        """Read a pipeline file (``.yaml``/``.yml``, or ``.json``) and validate it.

        Raises:
            FileAccessError: the file is missing or unreadable.
            FormatError: not valid YAML/JSON (with the line), or over a limit: larger than
                ``MAX_FILE_BYTES`` (10 MB), nested deeper than ``MAX_DEPTH`` (64), or YAML
                aliases beyond ``MAX_ALIASES`` (100) or ``MAX_ALIAS_NODES`` (100,000 nodes
                added; see :mod:`geobrep.batch.limits`).
            OptionsError: the document is not a valid pipeline.
        """
        file = Path(path)
        try:
            with file.open("rb") as stream:
                raw = stream.read(MAX_FILE_BYTES + 1)
            text = raw.decode("utf-8")
        except FileNotFoundError as exc:
            raise FileAccessError("no such file", file) from exc
        except (OSError, UnicodeDecodeError) as exc:
            raise FileAccessError(f"cannot be read ({exc})", file) from exc
        if len(raw) > MAX_FILE_BYTES:
            raise FormatError(
                f"a pipeline file is at most {MAX_FILE_BYTES // 2**20} MB; this one is larger",
                file,
            )
        data = _parse(text, file)
        return cls.from_data(data, source=str(file)).with_base_dir(file.parent)

    def halves(self) -> list[tuple[str, ...]]:
        """Per write step, the halves it writes: ``("",)`` for the one scene, or ``("negative",
        "positive")`` after a clip keeping both (``"negative-positive"``, ... after two).

        >>> Pipeline.from_data({"steps": [{"write": {"format": "vtu"}},
        ...     {"clip": {"plane": [1, 0, 0, 0], "keep": "both"}}, {"write": {"format": "ply"}}]}
        ...     ).halves()
        [('',), ('negative', 'positive')]
        """
        halves: tuple[str, ...] = ("",)
        per_write: list[tuple[str, ...]] = []
        for step in self.step_list:
            if isinstance(step, ClipStep) and step.keep == "both":
                halves = tuple(
                    f"{half}-{side}" if half else side
                    for half in halves
                    for side in ("negative", "positive")
                )
            elif isinstance(step, OutputStep):
                per_write.append(halves)
        return per_write

    # -- plugin resolution ----------------------------------------------------------------------
    def check(self, registries: Registries | None = None) -> Pipeline:
        """Resolve every format, clipper, fitter and builder and validate its options.

        Returns ``self``; raises :class:`OptionsError` naming the step, its kind and the option.
        """
        if registries is None:
            from geobrep.host import registries as loaded

            registries = loaded()
        for number, step in enumerate(self.step_list, 1):
            try:
                step.check(registries)
            except GeobrepError as exc:
                raise OptionsError(f"{self._source}: step {number} ({step.kind}): {exc}") from exc
        writes = [
            (number, step.pattern(registries))
            for number, step in enumerate(self.step_list, 1)
            if isinstance(step, OutputStep)
        ]
        for (number, pattern), halves in zip(writes, self.halves(), strict=True):
            if uses_half(pattern) and halves == ("",):
                raise OptionsError(
                    f"{self._source}: step {number} ({self.step_list[number - 1].kind}): name "
                    f"pattern {pattern!r} uses "
                    "{half}, but no clip step before it keeps both sides"
                )
        seen: dict[str, int] = {}
        for number, pattern in writes:
            if pattern in seen:
                raise OptionsError(
                    f"{self._source}: steps {seen[pattern]} and {number} both write "
                    f"{pattern!r}: give one a different name pattern"
                )
            seen[pattern] = number
        return self


def _shape(number: int, item: Any) -> Any:
    """Check that a step is ``{kind: body}``; bare ``kind`` strings and bodies are accepted."""
    if isinstance(item, OperationStep):
        return {"operation": item}
    if isinstance(item, StepOptions):
        return {item.kind: item}
    if isinstance(item, _Entry):
        return item
    if isinstance(item, str):
        item = {item: None}
    if not isinstance(item, Mapping) or not item:
        raise ValueError(
            f"step {number}: a step is a mapping with one key, its kind (e.g. clip: {{...}}), "
            f"not {item!r}"
        )
    if len(item) != 1:
        keys = ", ".join(repr(str(k)) for k in item)
        kinds = [str(k) for k in item if k in _BY_KIND]
        hint = (
            f" (indent the options of {kinds[0]!r} under it)"
            if len(kinds) == 1 and item[kinds[0]] is None
            else ""
        )
        raise ValueError(
            f"step {number}: a step is a mapping with one key, its kind; got {keys}{hint}"
        )
    kind, body = next(iter(item.items()))
    if kind not in _BY_KIND and kind != "operation":
        plugins = plugin_step_kinds()
        if kind in plugins:
            return {"operation": {"operation": kind, "options": {} if body is None else body}}
        raise ValueError(
            f"step {number}: unknown step kind {kind!r}; step kinds: "
            + ", ".join([*STEP_KINDS, *plugins])
        )
    return {kind: {} if body is None else body}


def _describe(exc: ValidationError, data: Mapping[str, Any]) -> str:
    steps = data.get("steps")
    problems: list[str] = []
    errors = exc.errors(include_url=False)
    if any(e["loc"][:1] == ("steps",) and len(e["loc"]) > 1 for e in errors):
        # pydantic also counts the failed steps as missing: that is no news
        errors = [e for e in errors if not (e["loc"] == ("steps",) and e["type"] == "too_short")]
    for error in errors:
        loc = list(error["loc"])
        message = str(error["msg"]).removeprefix("Value error, ")
        if error["type"] == "extra_forbidden":
            message = "unknown option"
        if loc[:1] == ["steps"] and len(loc) >= 2 and isinstance(loc[1], int):
            number = loc[1] + 1
            kind = _step_tag(steps[loc[1]]) if isinstance(steps, list | tuple) else None
            rest = loc[2:]
            while rest and rest[0] == kind:  # the union tag, then the wrapper's field
                rest = rest[1:]
            where = f"step {number} ({kind})" if kind else f"step {number}"
            if error["type"] == "extra_forbidden" and rest and kind in _BY_KIND:
                valid = ", ".join(option_names(_BY_KIND[kind]))
                message = f"unknown option (valid options: {valid})"
            option = ".".join(str(part) for part in rest)
            problems.append(
                f"{where}: option {option!r}: {message}" if option else f"{where}: {message}"
            )
        elif loc == ["steps"] and message.startswith("step "):
            problems.append(message)
        elif loc:
            field = ".".join(str(part) for part in loc)
            if error["type"] == "extra_forbidden":
                message = f"unknown field (fields: {', '.join(Pipeline.model_fields)})"
            problems.append(f"{field}: {message}")
        else:
            problems.append(message)
    return "; ".join(problems)


def option_names(step_type: type[StepOptions]) -> list[str]:
    """The keys a step body takes (aliases where a field has one), in declaration order.

    >>> option_names(FitStep)[:6]
    ['method', 'points', 'options', 'keep_input', 'check', 'max_triangles']
    >>> option_names(FitStep)[6:]
    ['markers', 'marker_surface', 'marker_weight']
    """
    return [info.alias or name for name, info in step_type.model_fields.items()]


def _parse(text: str, file: Path) -> Any:
    if file.suffix.lower() == ".json":
        check_json_depth(text, file)
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise FormatError(f"not valid JSON: {exc.msg}", file, exc.lineno) from exc
    import yaml

    try:
        return load_yaml(text, file)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        line = mark.line + 1 if mark is not None else None
        raise FormatError(f"not valid YAML: {problem}", file, line) from exc


def _get(registry: Any, name: str, option: str = "format") -> Any:
    from geobrep.host.registry import UnknownItemError

    try:
        return registry.get(name)
    except UnknownItemError as exc:
        raise OptionsError(f"option {option!r}: {exc}") from exc
