"""JSON Schemas generated from geobrep's pydantic models, and a loader.

``scene.schema.json`` describes ``scene.json``, the document inside a native ``.geobrep`` file;
``pipeline.schema.json`` describes pipeline files (``geobrep run pipeline.yaml``);
``inspection.schema.json`` describes an inspection report (``geobrep check --json``).
Regenerate after changing a model with ``make schemas`` (``python -m geobrep.schemas``); a test
fails when the stored file is stale.

>>> from geobrep.schemas import load
>>> load("scene")["title"]
'geobrep scene document'
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path
from typing import Any

__all__ = ["SCHEMA_NAMES", "generate", "load", "write_all"]

SCHEMA_NAMES = ("scene", "pipeline", "inspection")


def generate() -> dict[str, dict[str, Any]]:
    """Build every schema from the current models."""
    from geobrep.adapters.native._container import NativeDocument
    from geobrep.batch.pipeline import Pipeline
    from geobrep.ops.inspection import InspectionReport

    schemas = {
        "scene": NativeDocument.model_json_schema(mode="serialization"),
        "pipeline": Pipeline.model_json_schema(mode="validation", by_alias=True),
        "inspection": InspectionReport.model_json_schema(mode="serialization"),
    }
    schemas["inspection"]["title"] = "geobrep inspection report"
    for name, schema in schemas.items():
        schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
        schema["$id"] = f"https://geobrep.org/schemas/{name}.schema.json"
    return schemas


def load(name: str) -> dict[str, Any]:
    """The stored schema ``name`` (one of :data:`SCHEMA_NAMES`)."""
    if name not in SCHEMA_NAMES:
        raise KeyError(f"unknown schema {name!r}; known: {', '.join(SCHEMA_NAMES)}")
    text = resources.files(__name__).joinpath(f"{name}.schema.json").read_text("utf-8")
    result: dict[str, Any] = json.loads(text)
    return result


def render(schema: dict[str, Any]) -> str:
    """The canonical text of a schema file."""
    return json.dumps(schema, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def write_all(folder: Path | None = None) -> list[Path]:
    """Write every schema into ``folder`` (default: this package's folder)."""
    target = folder or Path(__file__).parent
    written = []
    for name, schema in generate().items():
        path = target / f"{name}.schema.json"
        path.write_text(render(schema), encoding="utf-8")
        written.append(path)
    return written
