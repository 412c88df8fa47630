"""geobrep.cli._frame_stack: a call run with room on the frame stack behaves as the call itself."""

from __future__ import annotations

import sys

import pytest

from geobrep.cli._frame_stack import ROOM_WORDS, _reserved, call_with_room
from geobrep.cli.main import main


def test_arguments_and_result_pass_through() -> None:
    def combine(a: int, b: int, *, scale: int = 1) -> int:
        return (a - b) * scale

    assert call_with_room(combine, 5, 3, scale=10) == 20
    assert call_with_room(sorted, [3, 1, 2], reverse=True) == [3, 2, 1]


def test_exceptions_reach_the_caller_unchanged() -> None:
    error = ValueError("kept")

    def fail() -> None:
        raise error

    with pytest.raises(ValueError, match="kept") as caught:
        call_with_room(fail)
    assert caught.value is error


def test_deep_recursion_inside_still_works() -> None:
    def depth(n: int) -> int:
        return 0 if n == 0 else 1 + depth(n - 1)

    assert call_with_room(depth, 900) == 900


@pytest.mark.skipif(sys.implementation.name != "cpython", reason="CPython frame layout")
def test_the_reserving_frame_asks_for_the_room() -> None:
    assert _reserved.__code__.co_stacksize >= ROOM_WORDS


def test_the_command_line_runs_in_the_room(capsys: pytest.CaptureFixture[str]) -> None:
    seen: list[str] = []

    def tracer(frame, event, arg):  # type: ignore[no-untyped-def]
        if event == "call":
            seen.append(frame.f_code.co_name)
        return None

    sys.setprofile(tracer)
    try:
        assert main(["--version"]) == 0
    finally:
        sys.setprofile(None)
    assert capsys.readouterr().out.startswith("geobrep ")
    assert "_reserved" in seen
    assert seen.index("_reserved") < seen.index("_main")
