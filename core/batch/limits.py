"""Limits on pipeline files: size, nesting depth and YAML alias expansion.

A pipeline file is small: these bounds are far above any real one, and each makes a hostile
file a :class:`~geobrep.errors.FormatError` naming the file (and the line) in milliseconds,
instead of an unbounded expansion (a "billion laughs" of nested YAML aliases, which the options
validation would walk as a tree) or a ``RecursionError`` on deep nesting.

>>> import pathlib
>>> load_yaml("a: &x [1, 2]\\nb: *x\\n", pathlib.Path("p.yaml"))
{'a': [1, 2], 'b': [1, 2]}
>>> check_json_depth("[" * 65 + "]" * 65, pathlib.Path("p.json"))
Traceback (most recent call last):
...
geobrep.errors.FormatError: p.json:1: nested deeper than 64 levels
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from yaml.events import Event
from yaml.nodes import MappingNode, Node, SequenceNode

from geobrep.errors import FormatError

__all__ = [
    "MAX_ALIASES",
    "MAX_ALIAS_NODES",
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "check_json_depth",
    "load_yaml",
]

MAX_FILE_BYTES = 10 * 2**20
"""The largest pipeline file read (10 MB)."""
MAX_DEPTH = 64
"""The deepest nesting of lists and mappings in a pipeline file."""
MAX_ALIASES = 100
"""The most YAML aliases (``*name``) in a pipeline file."""
MAX_ALIAS_NODES = 100_000
"""The most nodes YAML aliases may add to a document, each alias counting its whole subtree."""

_JSON_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"')


def check_json_depth(text: str, file: Path) -> None:
    """Raise :class:`FormatError` (with the line) if ``text`` nests deeper than :data:`MAX_DEPTH`.

    Brackets inside strings do not count. Linear time, no recursion.
    """
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return
    data = np.frombuffer(_JSON_STRING.sub('""', text).encode("utf-8"), dtype=np.uint8)
    opens = (data == ord("[")) | (data == ord("{"))
    closes = (data == ord("]")) | (data == ord("}"))
    depth = np.cumsum(opens.astype(np.int64) - closes.astype(np.int64))
    deep = np.flatnonzero(depth > MAX_DEPTH)
    if deep.size:
        line = int(np.count_nonzero(data[: deep[0]] == ord("\n"))) + 1
        raise FormatError(f"nested deeper than {MAX_DEPTH} levels", file, line)


class _LimitedLoader(yaml.SafeLoader):
    """A safe YAML loader that counts, while composing, nesting depth, aliases and the nodes
    aliases add; it refuses a document over :data:`MAX_DEPTH`, :data:`MAX_ALIASES` or
    :data:`MAX_ALIAS_NODES` before anything is constructed."""

    def __init__(self, text: str, file: Path) -> None:
        super().__init__(text)
        self.file = file
        self.depth = 0
        self.aliases = 0
        self.alias_nodes = 0
        self.sizes: dict[int, int] = {}
        """Per composed node (by id), the nodes of its subtree with aliases expanded."""

    def _event(self) -> Event:
        event: Event = self.peek_event()  # type: ignore[no-untyped-call]  # untyped in the stubs
        return event

    def _limit(self, message: str) -> FormatError:
        mark = self._event().start_mark
        return FormatError(message, self.file, mark.line + 1 if mark is not None else None)

    def compose_node(self, parent: Node | None, index: int) -> Node | None:
        if self.check_event(yaml.AliasEvent):
            self._count_alias()
            return super().compose_node(parent, index)
        level = int(self.check_event(yaml.SequenceStartEvent, yaml.MappingStartEvent))
        self.depth += level  # lists and mappings count, as brackets do in JSON
        try:
            if self.depth > MAX_DEPTH:
                raise self._limit(f"nested deeper than {MAX_DEPTH} levels")
            node = super().compose_node(parent, index)
        finally:
            self.depth -= level
        if node is not None:
            children: list[Node] = []
            if isinstance(node, SequenceNode):
                children = list(node.value)
            elif isinstance(node, MappingNode):
                children = [item for pair in node.value for item in pair]
            self.sizes[id(node)] = 1 + sum(self.sizes.get(id(child), 1) for child in children)
        return node

    def _count_alias(self) -> None:
        event = self._event()
        self.aliases += 1
        if self.aliases > MAX_ALIASES:
            raise self._limit(f"more than {MAX_ALIASES} YAML aliases")
        anchor = getattr(event, "anchor", None)
        node = self.anchors.get(anchor)
        if node is None:
            return  # an undefined alias: the composer reports it
        size = self.sizes.get(id(node))
        if size is None:
            raise self._limit(f"alias *{anchor} refers to a node that contains it")
        self.alias_nodes += size
        if self.alias_nodes > MAX_ALIAS_NODES:
            raise self._limit(f"YAML aliases expand to more than {MAX_ALIAS_NODES:,} nodes")


def load_yaml(text: str, file: Path) -> Any:
    """Parse ``text`` (the YAML of ``file``) with :class:`yaml.SafeLoader` within the limits.

    Raises:
        FormatError: a limit is exceeded (naming ``file`` and the line).
        yaml.YAMLError: the text is not valid YAML.
    """
    loader = _LimitedLoader(text, file)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()
