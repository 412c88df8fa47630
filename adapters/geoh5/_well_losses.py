"""What a geoh5 drillhole does not hold of a Well, one sentence each (numpy only: the loss
report is made before h5py is needed)."""

from __future__ import annotations

import numpy as np

from geobrep.adapters.geoh5._desurvey import desurvey, station_surveys
from geobrep.model.entities import Well, WellLog

__all__ = ["desurvey_error", "well_losses"]


def desurvey_error(well: Well) -> float:
    """Largest distance (m) between the stations and where geoh5 desurveys the float32 surveys
    geobrep writes for them (geoh5's arcs, not the stations' chords)."""
    if well.n_stations < 2:
        return 0.0
    rows = station_surveys(well.vertices, well.md)
    table = np.column_stack([rows[k] for k in ("Depth", "Azimuth", "Dip")]).astype(np.float64)
    placed = desurvey(well.head, table, float(well.md[-1]), well.md)
    return float(np.linalg.norm(placed - well.vertices, axis=1).max())


def _log_losses(where: str, log: WellLog) -> list[str]:
    lost = []
    values = np.asarray(log.values)
    if log.unit or log.no_data_value is not None or log.metadata:
        lost.append(f"{where}: unit, no-data value and metadata dropped")
    if values.dtype.kind == "f":
        missing = int(np.count_nonzero(np.isnan(values)))
        if missing:
            lost.append(f"{where}: {missing} NaN samples dropped (geoh5's no-data)")
        if values.dtype != np.float64:
            lost.append(f"{where}: {values.dtype} read back as float64")
    elif values.dtype != np.int32:
        lost.append(f"{where}: {values.dtype} stored as int32")
    repeated = int(np.count_nonzero(np.diff(log.md) == 0))
    if repeated:
        lost.append(f"{where}: {repeated} samples at a repeated depth dropped (one per depth)")
    return lost


def well_losses(well: Well) -> list[str]:
    """Datum, station properties, log details, marker and zone metadata, marker order, and how
    far geoh5's own desurveying of the surveys lies from the stations (kept as the trace)."""
    label = well.label
    lost = []
    if well.datum or well.datum_elevation is not None:
        lost.append(f"{label}: datum {well.datum!r} at {well.datum_elevation} dropped")
    names = [*well.point_data, *well.cell_data]
    if names:
        lost.append(f"{label}: station properties dropped: {', '.join(names)}")
    for name, log in well.logs.items():
        lost.extend(_log_losses(f"{label} log {name!r}", log))
    if any(m.metadata for m in well.markers) or any(z.metadata for z in well.zones):
        lost.append(f"{label}: metadata of markers and zones dropped")
    depths = [m.md for m in well.markers]
    if depths != sorted(depths):
        lost.append(f"{label}: markers read back in MD order")
    error = desurvey_error(well)
    if error:
        lost.append(
            f"{label}: geoh5 desurveys its float32 surveys to within {error:.3g} m of the "
            "stations (the stations are kept, as the drillhole's trace)"
        )
    return lost
