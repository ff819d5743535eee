"""Reading a measurement file as CSV text, streamed: its header (line number and names), then its rows with their
line numbers, one at a time, within limits checked as the text comes (so that ``/dev/zero`` or a file of one
endless line is refused at once, not after it has filled the memory)."""
from __future__ import annotations

import csv
import os
import select
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

from .errors import DataError

#: the largest measurement file read (about 20 million samples of one channel); more is split into files
MAX_FILE_BYTES = 1 << 30
#: the longest line (some thousands of columns); below the csv module's own limit on one cell (131072)
MAX_LINE_CHARS = 100_000
#: characters read at once
BLOCK_CHARS = 1 << 20
#: separators that are not commas, by the name a message gives them
SEPARATORS = {";": "semicolons (;)", "\t": "tabs", "|": "bars (|)"}


def megabytes(count: int) -> str:
    return f"{count / 2**20:.1f} MiB" if count >= 2**20 else f"{count} bytes"


@contextmanager
def csv_rows(path: Path) -> Iterator[tuple[int, list[str], Iterator[tuple[int, list[str]]]]]:
    """While open: the header's line number and names, and an iterator of the non-blank rows after it as (line
    number, cells), each row with as many cells as the header names."""
    try:
        handle = _open_text(path)
    except FileNotFoundError:
        raise DataError("no such file", path) from None
    except IsADirectoryError:
        raise DataError("is a folder; give the CSV file(s) of measurements in it", path) from None
    except OSError as exc:
        raise DataError(f"cannot be opened ({exc.strerror or exc})", path) from None
    with handle:
        info = os.fstat(handle.fileno())
        if stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode) or stat.S_ISSOCK(info.st_mode):
            raise DataError("is a device, not a file of measurements; give a CSV file", path)
        if stat.S_ISREG(info.st_mode) and info.st_size > MAX_FILE_BYTES:
            raise DataError(f"is {megabytes(info.st_size)}, more than the {megabytes(MAX_FILE_BYTES)} a measurement "
                            "file may have: split its records into several files and give them all", path)
        reader = csv.reader(_lines(handle, path))
        header_line, header = 0, None
        for line, cells in _rows(reader, path):
            header_line, header = line, [c.strip() for c in cells]
            break
        if header is None:
            raise DataError("the file is empty; expected a header line naming the columns, e.g. tau,x", path)
        _check_separator(header, path, header_line)
        yield header_line, header, _rows(reader, path, header_line, len(header))


#: seconds a named pipe (FIFO) is waited on for its writer's first text before it is refused (opening one with no
#: writer would wait for ever)
FIFO_WAIT = 10.0


def _open_text(path: Path) -> IO[str]:
    """``path`` opened as UTF-8 text (universal newlines: \\r\\n and \\r read as \\n); a named pipe is opened
    without waiting for a writer, then given ``FIFO_WAIT`` seconds for its first text."""
    try:
        fifo = stat.S_ISFIFO(os.stat(path).st_mode)
    except FileNotFoundError:
        raise
    except OSError:
        fifo = False
    if not fifo:
        return open(path, encoding="utf-8-sig")
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        waiting = select.poll()
        waiting.register(fd, select.POLLIN)
        if not waiting.poll(int(FIFO_WAIT * 1000)):
            raise DataError(f"is a named pipe (FIFO) that nothing wrote to in {FIFO_WAIT:g} s: start its writer "
                            "first (or give a file)", path)
        os.set_blocking(fd, True)
        return open(fd, encoding="utf-8-sig", closefd=True)
    except BaseException:
        os.close(fd)
        raise


def _rows(reader, path: Path, header_line: int = 0, cells: int | None = None) -> Iterator[tuple[int, list[str]]]:
    """The reader's non-blank rows as (line number, cells), each of ``cells`` cells if given; the reader's own
    complaints (a cell too long, a quote left open) said as a DataError."""
    try:
        for row in reader:
            if len(row) != cells or not row[0].strip():
                if not any(c.strip() for c in row):
                    continue
                if cells is not None and len(row) != cells:
                    raise DataError(f"{len(row)} cells, but the header (line {header_line}) names {cells} columns",
                                    path, reader.line_num)
            yield reader.line_num, row
    except csv.Error as exc:
        raise DataError(f"not readable as CSV ({exc})", path, reader.line_num + 1) from None


def _lines(handle: IO[str], path: Path) -> Iterator[str]:
    """The text line by line, read in blocks with bounds: a line longer than ``MAX_LINE_CHARS``, a NUL character
    (a binary file) or more than ``MAX_FILE_BYTES`` in all (a pipe, a device, a file that grows) ends the
    reading."""
    total, number, carry = 0, 0, ""
    while True:
        try:
            block = handle.read(BLOCK_CHARS)
        except UnicodeDecodeError:
            raise DataError(f"cannot read it as UTF-8 text ({_first_bad_byte(path, number)}): save it as UTF-8 CSV",
                            path) from None
        total += len(block)
        if "\0" in block:
            raise DataError("holds NUL characters: a binary file, not CSV text", path,
                            number + (carry + block[:block.index("\0")]).count("\n") + 1)
        if total > MAX_FILE_BYTES:
            raise DataError(f"more than {megabytes(MAX_FILE_BYTES)} of text, the most a measurement file may have: "
                            "split its records into several files and give them all", path)
        if not block:
            if carry:
                yield carry
            return
        lines = (carry + block).split("\n")
        carry = lines.pop()
        if len(carry) > MAX_LINE_CHARS or (lines and max(map(len, lines)) > MAX_LINE_CHARS):
            long = next(i for i, line in enumerate([*lines, carry]) if len(line) > MAX_LINE_CHARS)
            raise DataError(f"the line is longer than {MAX_LINE_CHARS} characters: not a CSV file of measurements "
                            "(one line per sample)", path, number + long + 1)
        number += len(lines)
        yield from (line + "\n" for line in lines)


def _first_bad_byte(path: Path, lines_read: int) -> str:
    """Where the first byte that is not UTF-8 is: its position and line, never its value (the file may be no
    measurement, and its bytes nobody's business)."""
    offset, lines, carry = 0, 0, b""
    try:
        with open(path, "rb") as raw:
            while True:
                block = raw.read(BLOCK_CHARS)
                data = carry + block
                try:
                    data.decode("utf-8")
                except UnicodeDecodeError as exc:
                    if block and exc.end == len(data):  # (a character cut by the block's end: read on)
                        lines, offset, carry = lines + data[:exc.start].count(b"\n"), offset + exc.start, data[exc.start:]
                        continue
                    line = lines + data[:exc.start].count(b"\n") + 1
                    return f"byte {offset + exc.start + 1}, on line {line}, is not UTF-8"
                if not block:
                    break
                lines, offset, carry = lines + data.count(b"\n"), offset + len(data), b""
    except OSError:
        pass
    return f"a byte that is not UTF-8 after line {lines_read}"


def _check_separator(header: list[str], path: Path, line: int) -> None:
    """A header of one cell that holds another separator: the file is not comma-separated."""
    if len(header) != 1:
        return
    found = [sep for sep in SEPARATORS if sep in header[0]]
    if found:
        sep = max(found, key=header[0].count)
        names = ", ".join(part.strip() for part in header[0].split(sep))
        raise DataError(f"the columns are separated by {SEPARATORS[sep]}, not commas (the header names {names}); "
                        "gearsym reads comma-separated files with a point as the decimal mark: write the file "
                        "with commas between the columns", path, line)
