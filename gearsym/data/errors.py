"""The error of a measured-data file: what is wrong, and where (the file, the line, the column)."""
from __future__ import annotations

from pathlib import Path
from typing import Union

from ..errors import GearsymError

PathLike = Union[str, Path]


class DataError(GearsymError):
    """A measured-data file that cannot be used; says where: ``source``, ``line`` and ``column``."""

    def __init__(self, message: str, source: PathLike, line: int | None = None, column: str | None = None):
        self.source, self.line, self.column = Path(source), line, column
        where = str(source) + (f", line {line}" if line else "") + (f", column {column!r}" if column else "")
        super().__init__(f"{where}: {message}")

