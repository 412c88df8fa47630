"""Run a call with room on the interpreter's frame stack, so no call in it crosses a chunk edge.

CPython (3.11 and later) keeps the frames of Python calls on a stack of memory chunks of
16 KiB. A call whose frame does not fit in the current chunk gets a new chunk (an ``mmap``),
and the chunk is handed back (``munmap``) as soon as that call returns. When a loop's calls sit
right at a chunk edge, every call of the loop maps and unmaps a chunk: measured on
``geobrep info`` of a 3-vertex file, 3,156 chunk unmaps (a ``typing.Literal`` loop of numpy's
import and pydantic's schema building happened to sit there), about 45 ms of its 300 ms.
Where the edge falls depends only on how deep the caller is, so the cost came and went
with unrelated changes.

:func:`call_with_room` runs a function under one frame that reserves a large chunk and keeps
it while the function runs: the calls inside it stay within that chunk (unless they nest
more than a few thousand frames deep), and the chunk is mapped once. The reserved frame only
enlarges the frame of one small function (``co_stacksize``); the memory it leaves untouched is
never paged in. Other interpreters run the function as it is.

>>> call_with_room(sum, [1, 2, 3])
6
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["ROOM_WORDS", "call_with_room"]

T = TypeVar("T")

#: Pointer-sized words the reserving frame asks for: its chunk (twice that, as CPython rounds
#: up to a power of two) leaves about 512 KiB for the frames of the call, thousands deep.
ROOM_WORDS = 65_536


def _reserved(function: Callable[..., T], args: tuple[Any, ...], kwargs: dict[str, Any]) -> T:
    return function(*args, **kwargs)


if sys.implementation.name == "cpython" and sys.version_info >= (3, 11):
    _code = _reserved.__code__
    _reserved.__code__ = _code.replace(co_stacksize=_code.co_stacksize + ROOM_WORDS)


def call_with_room(function: Callable[..., T], *args: Any, **kwargs: Any) -> T:
    """``function(*args, **kwargs)`` run with room on the frame stack (see the module)."""
    return _reserved(function, args, kwargs)
