"""A small JSON record kept private and sealed: what a cache keeps beside a library it loads.

The record is written as a private file (:func:`~gearsym.files.private.write_private`) with a seal: a hash of
its content and of the file's name (which, in a cache, hashes what the record is for). It is read back only if
it is still private, of the format asked and as it was written; a record that is not private or was changed
since is said once in a warning (the caller writes it again), one that is missing, partial or of another format
is passed over in silence. Only JSON is read.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..errors import warn
from .private import NotPrivate, read_private, write_private


def read_sealed(path: Path, format: int, what: str = "record") -> dict | None:
    """The record at ``path`` of this ``format``, or None (missing, partial, corrupt, of another format; or not
    private, or changed since it was written: said in a warning that names it as ``what``)."""
    record = unsealed(path, format)
    if isinstance(record, str):
        distrust(path, record, what)
        return None
    return record


def unsealed(path: Path, format: int) -> dict | str | None:
    """The record at ``path`` of this ``format``; None if there is none (missing, partial, corrupt, of another
    format); or, for one not to be trusted (not private, changed since it was written), why not: for a caller
    that reads records before it knows which it uses, and says why (:func:`distrust`) of the one it uses."""
    try:
        data = json.loads(read_private(path))
    except NotPrivate as exc:
        return str(exc)
    except (OSError, ValueError):
        return None
    if not (isinstance(data, dict) and data.get("format") == format):
        return None
    if data.pop("seal", None) != _seal(path, data):
        return "its content is not what gearsym wrote (edited?)"
    return data


def write_sealed(path: Path, data: dict, format: int) -> None:
    """``data`` with its ``format`` and seal, written privately at ``path``."""
    # (keys in their order: the parameters' order is that of the parameter vector)
    data = {"format": format, **data}
    write_private(path, (json.dumps({**data, "seal": _seal(path, data)}, indent=1) + "\n").encode())


def _seal(path: Path, data: dict) -> str:
    """The hash of a record's content and file name."""
    return hashlib.sha256(f"{path.name}\0{json.dumps(data, sort_keys=True)}".encode()).hexdigest()


def distrust(path: Path, why: str, what: str = "record") -> None:
    """Say once per process that the record at ``path`` is not used, and why (the caller writes it again)."""
    if path not in _DISTRUSTED:  # (a record is read more than once in a run: said once)
        _DISTRUSTED.add(path)
        warn(f"the {what} {path} is not used: {why}; gearsym writes it again")


_DISTRUSTED: set[Path] = set()
