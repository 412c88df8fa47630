"""JSON as the standard defines it, for the documents geobrep embeds in files.

Python's :func:`json.loads` also accepts ``NaN``, ``Infinity`` and ``-Infinity``, which no JSON
writer (geobrep's included: it writes non-finite numbers as the strings ``"NaN"``,
``"Infinity"``) produces; a value read that way would later make the scene unwritable to JSON.
:func:`loads` refuses them, and turns a document nested too deeply for the parser into a
``ValueError`` too, so a reader has one exception to translate.

>>> loads('{"a": [1, 2.5, "NaN"]}')
{'a': [1, 2.5, 'NaN']}
>>> loads('{"a": NaN}')
Traceback (most recent call last):
...
ValueError: NaN is not JSON (write it as the string "NaN")
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any, NoReturn

__all__ = ["find_leaf", "loads"]


def _refuse(constant: str) -> NoReturn:
    raise ValueError(f'{constant} is not JSON (write it as the string "{constant}")')


def loads(text: str | bytes) -> Any:
    """Parse ``text`` as strict JSON; ``ValueError`` (``json.JSONDecodeError`` for syntax, with
    its position) for anything else."""
    try:
        return json.loads(text, parse_constant=_refuse)
    except RecursionError:
        raise ValueError("JSON nested too deeply") from None


def find_leaf(
    data: Any, wanted: Callable[[Any, tuple[str, ...]], bool], where: tuple[str, ...] = ()
) -> tuple[str, ...] | None:
    """The path of the first leaf of a JSON document for which ``wanted(value, path)`` holds.

    >>> find_leaf({"a": [1, float("nan")]}, lambda value, _: value != value)
    ('a', '1')
    >>> find_leaf({"a": 1}, lambda value, _: False) is None
    True
    """
    if isinstance(data, dict | list):
        items = data.items() if isinstance(data, dict) else enumerate(data)
        for key, value in items:
            found = find_leaf(value, wanted, (*where, str(key)))
            if found is not None:
                return found
        return None
    return where if wanted(data, where) else None
