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
from typing import Any, NoReturn

__all__ = ["loads"]


def _refuse(constant: str) -> NoReturn:
    raise ValueError(f'{constant} is not JSON (write it as the string "{constant}")')


def loads(text: str | bytes) -> Any:
    """Parse ``text`` as strict JSON; ``ValueError`` (``json.JSONDecodeError`` for syntax, with
    its position) for anything else."""
    try:
        return json.loads(text, parse_constant=_refuse)
    except RecursionError:
        raise ValueError("JSON nested too deeply") from None
