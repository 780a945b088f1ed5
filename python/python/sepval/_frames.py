"""Telemetry as a table: a pandas DataFrame, or a numpy record array when pandas is absent.

The columns are ``t_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg`` (SI units, angles in
degrees; a file in feet is converted on reading), float64 with the very bits sepval read; the
file's ``# key = value`` metadata is in ``attrs`` (the last value of a key repeated), so a
table given back as ``data=`` keeps its flight condition.
"""

from __future__ import annotations

from typing import Any, Dict, List, Tuple

import numpy as np

COLUMNS: Tuple[str, ...] = ("t_s", "x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg")


class Telemetry(np.recarray):
    """A numpy record array of telemetry with the file's metadata in ``attrs`` (what
    ``read_telemetry`` and ``simulate`` return when pandas is not installed)."""

    attrs: Dict[str, str]

    def __array_finalize__(self, obj: Any) -> None:
        super().__array_finalize__(obj)
        self.attrs = dict(getattr(obj, "attrs", None) or {})


def table(columns: Dict[str, Any]) -> Any:
    """The table of what the native readers return (one float64 buffer per column)."""
    arrays = [np.frombuffer(columns[c], dtype="<f8").astype(np.float64) for c in COLUMNS]
    attrs: Dict[str, str] = {}
    for key, value in columns["metadata"]:
        attrs[key] = value
    try:
        import pandas
    except ImportError:
        records = np.rec.fromarrays(arrays, names=list(COLUMNS)).view(Telemetry)
        records.attrs = attrs
        return records
    frame = pandas.DataFrame(dict(zip(COLUMNS, arrays)))
    frame.attrs.update(attrs)
    return frame


def band_table(t_s: List[float], channels: Dict[str, Dict[str, List[float]]]) -> Any:
    """Bands as a table: ``t_s`` then ``CHANNEL_lo``, ``CHANNEL_mid``, ``CHANNEL_hi`` for
    each channel."""
    names = ["t_s"]
    arrays = [np.asarray(t_s, dtype=np.float64)]
    for channel, band in channels.items():
        for part in ("lo", "mid", "hi"):
            names.append(f"{channel}_{part}")
            arrays.append(np.asarray(band[part], dtype=np.float64))
    return records(names, arrays)


def records(names: List[str], arrays: List[Any]) -> Any:
    """Columns as a DataFrame, or a numpy record array without pandas."""
    try:
        import pandas
    except ImportError:
        return np.rec.fromarrays(arrays, names=names)
    return pandas.DataFrame(dict(zip(names, arrays)))


def rows(items: List[Dict[str, Any]]) -> Any:
    """A list of flat records as a DataFrame, or the list itself without pandas."""
    try:
        import pandas
    except ImportError:
        return items
    return pandas.DataFrame(items)
