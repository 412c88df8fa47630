"""Operations declared once: their options as a pydantic model, their work as a function of a Scene.

An :class:`OperationSpec` names an operation (``"voxelize"``, a plugin's ``"thin"``), its options
model and ``function(scene, options) -> Scene``. Everything else is derived from the
declaration, so the copies cannot drift:

* the Python function (:meth:`OperationSpec.__call__`: ``spec(scene, every=2)``),
* the command-line subcommand and its flags (:func:`add_arguments`, :func:`options_from_args`),
* the pipeline step (its body is the options model; its JSON Schema is the model's),
* the documentation's option table (:func:`options_table`).

The fields of the options model carry their help text (a docstring under the field, or
``Field(description=...)``) and, where the command line needs more than the field's name and
type, a :class:`Cli` marker::

    class ThinOptions(BaseModel):
        model_config = ConfigDict(extra="forbid", use_attribute_docstrings=True)

        every: Annotated[int, Cli(metavar="N")] = Field(default=2, ge=1)
        \"\"\"Keep every N-th point.\"\"\"

Plugins register operations with the ``geobrep_register_operations`` hook
(:class:`OperationRegistry`); geobrep's own operations are declared the same way.
"""

from __future__ import annotations

import types
import typing
import weakref
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal, Protocol, runtime_checkable

from pydantic import BaseModel, ValidationError
from pydantic.fields import FieldInfo

from geobrep.errors import OptionsError
from geobrep.host.registry import RegisteredItem, Registry

if TYPE_CHECKING:
    import argparse

    from geobrep.model.scene import Scene

__all__ = [
    "Cli",
    "FileOptions",
    "OperationFunction",
    "OperationRegistry",
    "OperationSpec",
    "add_arguments",
    "as_dict",
    "as_nested_dict",
    "cli_flags",
    "cli_of",
    "comma_items",
    "comma_numbers",
    "key_value",
    "options_from_args",
    "options_table",
]


@dataclass(frozen=True)
class Cli:
    """How an option appears on the command line, when its name and type are not enough.

    ``flags`` (default ``--field-name``); ``positional`` (an argument, not an option);
    ``metavar``, ``nargs``; ``group``: options of one group exclude each other, and the group is
    required when any member says ``required``; ``parse``: the text to value function (the
    argparse ``type``); ``negate``: for a boolean that is true by default, the flag that makes it
    false (``--no-validate``); ``append``: repeatable, values collected in a list (``parse``
    turns each) and folded into the field's value by ``collect``; ``hidden``: not on the
    command line (pipelines and Python only); ``help``: instead of the field's description.
    """

    flags: tuple[str, ...] = ()
    positional: bool = False
    metavar: str | tuple[str, ...] | None = None
    nargs: str | int | None = None
    group: str | None = None
    required: bool = False
    parse: Callable[[str], Any] | None = None
    negate: str | None = None
    append: bool = False
    hidden: bool = False
    help: str | None = None
    collect: Callable[[list[Any]], Any] | None = None


def cli_of(info: FieldInfo) -> Cli:
    """The :class:`Cli` marker of a field (a default one when it has none)."""
    for item in info.metadata:
        if isinstance(item, Cli):
            return item
    return Cli()


def cli_flags(name: str, info: FieldInfo) -> tuple[str, ...]:
    """The option strings of a field: ``("--fill-rule",)`` for ``fill_rule``; ``()`` if hidden.

    A positional field gives its name; a negated boolean gives its negating flag.
    """
    cli = cli_of(info)
    if cli.hidden:
        return ()
    if cli.positional:
        return (name,)
    if cli.negate:
        return (cli.negate,)
    return cli.flags or ("--" + name.replace("_", "-"),)


# -- text to values -----------------------------------------------------------------------------
def comma_numbers(count: int | None = None, what: str = "numbers") -> Callable[[str], list[float]]:
    """A ``parse`` for ``a,b,c,d``: ``count`` comma-separated numbers (any count: None)."""

    def parse(text: str) -> list[float]:
        import argparse  # the command line's: a library read imports neither it nor json

        try:
            values = [float(part) for part in text.replace(" ", "").split(",") if part]
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected {count or 'some'} comma-separated {what}, got {text!r}"
            ) from None
        if count is not None and len(values) != count:
            raise argparse.ArgumentTypeError(
                f"expected {count} comma-separated {what}, got {len(values)}"
            )
        return values

    parse.__name__ = what
    return parse


def key_value(text: str) -> tuple[str, Any]:
    """A ``parse`` for ``KEY=VALUE``: VALUE is JSON when it parses, else text.

    >>> key_value("surface.caps=false"), key_value("Surface=surface")
    (('surface.caps', False), ('Surface', 'surface'))
    """
    import argparse
    import json

    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    try:
        return key.strip(), json.loads(value)
    except json.JSONDecodeError:
        return key.strip(), value


def as_dict(pairs: list[Any]) -> dict[str, Any]:
    """A ``collect`` for :func:`key_value` pairs: ``{KEY: VALUE}``."""
    return dict(pairs)


def as_nested_dict(pairs: list[Any]) -> dict[str, dict[str, Any]]:
    """A ``collect`` for ``NAME.KEY=VALUE`` pairs: ``{NAME: {KEY: VALUE}}``."""
    nested: dict[str, dict[str, Any]] = {}
    for key, value in pairs:
        name, dot, option = str(key).partition(".")
        if not dot or not option:
            raise OptionsError(f"expected NAME.KEY=VALUE, got {key}={value!r}")
        nested.setdefault(name, {})[option] = value
    return nested


def comma_items(text: str) -> list[str | int]:
    """A ``parse`` for ``a,b,3``: names, and digits as integer ids."""
    items: list[str | int] = []
    for part in text.split(","):
        part = part.strip()
        if part:
            items.append(int(part) if part.isdigit() else part)
    return items


# -- the declaration ----------------------------------------------------------------------------
@runtime_checkable
class OperationFunction(Protocol):
    """``function(scene, options) -> Scene``: the operation's work (a new scene)."""

    def __call__(self, scene: Scene, options: Any, /) -> Scene: ...


@runtime_checkable
class FileOptions(Protocol):
    """The options of an operation whose result is files written (``output="files"``)."""

    name: str | None
    """The file-name pattern of its output in a pipeline (``{stem}.png``)."""

    def writer_format(self) -> str | None:
        """The registered format written (None: from the output's extension)."""
        ...

    def writer_options(self) -> dict[str, Any]:
        """The keywords of the format's writer."""
        ...


class OperationSpec(RegisteredItem):
    """One operation: its options model and its function of a Scene.

    ``summary`` is its one-line help; ``description`` its longer text. ``command`` is its
    ``geobrep`` subcommand (default: ``name``; ``None``: none) and ``step`` its pipeline step
    kind (default: ``name``; ``None``: none). ``writes`` says what the step leaves in the scene,
    for the documentation.

    Example:
        >>> from pydantic import ConfigDict
        >>> class Every(BaseModel):
        ...     model_config = ConfigDict(extra="forbid")
        ...     every: int = 2
        >>> spec = OperationSpec(name="thin", summary="keep every n-th point", options=Every,
        ...                      function=lambda scene, options: scene)
        >>> spec.kind, spec.command_name, spec.step_kind, cli_flags("every", Every.model_fields["every"])
        ('operation', 'thin', 'thin', ('--every',))
    """  # noqa: E501

    kind: ClassVar[str] = "operation"

    summary: str = ""
    function: OperationFunction
    command: str | None = ""
    step: str | None = ""
    writes: str = "the scene the function returns"
    output: Literal["scene", "files"] = "scene"
    """``"scene"``: the result is the new scene the function returns. ``"files"``: the result
    is files written (``convert``, ``render``, ``view``): the options are a step that writes a
    file (:class:`FileOptions`: they name the format and give its writer's keywords), the
    function returns the scene to write, and in a pipeline the scene flows on unchanged."""

    @property
    def command_name(self) -> str | None:
        """The ``geobrep`` subcommand, or None."""
        return self.name if self.command == "" else self.command

    @property
    def step_kind(self) -> str | None:
        """The pipeline step kind, or None."""
        return self.name if self.step == "" else self.step

    def __call__(self, scene: Scene, options: Any = None, /, **kwargs: Any) -> Scene:
        """Run the operation: ``spec(scene, every=3)`` (the options validated first)."""
        validated = self.validate_options(options, **kwargs)
        return self.function(scene, validated)


class OperationRegistry(Registry[OperationSpec]):
    """Operations: geobrep's own and the plugins'."""

    item_type: ClassVar[type[RegisteredItem]] = OperationSpec

    def for_command(self, command: str) -> OperationSpec | None:
        """The operation whose subcommand is ``command``."""
        return next((spec for spec in self if spec.command_name == command), None)

    def for_step(self, kind: str) -> OperationSpec | None:
        """The operation whose pipeline step is ``kind``."""
        return next((spec for spec in self if spec.step_kind == kind), None)


# -- the command line ---------------------------------------------------------------------------
def _unwrapped(annotation: Any) -> tuple[Any, bool]:
    """``(annotation without None, whether None was allowed)``; Annotated is unwrapped."""
    while typing.get_origin(annotation) is typing.Annotated:
        annotation = typing.get_args(annotation)[0]
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(annotation) if a is not type(None)]
        optional = len(members) < len(typing.get_args(annotation))
        if len(members) == 1:
            return _unwrapped(members[0])[0], optional
        return typing.Union[tuple(members)], optional  # noqa: UP007
    return annotation, False


def _choices(annotation: Any) -> tuple[Any, ...] | None:
    if typing.get_origin(annotation) is Literal:
        return typing.get_args(annotation)
    return None


def _argument(name: str, info: FieldInfo) -> dict[str, Any]:
    """The ``add_argument`` keywords of a field (without the option strings)."""
    import argparse

    cli = cli_of(info)
    annotation, _ = _unwrapped(info.annotation)
    keywords: dict[str, Any] = {"help": cli.help if cli.help is not None else info.description}
    if not cli.positional:
        keywords["dest"] = name
        keywords["default"] = argparse.SUPPRESS  # unset: the model's default applies
    if cli.metavar is not None:
        keywords["metavar"] = cli.metavar
    if cli.nargs is not None:
        keywords["nargs"] = cli.nargs
    if annotation is bool and not cli.positional:
        keywords["action"] = "store_false" if cli.negate else "store_true"
        keywords.pop("metavar", None)
        return keywords
    if cli.append:
        keywords["action"] = "append"
    choices = _choices(annotation)
    if choices is not None:
        keywords["choices"] = choices
    elif cli.parse is not None:
        keywords["type"] = cli.parse
    elif annotation in (int, float):
        keywords["type"] = annotation
    return keywords


#: The mutually exclusive groups of each parser, by name (several models may add to one).
_GROUPS: weakref.WeakKeyDictionary[argparse.ArgumentParser, dict[str, Any]] = (
    weakref.WeakKeyDictionary()
)


def add_arguments(
    parser: argparse.ArgumentParser, model: type[BaseModel], skip: Iterable[str] = ()
) -> None:
    """Add one argument per field of ``model`` (in field order, less ``skip``) to ``parser``."""
    groups = _GROUPS.setdefault(parser, {})
    left_out = set(skip)
    for name, info in model.model_fields.items():
        flags = () if name in left_out else cli_flags(name, info)
        if not flags:
            continue
        cli = cli_of(info)
        target: Any = parser
        if cli.group is not None:
            if cli.group not in groups:
                groups[cli.group] = parser.add_mutually_exclusive_group()
            target = groups[cli.group]
            target.required = target.required or cli.required
        keywords = _argument(name, info)
        if not cli.positional and info.is_required() and cli.group is None:
            keywords["required"] = True
        target.add_argument(*flags, **keywords)


def options_from_args(model: type[BaseModel], args: argparse.Namespace | Mapping[str, Any]) -> Any:
    """The parsed arguments as an instance of ``model`` (only the options given are set).

    Raises:
        OptionsError: a value the model refuses, naming the option as it was typed.
    """
    import argparse

    given = vars(args) if isinstance(args, argparse.Namespace) else dict(args)
    data = {name: given[name] for name in model.model_fields if name in given}
    for name, value in data.items():
        collect = cli_of(model.model_fields[name]).collect
        if collect is not None and isinstance(value, list):
            data[name] = collect(value)
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        problems = []
        for error in exc.errors(include_url=False):
            loc = error["loc"]
            field = str(loc[0]) if loc else ""
            info = model.model_fields.get(field)
            flag = (cli_flags(field, info) or (field,))[0] if info is not None else field
            message = str(error["msg"]).removeprefix("Value error, ")
            problems.append(f"{flag}: {message}" if flag else message)
        raise OptionsError("; ".join(problems)) from exc


# -- the documentation --------------------------------------------------------------------------
def _default_text(info: FieldInfo) -> str:
    if info.is_required():
        return "required"
    factory = info.default_factory
    value = factory() if factory is not None else info.default  # type: ignore[call-arg]
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Mapping | Sequence) and not isinstance(value, str) and not value:
        return "{}" if isinstance(value, Mapping) else "[]"
    return f"`{value}`"


def options_table(
    model: type[BaseModel], command: str | None = None, skip: Iterable[str] = ()
) -> str:
    """The Markdown table of an options model: each key (as a pipeline writes it), its flag on
    ``geobrep COMMAND`` (when the operation has a command), its default and what it does.

    >>> from pydantic import Field
    >>> class Every(BaseModel):
    ...     every: int = Field(default=2, description="keep every N-th point")
    >>> print(options_table(Every, "thin"))
    | Key | `geobrep thin` | Default | What |
    |---|---|---|---|
    | `every` | `--every` | `2` | keep every N-th point |
    """
    flag_heading = f"`geobrep {command}`" if command else "Flag"
    rows = [f"| Key | {flag_heading} | Default | What |", "|---|---|---|---|"]
    left_out = set(skip)
    for name, info in model.model_fields.items():
        if name in left_out:
            continue
        flags = ", ".join(f"`{f}`" for f in cli_flags(name, info)) if command else ""
        what = " ".join((info.description or cli_of(info).help or "").split())
        what = what.replace("|", "\\|")
        rows.append(f"| `{info.alias or name}` | {flags or '—'} | {_default_text(info)} | {what} |")
    return "\n".join(rows)
