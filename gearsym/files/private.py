"""Folders and files only this user can write, reached through no symlink someone else made.

gearsym keeps compiled code in a cache, and a library is code: loading one that someone else could write is
running their code. So the cache follows the rules ssh follows for its keys (StrictModes):

* every level gearsym makes is made 0700, whatever the umask;
* the cache's own levels (its root and everything below) must be this user's and writable by nobody else;
* the levels above it must be this user's or root's and writable by nobody else, unless sticky (``/tmp``:
  nobody can rename or remove an entry they do not own);
* "nobody else" counts a group as this user alone when it is the user's private group (named after the user,
  their primary group, no other member: Debian's and Fedora's default, where umask 002 makes folders 0775), as
  Debian's ssh does;
* a symlink on the way is followed only if it is this user's or root's (the path is resolved once, and the
  resolved path used from then on, so a link switched later changes nothing);
* a file is opened with ``O_NOFOLLOW`` (a symlink is never a cache file) and checked on the open
  descriptor: a regular file, this user's, writable by nobody else;
* a file is written through a new file (``O_EXCL``: never through an existing name or link), mode 0600 or
  0700, and a rename.

A breach is a :class:`NotPrivate`, which says what and why in a line; the caller decides whether to refuse
or to go around it.
"""
from __future__ import annotations

import os
import secrets
import stat
from pathlib import Path

from ..errors import GearsymError
from .atomic import write_error

try:
    import grp
    import pwd
except ImportError:  # (not a Unix system: no user or group database to name owners by)
    grp = pwd = None

#: how many symlinks a path may pass through (Linux's limit)
_MAX_LINKS = 40


class NotPrivate(GearsymError):
    """A folder or file that someone else could have written, or that is not this user's."""


#: what to do when the cache (generated code, a compiled library) cannot be written
CACHE_ADVICE = "free some space there, or write elsewhere: $GEARSYM_CACHE for the cache, --out for gearsym compile"


def owner() -> int:
    """The user whose files count as private (the effective user)."""
    return os.geteuid()


def private_folder(path: str | Path, cache: str | Path | None = None) -> Path:
    """``path``, made if missing (each new level 0700) and checked; returned resolved (use that from now on).

    ``cache``: the root of the private tree ``path`` lies in (default: ``path`` itself): it and the levels
    below it must be this user's and writable by nobody else; the levels above it this user's or root's
    and writable by nobody else unless sticky. A level that is a file is a :class:`GearsymError`; a breach
    a :class:`NotPrivate`."""
    path = Path(os.path.abspath(path))
    _make(path)
    real, chain = _resolve(path)
    root = real if cache is None else _resolve(Path(os.path.abspath(cache)))[0]
    uid = owner()
    for level, st in chain:
        if not stat.S_ISDIR(st.st_mode):
            raise GearsymError(f"{level} is not a folder")
        writable = _writable_by_others(st)
        if level == root or root in level.parents:
            if st.st_uid != uid:
                raise NotPrivate(f"{level} belongs to {_user(st.st_uid)}, not to you")
            if writable:
                raise NotPrivate(f"{level} is writable by others (mode {stat.S_IMODE(st.st_mode):04o})")
        else:
            if st.st_uid not in (uid, 0):
                raise NotPrivate(f"{level}, a folder above it, belongs to {_user(st.st_uid)}")
            if writable and not st.st_mode & stat.S_ISVTX:
                raise NotPrivate(f"{level}, a folder above it, is writable by others "
                                 f"(mode {stat.S_IMODE(st.st_mode):04o})")
    return real


def read_private(path: str | Path) -> bytes:
    """The bytes of ``path``, a regular file of this user's that nobody else can write, opened without
    following a symlink (:class:`NotPrivate` otherwise; FileNotFoundError if there is none)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        if os.path.islink(path):
            raise NotPrivate(f"{path} is a symlink") from None
        if isinstance(exc, FileNotFoundError):
            raise
        raise NotPrivate(f"{path} cannot be read ({exc.strerror})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):  # (before fdopen, which refuses a folder with an error of its own)
        os.close(fd)
        raise NotPrivate(f"{path} is not a regular file")
    with os.fdopen(fd, "rb") as f:
        if st.st_uid != owner():
            raise NotPrivate(f"{path} belongs to {_user(st.st_uid)}, not to you")
        if _writable_by_others(st):
            raise NotPrivate(f"{path} is writable by others (mode {stat.S_IMODE(st.st_mode):04o})")
        return f.read()


def write_private(path: str | Path, data: bytes, mode: int = 0o600) -> Path:
    """``data`` written whole to ``path`` with ``mode`` (whatever the umask): through a new file beside it and a
    rename, which replaces whatever is at ``path`` (a symlink included) and follows nothing."""
    path = Path(path)
    while True:
        tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0),
                         mode)
            break
        except FileExistsError:
            continue
        except OSError as exc:
            raise write_error(exc, path, CACHE_ADVICE) from None
    try:
        os.fchmod(fd, mode)  # (the umask may have taken bits away; none is added beyond ``mode``)
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise write_error(exc, path, CACHE_ADVICE) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _make(path: Path) -> None:
    """The missing levels of ``path`` made, each 0700 (a level that exists is left as it is, and checked)."""
    missing = []
    level = path
    while not os.path.lexists(level):
        missing.append(level)
        level = level.parent
    if os.path.exists(level) and not os.path.isdir(level):
        raise GearsymError(f"{level} is not a folder")
    for level in reversed(missing):
        try:
            os.mkdir(level, 0o700)
        except FileExistsError:  # made meanwhile by another process: checked like any other level
            continue
        except NotADirectoryError:
            raise GearsymError(f"{level.parent} is not a folder") from None
        except OSError as exc:
            raise GearsymError(f"cannot make the folder {level} ({exc.strerror})") from None
        os.chmod(level, 0o700)  # (a umask such as 0277 takes bits from mkdir's mode)


def _resolve(path: Path) -> tuple[Path, list[tuple[Path, os.stat_result]]]:
    """``path`` with its symlinks resolved, and every real level on the way with its ``lstat``; a symlink
    that is not this user's or root's is a :class:`NotPrivate` (it was planted)."""
    uid = owner()
    current, chain = Path("/"), [(Path("/"), os.lstat("/"))]
    parts, links = list(path.parts[1:]), 0
    while parts:
        name = parts.pop(0)
        if name in ("", "."):
            continue
        if name == "..":
            if len(chain) > 1:
                chain.pop()
            current = chain[-1][0]
            continue
        step = current / name
        try:
            st = os.lstat(step)
        except FileNotFoundError:
            raise GearsymError(f"{step} does not exist") from None
        except NotADirectoryError:
            raise GearsymError(f"{current} is not a folder") from None
        if stat.S_ISLNK(st.st_mode):
            if st.st_uid not in (uid, 0):
                raise NotPrivate(f"{step} is a symlink made by {_user(st.st_uid)}")
            links += 1
            if links > _MAX_LINKS:
                raise GearsymError(f"{path}: too many levels of symlinks")
            target = Path(os.readlink(step))
            if target.is_absolute():
                current, chain = Path("/"), chain[:1]
                parts = list(target.parts[1:]) + parts
            else:
                parts = list(target.parts) + parts
            continue
        current = step
        chain.append((current, st))
    return current, chain


def _writable_by_others(st: os.stat_result) -> bool:
    """Whether someone other than this user can write the file or folder of ``st`` (by its mode bits)."""
    return bool(st.st_mode & stat.S_IWOTH or (st.st_mode & stat.S_IWGRP and not _private_group(st.st_gid)))


def _private_group(gid: int) -> bool:
    """Whether the group ``gid`` is this user's private group: named after them, their primary group, no other
    member."""
    if pwd is None or grp is None:
        return False
    try:
        user, group = pwd.getpwuid(owner()), grp.getgrgid(gid)
    except KeyError:
        return False
    return gid == user.pw_gid and group.gr_name == user.pw_name and set(group.gr_mem) <= {user.pw_name}


def _user(uid: int) -> str:
    try:
        return f"user {pwd.getpwuid(uid).pw_name} (uid {uid})"
    except (AttributeError, KeyError):  # (no pwd module: not a Unix system)
        return f"uid {uid}"
