"""docs/pipelines.md: its YAML is valid, and the pipeline it shows is the one its example runs."""

from __future__ import annotations

import re
from pathlib import Path

import jsonschema
import yaml

import geobrep.schemas
from geobrep.batch.pipeline import STEP_KINDS, Pipeline

PAGE = Path(__file__).resolve().parents[2] / "docs" / "pipelines.md"


def _blocks(language: str) -> list[str]:
    text = PAGE.read_text(encoding="utf-8")
    return re.findall(rf"^```{language}\n(.*?)^```", text, re.MULTILINE | re.DOTALL)


def test_yaml_examples_are_valid_pipelines() -> None:
    validator = jsonschema.Draft202012Validator(geobrep.schemas.load("pipeline"))
    blocks = _blocks("yaml")
    assert blocks
    for block in blocks:
        document = yaml.safe_load(block)
        validator.validate(document)
        Pipeline.from_data(document).check()


def test_the_shown_pipeline_is_the_one_the_example_runs() -> None:
    [shown, *_] = _blocks("yaml")
    [run] = [b for b in _blocks("python") if 'run_pipeline("west.yaml")' in b]
    embedded = re.search(r'write_text\(\n    """(.*?)"""', run, re.DOTALL)
    assert embedded is not None
    assert yaml.safe_load(embedded.group(1)) == yaml.safe_load(shown)


def test_every_step_kind_is_documented() -> None:
    text = PAGE.read_text(encoding="utf-8")
    for kind in STEP_KINDS:
        assert f"| `{kind}` |" in text, kind
        assert f"**`{kind}`**" in text, kind
