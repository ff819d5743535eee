"""The numbers of a measurement file's rows, parsed (every bad cell reported where it is), grouped by record."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .columns import RECORD
from .errors import DataError
from .layout import Layout


@dataclass(frozen=True)
class Rows:
    """The data rows of one record: their line numbers, record id and numeric cells by column."""

    record: str
    lines: np.ndarray
    values: dict[str, np.ndarray]



def group_rows(path: Path, header: list[str], rows, layout: Layout) -> list[Rows]:
    """Numbers parsed (every bad cell reported where it is) and rows grouped by record."""
    numeric = [layout.time, *layout.states, *layout.conditions]
    index = {name: header.index(name) for name in header}
    ids, lines, table = [], [], np.empty((len(rows), len(numeric)))
    for r, (line, cells) in enumerate(rows):
        if layout.record:
            ids.append(cells[index[RECORD]].strip())
            if not ids[-1]:
                raise DataError("empty record id", path, line, RECORD)
        lines.append(line)
        for c, name in enumerate(numeric):
            table[r, c] = _number(cells[index[name]], path, line, name)
    groups, order = {}, []
    for r, rid in enumerate(ids or ["1"] * len(rows)):
        if rid not in groups:
            groups[rid] = [r]
            order.append(rid)
        elif groups[rid][-1] != r - 1:
            raise DataError(f"record {rid} appears again after other records (it started on line "
                            f"{lines[groups[rid][0]]}); the rows of a record must be together, or give the second "
                            "run another record id", path, lines[r], RECORD)
        else:
            groups[rid].append(r)
    if not order:
        raise DataError("no data rows below the header", path)
    return [Rows(rid, np.array(lines)[groups[rid]], {name: table[groups[rid], c] for c, name in enumerate(numeric)})
            for rid in order]


def _number(text: str, path: Path, line: int, column: str) -> float:
    cell = text.strip()
    if not cell:
        raise DataError("empty cell; every sample needs a value (drop the row or fill the gap, keeping the "
                        "time evenly spaced)", path, line, column)
    try:
        value = float(cell)
    except ValueError:
        raise DataError(f"{cell!r} is not a number", path, line, column) from None
    if not math.isfinite(value):
        raise DataError(f"{cell!r}: every value must be a finite number", path, line, column)
    return value

