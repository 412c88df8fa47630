"""Every hook has a heading with its exact signature in docs/plugin-guide.md (datasette's habit)."""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from geobrep.hookspecs import GeobrepSpecs
from geobrep.host.loader import HOOK_KINDS

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "plugin-guide.md"


def _annotation(annotation: Any) -> str:
    if isinstance(annotation, str):  # postponed annotations: the source text
        return annotation
    if annotation is None or annotation is type(None):
        return "None"
    return str(getattr(annotation, "__name__", annotation))


def hook_signature(function: Callable[..., Any]) -> str:
    """``geobrep_register_formats(registry: FormatRegistry) -> None``, ``self`` left out."""
    signature = inspect.signature(function)
    parameters = [p for p in signature.parameters.values() if p.name != "self"]
    arguments = ", ".join(f"{p.name}: {_annotation(p.annotation)}" for p in parameters)
    return f"{function.__name__}({arguments}) -> {_annotation(signature.return_annotation)}"


HOOKS = sorted(name for name in vars(GeobrepSpecs) if name.startswith("geobrep_"))


def guide_headings() -> list[str]:
    return re.findall(r"^##+ +(.+?) *$", GUIDE.read_text(encoding="utf-8"), flags=re.MULTILINE)


def test_there_are_hooks() -> None:
    assert sorted(HOOK_KINDS) == HOOKS


@pytest.mark.parametrize("hook", HOOKS)
def test_hook_has_signature_heading(hook: str) -> None:
    expected = hook_signature(getattr(GeobrepSpecs, hook))
    headings = [heading.strip("`") for heading in guide_headings()]
    assert expected in headings, f"docs/plugin-guide.md needs a heading '## {expected}'"


def test_no_heading_for_a_hook_that_does_not_exist() -> None:
    documented = {
        h.strip("`").split("(")[0]
        for h in guide_headings()
        if h.startswith(("geobrep_", "`geobrep_"))
    }
    assert documented == set(HOOKS)


def test_signature_text() -> None:
    assert hook_signature(GeobrepSpecs.geobrep_register_formats) == (
        "geobrep_register_formats(registry: FormatRegistry) -> None"
    )
