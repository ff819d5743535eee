"""Reading a measurement file as CSV text: its header (line number and names) and its rows with their line numbers."""
from __future__ import annotations

import csv
from pathlib import Path

from .errors import DataError


def read_csv(path: Path) -> tuple[int, list[str], list[tuple[int, list[str]]]]:
    """The header (its line number and names) and the non-blank rows with their line numbers."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DataError("no such file", path) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read it as UTF-8 text ({exc})", path) from None
    reader = csv.reader(text.splitlines())
    header_line, header, rows = 0, None, []
    for cells in reader:
        if not any(c.strip() for c in cells):
            continue
        if header is None:
            header_line, header = reader.line_num, [c.strip() for c in cells]
            continue
        if len(cells) != len(header):
            raise DataError(f"{len(cells)} cells, but the header (line {header_line}) names {len(header)} columns",
                            path, reader.line_num)
        rows.append((reader.line_num, cells))
    if header is None:
        raise DataError("the file is empty; expected a header line naming the columns, e.g. tau,x", path)
    return header_line, header, rows

