"""The lock of a file that one process writes at a time (a sweep's ``FILE.csv``, a basin continuation's): an flock
on ``FILE.csv.lock``.

The kernel drops an flock when the last descriptor of it closes: with its holder's death, so a lock file whose
holder is gone is simply taken over. Forked children inherit the descriptor and with it the lock (sweep workers
that outlived a killed parent kept it), so every fork closes it in the child. The file says who holds it, for
the message a second writer gets, and is removed when the writer ends.
"""
from __future__ import annotations

import fcntl
import json
import os
import socket
import stat
import time
from pathlib import Path

from .atomic import write_error
from ..errors import GearsymError

_HELD_LOCKS: set[int] = set()  # descriptors of the locks this process holds


def _close_inherited_locks() -> None:
    for fd in _HELD_LOCKS:  # only this copy: the parent's lock stays (no LOCK_UN, which would drop it)
        os.close(fd)
    _HELD_LOCKS.clear()


os.register_at_fork(after_in_child=_close_inherited_locks)


def lock_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock")


def take_lock(path: Path) -> int:
    """Lock the sweep ``path`` against other writers (GearsymError naming the holder if one is alive);
    returns the lock file's descriptor, for :func:`release_lock`."""
    lock = lock_path(path)
    while True:
        fd = _open_lock(lock)
        if fd is None:
            continue  # (removed between our two tries: try again)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = _read_holder(fd)
            os.close(fd)
            raise GearsymError(_busy(path, holder)) from None
        if _is_at(fd, lock):
            break
        os.close(fd)  # its holder removed the file as we locked it: lock the one now at the path
    _HELD_LOCKS.add(fd)
    holder = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(holder) + "\n").encode(), 0)
    except OSError as exc:  # (the disk full: the lock holds, but the sweep cannot start)
        release_lock(path, fd)
        raise write_error(exc, lock) from None
    return fd


def _open_lock(lock: Path) -> int | None:
    """The lock file's descriptor: made new (``O_EXCL``), else the one there opened; never through a symlink (one
    planted at the lock's name would have the holder's line written into the file it points at). None if the
    file went away between the two tries."""
    flags = os.O_RDWR | os.O_CLOEXEC | os.O_NOFOLLOW | os.O_NONBLOCK
    try:
        fd = os.open(lock, flags | os.O_CREAT | os.O_EXCL, 0o666)
    except FileExistsError:
        try:
            fd = os.open(lock, flags)
        except FileNotFoundError:
            return None
        except OSError as exc:
            if os.path.islink(lock):
                raise GearsymError(f"{lock}, the sweep's lock file, is a symlink (to {os.readlink(lock)}); gearsym "
                                   "never writes through one: remove it, or choose another --out") from None
            raise GearsymError(f"cannot open the sweep's lock file {lock} ({exc.strerror}); remove it, or choose "
                               "another --out") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise GearsymError(f"{lock}, the sweep's lock file, is not a regular file; remove it, or choose another --out")
    return fd


def release_lock(path: Path, fd: int) -> None:
    """Remove the lock file, while still holding it (whoever opened it meanwhile sees it gone), and unlock."""
    lock = lock_path(path)
    if _is_at(fd, lock):  # (not a file someone made after deleting ours)
        lock.unlink(missing_ok=True)
    _HELD_LOCKS.discard(fd)
    os.close(fd)


def _is_at(fd: int, path: Path) -> bool:
    try:
        return os.path.samestat(os.fstat(fd), os.stat(path))
    except FileNotFoundError:
        return False


def _read_holder(fd: int) -> dict:
    try:
        holder = json.loads(os.pread(fd, 4096, 0))
        return holder if isinstance(holder, dict) and isinstance(holder.get("pid"), int) else {}
    except (OSError, ValueError):  # written by an older gearsym (empty), or not yet
        return {}


def _busy(path: Path, holder: dict) -> str:
    """Who holds the lock of ``path``, as the one line a second writer gets."""
    lock = lock_path(path)
    find = f"`fuser -v {lock}` or `lsof {lock}` names it"
    if not holder:
        return f"another gearsym process is writing {path}; wait for it or stop it ({find}), or choose another --out"
    pid, host = holder["pid"], holder.get("host")
    here = host in (None, socket.gethostname())
    if here and not process_alive(pid):
        return (f"{path} is locked by a process left behind by gearsym process {pid}, which has ended (a sweep "
                f"worker of an older gearsym?): stop it ({find}), or choose another --out")
    where = "" if here else f" on {host}"
    return (f"{path} is being written by gearsym process {pid}{where} (started {holder.get('started', '?')}); "
            f"wait for it or stop it{'' if where else f' (kill {pid})'}, or choose another --out")


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` of this machine still runs (another user's counts as running)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's
        pass
    return True
