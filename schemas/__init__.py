"""JSON Schemas generated from geobrep's pydantic models."""
