"""A sweep on disk: rows appended as points finish, so an interrupted sweep keeps them and resumes.

Three files share a stem: ``FILE.csv`` (one row per point), ``FILE.json``
(how the sweep was made and, at the end, what it found) and
``FILE.poincare.csv`` (the last stroboscopic samples of every point, for
bifurcation diagrams). Rows are written by a thread of the store's own and flushed after each batch of
points (at most a fraction of a second of work); a row cut off by a kill
is dropped when the sweep resumes, and a point is resumed only if it is whole
(its row and every one of its Poincare samples). A write that fails (the disk
full) cuts both files back to the last whole batch and ends the sweep with a
one-line error; the record then says ``failed`` and why. (The record of a running
sweep is written with room to spare, so that this can be said in place on a full
disk.) Running the same command again resumes:
the record in ``FILE.json`` must match the new command (else the error says
what differs). When every point is done, both CSV files are rewritten in the
plan's order, so the result does not depend on which thread finished first or
on where the sweep was interrupted. Floats are written with ``repr``, which
reads back to the same bits: a continuation resumed from a row continues
exactly where it stopped.
"""
from __future__ import annotations

import csv
import io
import json
import operator
import os
import queue
import threading
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GearsymError, on_command_line, option, option_name, warn
from ..files.atomic import write_atomically
from ..files.lock import release_lock, take_lock

#: spaces kept in the record of a running sweep, so that a failure can be recorded in place on a full disk
RECORD_ROOM = 2048


def overwrite_option() -> str:
    """The option that starts a sweep's files again, as the caller writes it (--overwrite, overwrite=True)."""
    return option("overwrite", True)


def start_again() -> str:
    """The advice 'pass --overwrite or choose another --out', as the caller writes it."""
    return f"pass {overwrite_option()} or choose another {option_name('out')}"


def number(x: float) -> str:
    return repr(float(x))


@dataclass(frozen=True)
class PoincareRows:
    """One point's rows of the Poincare table: the point's fields as its main row writes them (swept values,
    direction) and its samples (samples x states, floats: written with ``repr``, so a file read back gives
    the same rows, to the bit)."""

    where: tuple[str, ...]
    samples: np.ndarray

    def text(self) -> str:
        """The CSV lines (fields: where, sample index, states)."""
        head, n = ",".join(self.where) + ",", self.samples.shape[1]
        reprs = list(map(float.__repr__, self.samples.ravel().tolist()))
        return "".join([f"{head}{j},{','.join(reprs[k:k + n])}\n" for j, k in enumerate(range(0, len(reprs), n))])

    def whole(self, count: int) -> bool:
        """Whether the point has all its ``count`` samples (a point whose rows were cut off as they were written
        has fewer, and is not finished)."""
        return self.samples.shape[0] == count

    @classmethod
    def from_fields(cls, rows: Sequence[Sequence[str]], keys: int) -> "PoincareRows":
        """One point's rows as read from the table (``keys``: the fields before the sample index)."""
        return cls(tuple(rows[0][:keys]), np.array([r[keys + 1:] for r in rows], dtype=float).reshape(len(rows), -1))


def read_poincare(path: Path, keys: int, columns: list[str] | None = None) -> tuple[list[str], list[PoincareRows]]:
    """The columns of a Poincare table (none if it has no row) and its points, in the order they first appear
    (``keys``: the fields before the sample index; ``columns``: the header it must have)."""
    points: dict[tuple, list] = {}
    rows = read_rows(path, columns)
    for row in rows:
        fields = tuple(row.values())
        points.setdefault(fields[:keys], []).append(fields)
    return list(rows[0]) if rows else [], [PoincareRows.from_fields(p, keys) for p in points.values()]


_FLUSH = object()  # the writer thread's signal to flush


def sidecar(path: Path, suffix: str) -> Path:
    return path.with_name(path.stem + suffix)


class SweepStore:
    """The CSV, Poincare CSV and JSON record of one sweep."""

    def __init__(self, path: str | Path, columns: Sequence[str], strobe_columns: Sequence[str],
                 key_columns: Sequence[str], record: dict):
        self.path = Path(path)
        if self.path.suffix.lower() != ".csv":
            raise GearsymError(f"--out {self.path}: the sweep is written as CSV; name the file *.csv")
        self.meta_path = sidecar(self.path, ".json")
        self.strobe_path = sidecar(self.path, ".poincare.csv")
        self.columns, self.strobe_columns = list(columns), list(strobe_columns)
        self.key_columns = list(key_columns)  # the swept parameters, then "direction"
        self.record = record
        self._files: list[int] = []  # the Poincare table's and the table's descriptors, appending
        self._sizes: list[int] = []  # their sizes after the last batch written whole
        self.stored = 0  # points on disk, whole
        self._lock_fd: int | None = None
        self._appended: list[dict] | None = None  # the rows appended after a fresh start, in their order
        self._thread: threading.Thread | None = None  # the writer, started by the first append
        self._queue: queue.SimpleQueue | None = None
        self._failed: BaseException | None = None

    # ------------------------------------------------------------ opening
    def open(self, overwrite: bool | str = False) -> tuple[dict[tuple, dict], dict[tuple, PoincareRows]]:
        """Start the files, or resume them: returns the rows already done (and their Poincare rows) by key.
        ``overwrite="stale"``: start again files that another sweep wrote (or a changed model), resume the
        same sweep's: how a cache of sweeps (the reproduction's data) is kept."""
        if overwrite not in (False, True, "stale"):
            raise GearsymError(f"overwrite must be False, True or 'stale', not {overwrite!r}")
        self._lock()
        done, strobes = {}, {}
        if overwrite == "stale":
            overwrite = self.path.exists() and self._record_differs() is not None
        if overwrite:
            for p in (self.path, self.meta_path, self.strobe_path):
                p.unlink(missing_ok=True)
        elif self.path.exists() and (read_rows(self.path) if self.meta_path.exists() else True):
            self._check_record()  # (a file with no finished point is simply started again)
            done = self._read(self.path, self.columns)
            _, read = read_poincare(self.strobe_path, len(self.key_columns), self.strobe_columns) \
                if self.strobe_path.exists() else ([], [])
            strobes = {k: r for r in read if (k := self.key(dict(zip(self.key_columns, r.where)))) in done}
            # (rows written before their main row are dropped)
            samples = self.record.get("poincare_samples")
            lacking = [k for k in done if k not in strobes]
            if samples and lacking:
                raise GearsymError(f"{self.strobe_path} lacks the Poincare samples of {len(lacking)} finished "
                                   "points (deleted or damaged?), so the sweep cannot be resumed whole: pass "
                                   f"{overwrite_option()} to start again")
            partial = [k for k, r in strobes.items() if not r.whole(samples or 0)]
            for k in partial:  # (cut off as they were written, by an older gearsym: computed again)
                del done[k], strobes[k]
            if partial:
                warn(f"{self.strobe_path}: {len(partial)} point(s) lack some of their {samples} Poincare samples "
                     "(cut off as they were written); they are computed again")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._write_table(self.path, self.columns, map(_fields(self.columns), done.values()))  # (drops a row cut off)
        self._write_table(self.strobe_path, self.strobe_columns, (), "".join(r.text() for r in strobes.values()))
        self.write_record(status="running", room=RECORD_ROOM)
        self._files = [_append_only(p) for p in (self.strobe_path, self.path)]
        self._sizes = [os.fstat(fd).st_size for fd in self._files]
        self._main_fields = _fields(self.columns)
        self._appended = None if done else []
        self.stored = len(done)
        return done, strobes

    def key(self, row: dict) -> tuple:
        try:
            return row_key(row, self.key_columns[:-1])
        except ValueError as exc:
            raise GearsymError(f"{self.path}: a swept parameter is not a number: {exc}") from None

    def _check_record(self) -> None:
        why = self._record_differs()
        if why is not None:
            raise GearsymError(why)

    def _record_differs(self) -> str | None:
        """Why the files cannot be resumed by this sweep (their record is missing, unreadable or another
        sweep's), or None."""
        if not self.meta_path.exists():
            return (f"{self.path} exists but {self.meta_path.name} (the record of how it was made) "
                    f"does not, so it cannot be resumed: {start_again()}")
        try:
            old = json.loads(self.meta_path.read_text())["sweep"]
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            return f"{self.meta_path}: not a gearsym sweep record ({exc}); {start_again()}"
        new = json.loads(json.dumps(self.record))  # compare as JSON sees them
        differ = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
        if not differ:
            return None
        detail = "; ".join(f"{k}: {_short(old.get(k))} before, {_short(new.get(k))} now" for k in differ)
        return (f"{self.path} was written by a different sweep ({detail}). To resume it, repeat "
                f"the {'command' if on_command_line() else 'call'} it came from; to start again {start_again()}")

    def _read(self, path: Path, columns: list[str]) -> dict[tuple, dict]:
        rows = {}
        for row in read_rows(path, columns):
            key = self.key(row)
            if key in rows:
                raise GearsymError(f"{path}: the point {key} appears twice; pass {overwrite_option()} to start again")
            rows[key] = row
        return rows


    # ------------------------------------------------------------ writing
    def append(self, row: dict, poincare: PoincareRows) -> None:
        """One finished point: its Poincare rows first, then its row (whose presence marks it done); on disk
        at the next :meth:`flush`. The formatting and writing happen on the store's writer thread: the
        native loops release Python's lock, so the ``repr`` of every sample overlaps the next points'
        integration instead of adding to it."""
        self._writer().put((row, poincare))

    def flush(self) -> None:
        """Put every point appended so far on disk (without waiting for it)."""
        self._writer().put(_FLUSH)

    def close(self) -> None:
        """Write what was appended, stop the writer thread and close the files; an error of the writer is
        raised here."""
        thread, self._thread = self._thread, None
        if thread is not None:
            self._queue.put(None)
            thread.join()
        for fd in self._files:
            os.close(fd)
        self._files = []
        failed, self._failed = self._failed, None
        if failed is not None:
            raise failed

    def _writer(self) -> queue.SimpleQueue:
        if self._failed is not None:
            self.close()  # raises it
        if self._thread is None:
            self._queue = queue.SimpleQueue()
            self._thread = threading.Thread(target=self._write_appended, name="gearsym-sweep-writer", daemon=True)
            self._thread.start()
        return self._queue

    def _write_appended(self) -> None:
        strobes, table, rows = [], io.StringIO(), []  # the batch being formatted
        writer = _writer(table)
        try:
            while (item := self._queue.get()) is not None:
                if item is _FLUSH:
                    self._write_batch(strobes, table, rows)
                    strobes, table, rows = [], io.StringIO(), []
                    writer = _writer(table)
                    continue
                row, poincare = item
                strobes.append(poincare.text())
                writer.writerow(self._main_fields(row))
                rows.append(row)
                time.sleep(0)  # let a loop that has finished its native call have the lock back at once
            self._write_batch(strobes, table, rows)
        except BaseException as exc:  # (the disk full, ...): said by the next append, flush or close
            self._failed = self._cut_back(exc)
            while self._queue.get() is not None:  # the rest is dropped; close() waits for its None
                pass

    def _write_batch(self, strobes: list[str], table: io.StringIO, rows: list[dict]) -> None:
        """A batch of points on disk: their Poincare rows, then their rows (whose presence marks them done)."""
        if not rows:
            return
        data = ["".join(strobes).encode(), table.getvalue().encode()]
        for fd, part in zip(self._files, data):
            _write_all(fd, part)
        self._sizes = [size + len(part) for size, part in zip(self._sizes, data)]  # (both written: the batch is)
        self.stored += len(rows)
        if self._appended is not None:
            self._appended.extend(rows)

    def _cut_back(self, exc: BaseException) -> BaseException:
        """Both tables cut back to their last whole batch (a write that failed may have left part of a line, which
        would be read as a sample); the error to raise, as one line if it is the system's (the disk full)."""
        for fd, size in zip(self._files, self._sizes):
            try:
                os.ftruncate(fd, size)
            except OSError:
                pass
        if not isinstance(exc, OSError):
            return exc
        return GearsymError(f"writing {self.path} failed: {exc.strerror or exc}; the {self.stored} points before "
                            "are kept whole: make room (or choose another --out) and run the same command again "
                            "to resume")

    def _lock(self) -> None:
        """One writer per sweep file: a second process on the same --out would interleave rows."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock_fd = take_lock(self.path)

    def release(self) -> None:
        """Close the files, remove the lock file and let another process have the sweep."""
        try:
            self.close()
        finally:
            if self._lock_fd is not None:
                release_lock(self.path, self._lock_fd)
                self._lock_fd = None

    def finish(self, rows: Iterable[dict], strobes: Iterable[PoincareRows]) -> None:
        """All points done: both tables rewritten in plan order (the lock is kept until ``release``), unless
        they were written in it (a fresh sweep whose points finished in order: the rewrite would copy them)."""
        self.close()
        rows = list(rows)
        if self._appended is not None and len(self._appended) == len(rows) and all(
                a is b for a, b in zip(self._appended, rows)):
            return
        self._write_table(self.path, self.columns, map(_fields(self.columns), rows))
        self._write_table(self.strobe_path, self.strobe_columns, (), "".join(r.text() for r in strobes))

    def write_record(self, room: int = 0, **extra) -> None:
        """The record with ``extra`` (status, ...), written atomically; with ``room`` bytes of spaces kept, so that
        a failure can be written over it in place on a full disk (:meth:`write_failure`)."""
        write_atomically(self.meta_path, self._record_text(extra) + " " * room + "\n")

    def write_failure(self, error: BaseException, planned: int) -> None:
        """The record says the sweep failed and why (the error's message), with the points kept whole: written
        atomically, else (the disk full) over the record in place, in its room."""
        self.close_quietly()
        extra = dict(status="failed", error=str(error) or type(error).__name__,
                     points={"planned": planned, "done": self.stored})
        try:
            self.write_record(**extra)
        except OSError:
            if not _write_in_place(self.meta_path, self._record_text(extra)):
                warn(f"{self.meta_path} could not be updated (it still says the sweep is running)")

    def _record_text(self, extra: dict) -> str:
        return json.dumps({"sweep": self.record, **extra}, indent=2)

    def close_quietly(self) -> None:
        """Close the files; an error of the writer (being reported) is not raised again."""
        try:
            self.close()
        except BaseException:
            pass

    def previous_record(self) -> dict:
        """What the last run wrote beside the sweep record (status, points, seconds, ...), or {}."""
        try:
            return {k: v for k, v in json.loads(self.meta_path.read_text()).items() if k != "sweep"}
        except (OSError, json.JSONDecodeError, AttributeError):
            return {}

    @staticmethod
    def _write_table(path: Path, columns: list[str], rows: Iterable[Sequence[str]], text: str = "") -> None:
        """The header, ``rows`` (fields) and ``text`` (lines already formatted)."""
        buffer = io.StringIO()
        writer = _writer(buffer)
        writer.writerow(columns)
        writer.writerows(rows)
        buffer.write(text)
        write_atomically(path, buffer.getvalue())


def _append_only(path: Path) -> int:
    """A descriptor appending to ``path``, never through a symlink (the file was just written in place; one
    switched for a link meanwhile is refused, not written through)."""
    try:
        return os.open(path, os.O_WRONLY | os.O_APPEND | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError as exc:
        raise GearsymError(f"cannot append to {path} ({exc.strerror}); choose another --out") from None


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _write_in_place(path: Path, text: str) -> bool:
    """``text`` over the file ``path`` without taking disk space (padded with spaces to its size; it must fit)."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError:
        return False
    try:
        size = os.fstat(fd).st_size
        data = text.encode()
        if len(data) + 1 > size:
            return False
        os.pwrite(fd, data + b" " * (size - len(data) - 1) + b"\n", 0)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


def _writer(file):
    return csv.writer(file, lineterminator="\n")


def _fields(columns: Sequence[str]):
    """A row's fields in the order of ``columns`` (csv.DictWriter's, without its per-row check of the keys:
    the rows are this module's own)."""
    pick = operator.itemgetter(*columns)
    return (lambda row: pick(row)) if len(columns) > 1 else (lambda row: (pick(row),))


def row_key(row: dict, params) -> tuple:
    """A point's identity in a table row: its direction and swept values (the same as ``Point.key``)."""
    return (row["direction"], tuple(float(row[p]) for p in params))


def read_rows(path: Path, columns: list[str] | None = None) -> list[dict]:
    """The rows of a sweep table; a last row cut off mid-write is left out (a resume redoes it).
    ``columns``: the header it must have (default: whatever it has)."""
    text = path.read_text()
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    if header is None:
        return []
    columns = header if columns is None else columns
    if header != columns:
        raise GearsymError(f"{path}: its columns ({', '.join(header)}) are not this sweep's "
                           f"({', '.join(columns)}); {start_again()}")
    rows = []
    for line, fields in enumerate(reader, start=2):
        if len(fields) != len(columns):
            raise GearsymError(f"{path}, row {line}: {len(fields)} fields, expected {len(columns)}; "
                               f"the file was edited or damaged: fix the row or pass {overwrite_option()}")
        rows.append(dict(zip(columns, fields)))
    return rows


def _short(value) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."
