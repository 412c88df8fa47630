"""``python -m geobrep.schemas``: regenerate the stored JSON Schemas."""

from geobrep.schemas import write_all

for path in write_all():
    print(f"wrote {path}")
