"""Writing a file so that no reader (a resumed sweep, a concurrent worker, the tests) ever sees half of it."""
from __future__ import annotations

import errno
import os
import secrets
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import GearsymError

#: errors of a file system that has no room left (the disk full, a quota reached)
NO_ROOM = (errno.ENOSPC, errno.EDQUOT)


class WriteError(GearsymError, OSError):
    """A file that could not be written (the disk full, a read-only file system, ...): a one-line error that
    names it and says that nothing of it was written; an :class:`OSError` still (``errno``, ``strerror``,
    ``filename``), for the callers that keep what they finished when a write fails. ``advice``: what to do, if
    not to free space or write elsewhere (a cache: point $GEARSYM_CACHE elsewhere)."""

    advice = ""

    def __str__(self) -> str:
        advice = self.advice or ("free some space there or write elsewhere" if self.errno in NO_ROOM
                                 else "write elsewhere")
        return f"writing {self.filename} failed: {self.strerror}; it is left as it was ({advice})"


def write_error(exc: OSError, path, advice: str = "") -> WriteError:
    """``exc``, raised while writing ``path``, as a :class:`WriteError` (with ``advice``, if given)."""
    if isinstance(exc, WriteError) and not advice:
        return exc
    error = WriteError(exc.errno, exc.strerror or str(exc), str(path))
    error.advice = advice
    return error


@contextmanager
def writing(folder, advice: str = "") -> Iterator[None]:
    """Files written into ``folder`` in the block (by gearsym or a tool it calls): an OSError there is a
    :class:`WriteError` naming the folder; so is any other failure while its disk has no room left (CasADi's code
    generator fails, or writes half a file, without a word on a full disk)."""
    try:
        yield
    except WriteError:
        raise
    except OSError as exc:
        raise write_error(exc, folder, advice) from None
    except Exception:
        if no_room(folder):
            raise write_error(OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)), folder, advice) from None
        raise


def no_room(folder) -> bool:
    """Whether the file system of ``folder`` has no space left for an ordinary user (a tool that fails without
    saying why, such as CasADi's code generator, is then out of disk)."""
    try:
        st = os.statvfs(folder)
    except OSError:
        return False
    return st.f_bavail == 0 or st.f_favail == 0


def write_atomically(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` (text or bytes) to ``path`` through a temporary file in the same folder and a rename;
    the folder is made if missing. Concurrent writers of the same bytes are harmless: the last rename wins.

    Permissions are those any other tool's output gets: a new file 0666 less the umask, a replaced file
    keeps its mode (as ``>`` or ``write_text`` keep it). A symlink at ``path`` is replaced, never written through.

    A failure (the disk full, ...) leaves ``path`` as it was and raises :class:`WriteError`."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = _create_temporary(path)
    except OSError as exc:
        raise write_error(exc, path) from None
    try:
        with os.fdopen(fd, "wb" if isinstance(data, bytes) else "w", encoding=None if isinstance(data, bytes)
                       else "utf-8") as f:
            f.write(data)
        try:
            kept = os.lstat(path)
        except FileNotFoundError:
            kept = None
        if kept is not None and stat.S_ISREG(kept.st_mode):  # (a symlink's target's mode is not this file's)
            os.chmod(tmp, stat.S_IMODE(kept.st_mode))
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise write_error(exc, path) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _create_temporary(path: Path) -> tuple[int, Path]:
    """A new, empty file beside ``path``. Not ``tempfile.mkstemp``: its mode is 0600 whatever the umask.
    Asked for 0666, the kernel applies the umask itself; Python could only read the umask by setting it
    (``os.umask``), which races with other threads creating files."""
    while True:
        tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
        try:
            return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666), tmp
        except FileExistsError:
            continue
