"""Issue 15 item 3: pipeline files are bounded in size, nesting depth and YAML alias expansion.

Before, the 650-byte ``yaml_billion_laughs.yaml`` grew without limit (1.2 GB after 30 s) while
its ``options`` were validated, and deep nesting ended in ``internal error: RecursionError``.
Each limit is now a FormatError naming the file and the line, in milliseconds.
"""

from __future__ import annotations

import json
import time
import tracemalloc
from collections.abc import Iterator
from pathlib import Path

import pytest

from geobrep.batch.limits import MAX_ALIAS_NODES, MAX_ALIASES, MAX_DEPTH, MAX_FILE_BYTES
from geobrep.batch.pipeline import Pipeline
from geobrep.cli.main import main
from geobrep.errors import FormatError, OptionsError

LAUGHS = (
    Path(__file__).resolve().parents[1]
    / "data"
    / "reliability"
    / "pipeline_traversal"
    / "yaml_billion_laughs.yaml"
)
HEAD = "version: 1\ninputs: [in/tri.ts]\noutput: out\n"
WRITE = "  - write: {format: native}\n"


@pytest.fixture
def bounded() -> Iterator[None]:
    """Each case finishes (in well under a second: PyYAML's own scanner looks at most 1024
    characters ahead for a key, which bounds the work before the depth check). The bound is a
    hang guard against unbounded expansion, not a timing test: the memory checks are the test."""
    started = time.perf_counter()
    yield
    seconds = time.perf_counter() - started
    assert seconds < 30.0, f"{seconds:.2f} s"  # a guard, not a timing test


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_billion_laughs_is_refused(bounded: None) -> None:
    tracemalloc.start()
    with pytest.raises(FormatError, match="YAML aliases expand to more than") as raised:
        Pipeline.load(LAUGHS)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 16 * 2**20, f"{peak / 2**20:.0f} MB"  # before: 1.2 GB after 30 s, growing
    assert raised.value.path == LAUGHS
    assert raised.value.line == 10  # l5: the first level that goes over 100,000 nodes


def test_billion_laughs_through_the_cli(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(LAUGHS), "--no-progress"]) == 1
    assert f"{LAUGHS}:10: YAML aliases expand" in capsys.readouterr().err


def _options(depth: int) -> str:
    """``{format: gocad, options: {k: [[...[1]...]]}}``: ``depth`` levels in all (the document,
    ``steps``, the step, its body and ``options`` are five)."""
    inner = "[" * (depth - 5) + "1" + "]" * (depth - 5)
    return "{format: gocad, options: {k: " + inner + "}}"


def test_yaml_at_the_depth_limit_loads(tmp_path: Path) -> None:
    """MAX_DEPTH levels load; the options then go to the format (which refuses ``k``)."""
    path = _write(tmp_path, "p.yaml", f"{HEAD}steps:\n  - read: {_options(MAX_DEPTH)}\n{WRITE}")
    pipeline = Pipeline.load(path)
    value = pipeline.model_dump()["steps"][0]["read"]["options"]["k"]
    depth = 0
    while isinstance(value, list):
        value, depth = value[0], depth + 1
    assert (value, depth) == (1, MAX_DEPTH - 5)
    with pytest.raises(OptionsError, match="step 1 \\(read\\)"):
        pipeline.check()


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 1000, 100_000])
def test_yaml_nested_too_deep(tmp_path: Path, depth: int, bounded: None) -> None:
    path = _write(tmp_path, "p.yaml", f"{HEAD}steps:\n  - read: {_options(depth)}\n{WRITE}")
    with pytest.raises(FormatError, match=f"nested deeper than {MAX_DEPTH} levels") as raised:
        Pipeline.load(path)
    assert (raised.value.path, raised.value.line) == (path, 5)


def test_yaml_block_nesting_too_deep(tmp_path: Path, bounded: None) -> None:
    lines = [f"{'  ' * level}k{level}:" for level in range(MAX_DEPTH + 10)]
    path = _write(tmp_path, "p.yaml", HEAD + "x:\n" + "\n".join("  " + s for s in lines) + " 1\n")
    with pytest.raises(FormatError, match="nested deeper") as raised:
        Pipeline.load(path)
    assert raised.value.line == 4 + MAX_DEPTH  # the mapping that opens level MAX_DEPTH + 1


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 100_000])
def test_json_nested_too_deep(tmp_path: Path, depth: int, bounded: None) -> None:
    document = {"inputs": ["in/tri.ts"], "steps": [{"write": {"format": "native"}}]}
    text = json.dumps(document, indent=1)[:-2]  # all but the closing brace
    text += ',\n "x": "[[[[ brackets in a string do not count",\n "y": '
    text += "[" * depth + "]" * depth + "\n}"
    path = _write(tmp_path, "p.json", text)
    with pytest.raises(FormatError, match="nested deeper") as raised:
        Pipeline.load(path)
    assert (raised.value.path, raised.value.line) == (path, text.count("\n"))


def test_json_at_the_depth_limit_is_judged_as_a_pipeline(tmp_path: Path) -> None:
    nested = "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1)  # inside the document's braces
    path = _write(
        tmp_path, "p.json", '{"steps": [{"write": {"format": "native"}}], "y": ' + nested + "}"
    )
    with pytest.raises(OptionsError, match="y: unknown field"):
        Pipeline.load(path)


def test_deep_nesting_through_the_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "p.json", '{"steps": ' + "[" * 5000 + "]" * 5000 + "}")
    assert main(["run", str(path), "--no-progress"]) == 1  # not 70: no internal error
    assert f"{path}:1: nested deeper than {MAX_DEPTH} levels" in capsys.readouterr().err


def _aliases(count: int) -> str:
    uses = ", ".join(["*v"] * count)
    return f"{HEAD}x: &v 1\ny: [{uses}]\nsteps:\n{WRITE}"


def test_aliases_are_counted(tmp_path: Path, bounded: None) -> None:
    with pytest.raises(OptionsError, match="unknown field"):  # loaded, then judged
        Pipeline.load(_write(tmp_path, "ok.yaml", _aliases(MAX_ALIASES)))
    with pytest.raises(FormatError, match=f"more than {MAX_ALIASES} YAML aliases") as raised:
        Pipeline.load(_write(tmp_path, "many.yaml", _aliases(MAX_ALIASES + 1)))
    assert raised.value.line == 5


@pytest.mark.parametrize(("uses", "refused"), [(8, False), (9, True)])
def test_expanded_nodes_are_counted(
    tmp_path: Path, uses: int, refused: bool, bounded: None
) -> None:
    """Few aliases, many nodes: ``a`` is 1,000 nodes, ``b`` ten of it (10,001 nodes; 10,000
    added), each use of ``b`` adds 10,001: the ninth goes over MAX_ALIAS_NODES (100,000)."""
    assert MAX_ALIAS_NODES == 100_000
    ones = ", ".join(["1"] * 999)
    tens = ", ".join(["*a"] * 10)
    text = f"{HEAD}a: &a [{ones}]\nb: &b [{tens}]\nc: [{', '.join(['*b'] * uses)}]\n"
    path = _write(tmp_path, "p.yaml", f"{text}steps:\n{WRITE}")
    if refused:
        with pytest.raises(FormatError, match="expand to more than 100,000 nodes") as raised:
            Pipeline.load(path)
        assert raised.value.line == 6  # c
    else:
        with pytest.raises(OptionsError, match="unknown field"):  # loaded, then judged
            Pipeline.load(path)


def test_useful_anchors_still_work(tmp_path: Path) -> None:
    text = (
        f"{HEAD}steps:\n  - clip: &cut {{plane: [1, 0, 0, -450500], keep: negative}}\n"
        "  - write: {format: native, name: '{stem}_a.geobrep'}\n  - clip: *cut\n"
        "  - write: {format: native, name: '{stem}_b.geobrep'}\n"
    )
    pipeline = Pipeline.load(_write(tmp_path, "p.yaml", text)).check()
    first, _, second, _ = pipeline.step_list
    assert first == second


def test_recursive_alias_is_refused(tmp_path: Path, bounded: None) -> None:
    with pytest.raises(FormatError, match="refers to a node that contains it"):
        Pipeline.load(_write(tmp_path, "p.yaml", f"{HEAD}steps: &s [*s]\n"))


def test_file_size_is_bounded(tmp_path: Path, bounded: None) -> None:
    head = '{"steps": [{"write": {"format": "native"}}], "x": "'
    path = _write(tmp_path, "p.json", head + "a" * (MAX_FILE_BYTES - len(head) - 2) + '"}')
    assert path.stat().st_size == MAX_FILE_BYTES
    with pytest.raises(OptionsError, match="x: unknown field"):  # at the limit: read and judged
        Pipeline.load(path)
    for name in ("p.json", "p.yaml"):
        path = _write(tmp_path, name, head + "a" * MAX_FILE_BYTES + '"}')
        with pytest.raises(FormatError, match="at most 10 MB") as raised:
            Pipeline.load(path)
        assert raised.value.path == path
