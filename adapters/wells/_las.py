"""LAS 2.0 / 3.0 well logs through lasio: the curves as :class:`~geobrep.WellLog` on measured
depth, attached to a well.

A LAS file holds logs, not a trajectory: read alone it gives a :class:`~geobrep.Well` of one
station at the head the ``~Well`` section states (``X``/``Y`` or ``XCOORD``/``YCOORD``, the datum
elevation ``EKB``, ``EDF`` or ``EGL``; 0 where absent) at MD ``STRT``, its logs on the index curve
(``DEPT``, ``DEPTH`` or ``MD``). :func:`attach_las` puts the logs of a LAS file on a well that has
its trajectory. Each curve keeps every row, its unit, and the file's ``NULL`` as its no-data
value; a file logged upwards (negative ``STEP``) is turned to increasing depth.

The writer writes the logs on one index (LAS has one depth column): logs sampled at different
depths are written on the union of their depths, ``NULL`` where a log has no sample. The head is
``X``/``Y``/``ZHEAD`` and the stations go in the free-text ``~Other`` section under a
``geobrep trajectory: MD X Y Z`` line, which this reader reads back.
"""

from __future__ import annotations

import io
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.limits import human_bytes, parse_numbers
from geobrep.errors import EntityValidationError, FormatError, import_optional
from geobrep.model.entities import Well, WellLog
from geobrep.model.scene import Scene

__all__ = ["LasWarning", "attach_las", "las_losses", "looks_like_las", "read_las", "write_las"]


class LasWarning(UserWarning):
    """What a LAS file cannot hold of what is written."""


_MAX_FILE = 1 << 30
_INDEX = ("DEPT", "DEPTH", "MD")
_NULL = -999.25


def looks_like_las(head: bytes) -> bool:
    """True when the first line that is not a comment opens a ``~V`` (version) section."""
    for line in head.lstrip(b"\xef\xbb\xbf").splitlines():
        text = line.strip()
        if text and not text.startswith(b"#"):
            return text[:2].upper() == b"~V"
    return False


def _lasio() -> Any:
    return import_optional("lasio", "wells", "LAS well logs")


def _parsed(path: Path) -> Any:
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise FormatError(f"cannot open the LAS file: {exc.strerror}", path) from None
    if size > _MAX_FILE:
        raise FormatError(f"the LAS file is {human_bytes(size)}, more than a LAS file may be", path)
    lasio = _lasio()
    text = path.read_bytes().decode("latin-1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # lasio logs and warns on every oddity
        try:
            las = lasio.read(io.StringIO(text), ignore_header_errors=False, engine="normal")
        except Exception as exc:  # lasio raises bare Exceptions, KeyErrors, ValueErrors ...
            raise FormatError(f"lasio cannot read it: {type(exc).__name__}: {exc}", path) from None
    if not las.curves:
        raise FormatError("the LAS file has no curves", path)
    return las


def _header_value(las: Any, *names: str) -> Any:
    for name in names:
        item = las.well.get(name)
        value = getattr(item, "value", None)
        if value not in (None, ""):
            return value
    return None


def _number(value: Any) -> float | None:
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def _logs(las: Any, path: Path) -> tuple[dict[str, WellLog], NDArray[np.float64], str]:
    """The curves on the index, in increasing depth; the index and its unit."""
    index_curve = las.curves[0]
    if index_curve.mnemonic.upper().split(":")[0] not in _INDEX:
        raise FormatError(
            f"the first curve {index_curve.mnemonic!r} is not a depth index ({', '.join(_INDEX)})",
            path,
        )
    try:
        md = np.asarray(index_curve.data, dtype=np.float64)
    except (TypeError, ValueError):
        raise FormatError("the depth index has non-numeric values", path) from None
    null = _number(_header_value(las, "NULL"))
    if md.size and (not np.isfinite(md).all() or (null is not None and (md == null).any())):
        raise FormatError("the depth index has null or non-numeric values", path)
    order = np.argsort(md, kind="stable") if md.size > 1 and md[0] > md[-1] else None
    logs: dict[str, WellLog] = {}
    for curve in las.curves[1:]:
        values = np.asarray(curve.data)
        if values.dtype.kind not in "iuf":
            continue  # text curves (LAS 3 strings) have no numeric log
        if order is not None:
            values = values[order]
        if null is not None and values.dtype.kind == "f":
            values = np.where(np.isnan(values), null, values)  # lasio reads NULL as NaN
        name = curve.mnemonic or f"curve_{len(logs) + 1}"
        try:
            logs[name] = WellLog(
                md=md if order is None else md[order],
                values=values,
                unit=curve.unit or None,
                no_data_value=null,
                metadata={"las": {"description": curve.descr}} if curve.descr else {},
            )
        except ValueError as exc:  # depths neither increasing nor decreasing, ...
            raise FormatError(f"curve {name!r}: {exc}", path) from None
    return logs, md if order is None else md[order], index_curve.unit or ""


def _version(las: Any) -> str:
    item = las.version.get("VERS")
    return str(getattr(item, "value", "") or "")


_TRAJECTORY = "geobrep trajectory: MD X Y Z"


def _trajectory(las: Any, path: Path) -> NDArray[np.float64] | None:
    """The ``MD X Y Z`` stations geobrep writes in the free-text ``~Other`` section."""
    text = str(las.other or "").strip()
    if not text.startswith(_TRAJECTORY):
        return None
    try:
        numbers = parse_numbers(text[len(_TRAJECTORY) :])
    except ValueError as exc:
        raise FormatError(f"~Other trajectory: {exc}", path) from None
    if numbers.size == 0 or numbers.size % 4:
        raise FormatError(f"~Other trajectory: {numbers.size} numbers are not MD X Y Z rows", path)
    return numbers.reshape(-1, 4)


def read_las(path: Path) -> Scene:
    """A scene of one well holding the LAS file's logs (one station at the head, or the stations
    geobrep wrote in ``~Other``)."""
    las = _parsed(path)
    logs, md, unit = _logs(las, path)
    stations = _trajectory(las, path)
    x = _number(_header_value(las, "X", "XCOORD", "XWELL")) or 0.0
    y = _number(_header_value(las, "Y", "YCOORD", "YWELL")) or 0.0
    datum, elevation = "", None
    for key in ("EKB", "EDF", "EGL"):
        elevation = _number(_header_value(las, key))
        if elevation is not None:
            datum = key[1:]
            break
    start = float(md[0]) if md.size else 0.0
    name = str(_header_value(las, "WELL") or path.stem)
    head = [x, y, elevation or 0.0]
    if stations is not None:
        head = [x, y, _number(_header_value(las, "ZHEAD")) or head[2]]
    try:
        well = Well(
            name=name,
            head=head,
            vertices=[head] if stations is None else stations[:, 1:],
            md=[start] if stations is None else stations[:, 0],
            datum=datum,
            datum_elevation=elevation,
            logs=logs,
            metadata={"las": {"version": _version(las), "md_unit": unit}},
        )
    except EntityValidationError as exc:
        raise FormatError(f"the well is invalid: {exc}", path) from None
    return Scene(entities=[well.replace(id=0)], name=path.stem)


def attach_las(well: Well, path: str | Path) -> Well:
    """``well`` with the logs of the LAS file ``path`` added (a log of the same name replaced).

    >>> import tempfile, pathlib
    >>> las = pathlib.Path(tempfile.mkdtemp()) / "w.las"
    >>> _ = las.write_text("~V\\nVERS. 2.0:\\nWRAP. NO:\\n~W\\nNULL. -999.25:\\n"
    ...                    "~C\\nDEPT.M :\\nGR.API :\\n~A\\n100 55.5\\n101 -999.25\\n")
    >>> well = Well(head=[0, 0, 0], vertices=[[0, 0, 0], [0, 0, -200]], md=[0, 200])
    >>> log = attach_las(well, las).logs["GR"]
    >>> log.md.tolist(), log.values.tolist(), log.no_data_value
    ([100.0, 101.0], [55.5, -999.25], -999.25)
    """
    logs, _, _ = _logs(_parsed(Path(path)), Path(path))
    return well.replace(logs={**well.logs, **logs})


def _shared(depths: list[NDArray[np.float64]]) -> bool:
    return all(d.shape == depths[0].shape and (d == depths[0]).all() for d in depths)


def _index(well: Well) -> NDArray[np.float64]:
    """The depths of the LAS index: the one all logs share, else the union of theirs."""
    depths = [log.md for log in well.logs.values()]
    if not depths:
        return well.md.copy()
    if _shared(depths):
        return depths[0]
    warnings.warn(
        f"{well.label}: logs on different depths share one index in a LAS file (NULL-filled)",
        LasWarning,
        stacklevel=4,
    )
    return np.unique(np.concatenate(depths))


def write_las(scene: Scene, path: Path, options: object) -> None:
    """Write the first well's logs as a LAS 2.0 file (values as exact decimal text)."""
    lasio = _lasio()
    wells = [e for e in scene.entities if isinstance(e, Well)]
    if not wells:
        raise FormatError("the scene has no well to write as LAS", path)
    well = wells[0]
    md = _index(well)
    given = {log.no_data_value for log in well.logs.values() if log.no_data_value is not None}
    null = given.pop() if len(given) == 1 else _NULL
    las = lasio.LASFile()
    las.well["WELL"].value = well.name or path.stem
    las.well["NULL"].value = null
    las.well["STRT"].value = float(md[0]) if md.size else 0.0
    las.well["STOP"].value = float(md[-1]) if md.size else 0.0
    las.well["STEP"].value = 0.0
    x, y, z = (float(v) for v in well.head)
    las.well.append(lasio.HeaderItem("X", "", x, "X of the well head"))
    las.well.append(lasio.HeaderItem("Y", "", y, "Y of the well head"))
    las.well.append(lasio.HeaderItem("ZHEAD", "", z, "Z of the well head"))
    rows = np.column_stack([well.md, well.vertices])
    las.other = _TRAJECTORY + "\n" + "\n".join(" ".join(map(repr, r)) for r in rows.tolist())
    if well.datum_elevation is not None and well.datum in ("KB", "DF", "GL"):
        elevation = well.datum_elevation
        las.well.append(lasio.HeaderItem(f"E{well.datum}", "", elevation, "datum elevation"))
    unit = well.metadata.get("las", {})
    md_unit = unit.get("md_unit", "M") if isinstance(unit, dict) else "M"
    las.append_curve("DEPT", md, unit=str(md_unit or "M"))
    for name, log in well.logs.items():
        column = np.full(md.shape, null, dtype=np.float64)
        column[np.searchsorted(md, log.md)] = np.where(
            np.isnan(log.values.astype(np.float64)), null, log.values
        )
        description = log.metadata.get("las", {})
        descr = description.get("description", "") if isinstance(description, dict) else ""
        las.append_curve(name, column, unit=log.unit or "", descr=str(descr))
    with path.open("w", encoding="utf-8", newline="\n") as handle:
        las.write(handle, version=2.0, wrap=False, fmt="%.17g", column_fmt={0: "%.17g"})


def las_losses(scene: Scene, path: Path) -> list[str]:
    """What a LAS file cannot hold of the scene's first well."""
    wells = [e for e in scene.entities if isinstance(e, Well)]
    lost: list[str] = []
    for well in wells[:1]:
        if well.markers or well.zones:
            lost.append(f"{well.label}: its markers and zones")
        if any(log.values.dtype.kind in "iub" for log in well.logs.values()):
            lost.append(f"{well.label}: integer logs are written as decimals (read as floats)")
        depths = [log.md for log in well.logs.values()]
        if depths and not _shared(depths):
            lost.append(f"{well.label}: logs on different depths share one index (NULL-filled)")
    lost += [f"{w.label}: only the first well is written" for w in wells[1:]]
    return lost
