"""Committed outputs compared as numbers, not bytes (``gearsym.reproduce.rounding`` says how): texts, listings, JSON
records, and CSV files cell by cell."""
from __future__ import annotations

import csv
import io

from gearsym.reproduce.rounding import NUMBER, differences, numbers_agree, record_differences

__all__ = ["NUMBER", "csv_differences", "differences", "json_differences", "numbers_agree"]
json_differences = record_differences


def csv_differences(made: str, committed: str, rel: float = 1e-9, absolute: float = 0.0) -> list[str]:
    """Where two CSV texts differ: headers and text cells exactly, numbers within ``rel`` (or ``absolute``)."""
    rows_made, rows_committed = (list(csv.reader(io.StringIO(t))) for t in (made, committed))
    if len(rows_made) != len(rows_committed):
        return [f"{len(rows_made)} rows made, {len(rows_committed)} committed"]
    found = []
    for number, (m, c) in enumerate(zip(rows_made, rows_committed), 1):
        if len(m) != len(c):
            found.append(f"row {number}: {len(m)} cells made, {len(c)} committed")
            continue
        for x, y in zip(m, c):
            if x == y:
                continue
            try:
                a, b = float(x), float(y)
            except ValueError:
                found.append(f"row {number}: {x!r} made, {y!r} committed")
                continue
            if not abs(a - b) <= max(absolute, rel * max(abs(a), abs(b))):
                found.append(f"row {number}: {x} made, {y} committed")
        if len(found) > 20:
            break
    return found
