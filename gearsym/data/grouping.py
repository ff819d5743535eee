"""The numbers of a measurement file's rows, parsed as they are read (every bad cell reported where it is), and
grouped by record in one pass: a record is a run of consecutive rows with the same id."""
from __future__ import annotations

import math
import itertools
import operator
from array import array
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .columns import RECORD
from .errors import DataError
from .layout import Layout

#: the most records one file may hold (each is fitted window by window: split a larger collection into files)
MAX_RECORDS = 100_000
#: rows parsed as numbers at once
CHUNK = 1 << 14


@dataclass(frozen=True)
class Rows:
    """The data rows of one record: their line numbers, record id and numeric cells by column."""

    record: str
    lines: np.ndarray
    values: dict[str, np.ndarray]


def group_rows(path: Path, header: list[str], rows: Iterable[tuple[int, list[str]]], layout: Layout) -> list[Rows]:
    """Numbers parsed and rows grouped by record, in one pass over ``rows`` (line number, cells)."""
    numeric = [layout.time, *layout.states, *layout.conditions]
    where = [header.index(name) for name in numeric]
    at = header.index(RECORD) if layout.record else None
    cells_of = operator.itemgetter(*where) if len(where) > 1 else (lambda cells: (cells[where[0]],))
    table, lines, pending = array("d"), array("q"), []
    starts: list[tuple[int, str]] = []  # (first row, id) of each record, in file order
    seen: dict[str, int] = {}  # id -> the line its record started on
    current = None
    for line, cells in rows:
        rid = "1"
        if at is not None:
            rid = cells[at].strip()
            if not rid:
                raise DataError("empty record id", path, line, RECORD)
        if rid != current:
            if rid in seen:
                raise DataError(f"record {rid} appears again after other records (it started on line {seen[rid]}); "
                                "the rows of a record must be together, or give the second run another record id",
                                path, line, RECORD)
            if len(seen) == MAX_RECORDS:
                raise DataError(f"more than {MAX_RECORDS} records in one file: split them into several files and "
                                "give them all", path, line, RECORD)
            seen[rid], current = line, rid
            starts.append((len(lines), rid))
        lines.append(line)
        pending.append(cells_of(cells))
        if len(pending) == CHUNK:
            _parse(pending, lines, table, numeric, path)
    _parse(pending, lines, table, numeric, path)
    if not starts:
        raise DataError("no data rows below the header", path)
    line_numbers = np.frombuffer(lines, dtype=np.int64) if lines else np.empty(0, dtype=np.int64)
    columns = np.frombuffer(table, dtype=float).reshape(-1, len(numeric)).T.copy()  # one contiguous row per column
    _check_finite(columns, numeric, line_numbers, path)
    bounds = [first for first, _ in starts[1:]] + [len(line_numbers)]
    return [Rows(rid, line_numbers[first:stop], {name: values[first:stop] for name, values in zip(numeric, columns)})
            for (first, rid), stop in zip(starts, bounds)]


def _parse(pending: list[tuple[str, ...]], lines: array, table: array, names: list[str], path: Path) -> None:
    """The cells of the ``pending`` rows (the last rows of ``lines``) as numbers onto ``table``, row after row; a
    cell that is not a number is reported with its line and column."""
    if not pending:
        return
    try:
        table.extend(map(float, itertools.chain.from_iterable(pending)))
    except ValueError:
        first = len(lines) - len(pending)
        for k, cells in enumerate(pending):
            for text, name in zip(cells, names):
                try:
                    float(text)
                except ValueError:
                    raise _not_a_number(text, path, lines[first + k], name) from None
        raise
    pending.clear()


def _not_a_number(text: str, path: Path, line: int, column: str) -> DataError:
    cell = text.strip()
    if not cell:
        return DataError("empty cell; every sample needs a value (drop the row or fill the gap, keeping the time "
                         "evenly spaced)", path, line, column)
    return DataError(f"{cell!r} is not a number", path, line, column)


def _check_finite(table: list[np.ndarray], names: list[str], lines: np.ndarray, path: Path) -> None:
    """Every value a finite number: the first that is not (by row, then by column) is reported."""
    first = None
    for values, name in zip(table, names):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size and (first is None or bad[0] < first[0]):
            first = (int(bad[0]), name, float(values[bad[0]]))
    if first is not None:
        row, name, value = first
        shown = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        raise DataError(f"{shown!r}: every value must be a finite number", path, int(lines[row]), name)
