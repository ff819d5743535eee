"""What stands at a path that should be a regular file (a folder, a named pipe, a device), said for a message:
a FIFO or a device given where a file is read is named as what it is, not as a folder or a missing file."""
from __future__ import annotations

import stat
from pathlib import Path


def what_is_at(path: Path, wanted: str) -> str:
    """What stands at ``path`` that is not a regular file, as the rest of a sentence ('is a folder; ...')."""
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return "does not exist (a broken symlink)" if path.is_symlink() else "does not exist"
    except OSError as exc:
        return f"cannot be read ({exc.strerror or exc})"
    kind = ("a folder" if stat.S_ISDIR(mode) else "a named pipe (FIFO)" if stat.S_ISFIFO(mode)
            else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode)
            else "not a regular file")
    return f"is {kind}, not a file; {wanted}"
