"""Writing a file so that no reader (a resumed sweep, a concurrent worker, the tests) ever sees half of it."""
from __future__ import annotations

import os
import secrets
import stat
from pathlib import Path


def write_atomically(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` (text or bytes) to ``path`` through a temporary file in the same folder and a rename;
    the folder is made if missing. Concurrent writers of the same bytes are harmless: the last rename wins.

    Permissions are those any other tool's output gets: a new file 0666 less the umask, a replaced file
    keeps its mode (as ``>`` or ``write_text`` keep it)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = _create_temporary(path)
    try:
        with os.fdopen(fd, "wb" if isinstance(data, bytes) else "w") as f:
            f.write(data)
        try:
            os.chmod(tmp, stat.S_IMODE(path.stat().st_mode))
        except FileNotFoundError:
            pass
        os.replace(tmp, path)
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
