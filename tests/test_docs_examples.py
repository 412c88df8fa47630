"""Every ```python block of README.md and docs/ runs (each page's blocks share one namespace)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

import geobrep.plugins

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted([ROOT / "README.md", *(ROOT / "docs").rglob("*.md")])
BLOCK = re.compile(r"^```python\n(.*?)^```", re.MULTILINE | re.DOTALL)


def _pages_with_code() -> list[Path]:
    return [page for page in PAGES if BLOCK.search(page.read_text(encoding="utf-8"))]


@pytest.mark.parametrize("page", _pages_with_code(), ids=lambda p: str(p.relative_to(ROOT)))
def test_page_examples_run(page: Path, tmp_path: Path) -> None:
    namespace: dict[str, object] = {"__name__": f"docs_example_{page.stem}"}
    cwd = Path.cwd()
    os.chdir(tmp_path)  # examples may write files: keep them out of the repository
    try:
        for number, match in enumerate(BLOCK.finditer(page.read_text(encoding="utf-8")), 1):
            code = compile(match.group(1), f"{page.name}[block {number}]", "exec")
            exec(code, namespace)
    finally:
        os.chdir(cwd)
        geobrep.plugins.reload()  # pages register plugins: the next test sees installed ones only


def test_pages_have_examples() -> None:
    assert len(_pages_with_code()) >= 3
