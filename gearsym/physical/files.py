"""Results in physical units as files beside the engine's: a table (``FILE.physical.csv``, each column headed by
its name and unit) and, for a sweep, its record (``FILE.physical.json``: the scaling, the units and the
findings along the physical values)."""
from __future__ import annotations

import csv
import io
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..checks import json_safe
from ..files.atomic import write_atomically


def write_physical_table(result, path: Path) -> Path:
    """One row per point of a sweep in physical units (``speed [rpm]``, ``A_x [µm]``)."""
    names = list(result.columns)
    rows = ({n: result.columns[n][i] for n in names} for i in range(len(result)))
    return write_physical_rows(names, rows, result.units, path)


def write_physical_rows(names: Sequence[str], rows, units: Mapping[str, str], path: Path) -> Path:
    """Rows (dicts) as a table whose headers give each column's unit."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([f"{n} [{units[n]}]" if n in units else n for n in names])
    for row in rows:
        writer.writerow([_cell(row[n]) for n in names])
    return write_atomically(path, buffer.getvalue())


def write_physical_record(result, path: Path) -> Path:
    """A sweep's physical record (``result.record["physical"]``: the scaling, units, jumps and hysteresis)."""
    record = {"model": result.model, **result.record["physical"]}
    return write_atomically(path, json.dumps(json_safe(record), indent=1, allow_nan=False) + "\n")


def _cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value)).lower()
    if isinstance(value, (str, int, np.integer)):
        return str(value)
    return repr(float(value))
