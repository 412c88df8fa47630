"""The pipeline JSON Schema: valid, up to date, and in agreement with the loader."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import jsonschema
import pytest

import geobrep.schemas
from geobrep.batch.pipeline import STEP_KINDS, Pipeline
from geobrep.errors import OptionsError

FULL: dict[str, Any] = {
    "version": 1,
    "inputs": ["models/*.geobrep", "extra/one.ts"],
    "output": "out",
    "steps": [
        {"read": {"format": "native"}},
        {"reproject": {"to": "EPSG:32632", "from": "EPSG:32631"}},
        {"clip": {"plane": [1, 0, 0, -450500], "keep": "negative", "tolerance": 0.001}},
        {"clip_box": {"bounds": [0, 1, 0, 1, 0, 1], "options": {"surface": {"caps": True}}}},
        {"clip_box": {"planes": [[1, 0, 0, -1], [0, 1, 0, -1]]}},
        {"section": {"plane": [0, 1, 0, -6700400], "clippers": {"Surface": "surface"}}},
        {"fit": {"method": "kriging", "options": {"epsilon": 0.5}, "check": True}},
        {"build_blocks": {"options": {"tolerance": 0.01}}},
        {"build": {"builder": "blocks"}},
        {"voxelize": {"depth": 6, "method": "exact", "bodies": ["unit 1", 3]}},
        {"write": {"format": "native", "name": "{stem}_{index}.geobrep"}},
        {"convert": {"format": "vtu", "options": {"compression": None}}},
    ],
}


@pytest.fixture(scope="module")
def validator() -> jsonschema.Draft202012Validator:
    schema = geobrep.schemas.load("pipeline")
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_stored_schema_is_up_to_date() -> None:
    stored = Path(geobrep.schemas.__file__).parent / "pipeline.schema.json"
    generated = geobrep.schemas.render(geobrep.schemas.generate()["pipeline"])
    assert stored.read_text(encoding="utf-8") == generated, (
        "schemas/pipeline.schema.json is stale: run `make schemas`"
    )


def test_schema_describes_every_step_kind() -> None:
    schema = geobrep.schemas.load("pipeline")
    assert schema["title"] == "geobrep pipeline"
    entries = schema["properties"]["steps"]["items"]["oneOf"]
    kinds = [schema["$defs"][e["$ref"].rsplit("/", 1)[1]]["required"][0] for e in entries]
    assert kinds == list(STEP_KINDS)


def test_a_document_using_every_step_is_valid_for_both(
    validator: jsonschema.Draft202012Validator,
) -> None:
    validator.validate(FULL)
    pipeline = Pipeline.from_data(FULL)
    assert [step.kind for step in pipeline.step_list] == [
        next(iter(step)) for step in FULL["steps"]
    ]
    # The model writes back what it read (aliases included) and that is valid too.
    dumped = pipeline.model_dump(mode="json", by_alias=True, exclude_defaults=True)
    validator.validate(dumped)
    assert Pipeline.from_data(dumped) == pipeline


@pytest.mark.parametrize(
    "steps",
    [
        [{"clipp": {}}, {"write": {"format": "vtu"}}],  # unknown kind
        [{"clip": {"plane": [1, 0, 0]}}, {"write": {"format": "vtu"}}],  # 3 coefficients
        [{"clip": {"plane": [1, 0, 0, 0], "keep": "middle"}}, {"write": {"format": "vtu"}}],
        [{"voxelize": {"depht": 5}}, {"write": {"format": "vtu"}}],  # typo
        [{"clip": {"plane": [1, 0, 0, 0]}, "keep": "negative"}, {"write": {"format": "vtu"}}],
        [],
    ],
)
def test_schema_and_loader_reject_the_same_mistakes(
    validator: jsonschema.Draft202012Validator, steps: list[Any]
) -> None:
    document = {"inputs": ["a.ts"], "steps": steps}
    assert not validator.is_valid(document)
    with pytest.raises(OptionsError):
        Pipeline.from_data(document)
