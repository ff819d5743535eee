"""``F.csv`` (one row per branch point) and ``F.json`` (the record and the bifurcations) of a continuation."""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from ..checks import json_safe
from ..files.atomic import write_atomically
from ..sweep.store import number, sidecar
from .branches import Continuation


def write_orbits(result: Continuation, path: str | Path, extra: dict | None = None) -> tuple[Path, Path]:
    """Write the branch points to ``path`` (CSV, floats as ``repr``: they read back to the same bits) and the
    record with its bifurcations beside it (``.json``, with ``extra`` keys: the same in physical units); both
    atomically. Returns the two paths."""
    path = Path(path)
    rows = result.rows()
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    header = list(rows[0]) if rows else []
    writer.writerow(header)
    for row in rows:
        writer.writerow([_cell(row[k]) for k in header])
    write_atomically(path, out.getvalue())
    record = sidecar(path, ".json")
    write_atomically(record, json.dumps({**result.as_dict(), **json_safe(extra or {})}, indent=1, allow_nan=False)
                     + "\n")
    return path, record


def _cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value)).lower()
    if isinstance(value, (int, np.integer, str)):
        return str(value)
    return number(value)
