"""A sweep in physical units as a table beside the engine's (``FILE.physical.csv``)."""
from __future__ import annotations

import csv
import io
from pathlib import Path

from ..files import write_atomically


def write_physical_table(result, path: Path) -> Path:
    """One row per point, each column headed by its name and unit (``speed [rpm]``, ``A_x [µm]``)."""
    names = list(result.columns)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([f"{n} [{result.units[n]}]" if n in result.units else n for n in names])
    for i in range(len(result)):
        writer.writerow([_cell(result.columns[n][i]) for n in names])
    return write_atomically(path, buffer.getvalue())


def _cell(value) -> str:
    return value if isinstance(value, str) else repr(float(value))
