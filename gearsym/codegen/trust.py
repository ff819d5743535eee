"""What a file of compiled code in the cache holds, recorded when gearsym writes it and checked before use.

A library (or the C it is compiled from) is loaded only if its bytes are those gearsym recorded when it
wrote them: a record beside it, ``<file>.<sha256 prefix>.json``, holding the SHA-256 of the bytes, their
size and what they are (``describes``: the model, its code hash, states and parameters, so that a summary
pointing at a library can be checked against it). Both are read as private files
(:func:`~gearsym.files.private.read_private`: this user's, writable by nobody else, no symlink). A library
cut short (which crashed the process with SIGBUS when loaded), overwritten with garbage, or with one
constant changed, no longer matches: it is compiled again, and a warning says so in one line.

Each version of a file has its own record (the hash is in the record's name), written before the file is
renamed into place: two processes compiling the same model at once each leave a library whose record is
there, whichever rename comes last.
"""
from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import field
from pathlib import Path

from ..errors import warn
from ..records import record_class
from ..files.private import NotPrivate, read_private, write_private

#: bump when what a record holds changes
RECORD_FORMAT = 1


def record_path(path: Path, digest: str) -> Path:
    return path.with_name(f"{path.name}.{digest[:16]}.json")


def record(path: Path, data: bytes, describes: Mapping[str, object] | None = None) -> None:
    """Record ``data`` as the content ``path`` is about to get (call before renaming it into place)."""
    digest = hashlib.sha256(data).hexdigest()
    text = json.dumps({"format": RECORD_FORMAT, "sha256": digest, "size": len(data),
                       "describes": dict(describes or {})}, indent=1, sort_keys=True) + "\n"
    write_private(record_path(path, digest), text.encode())


def trusted(path: Path, describes: Mapping[str, object] | None = None) -> bytes | None:
    """The bytes of ``path`` if they are what gearsym recorded (and, with ``describes``, the record says the file
    is that: every key given has that value); else None, with a one-line warning when a file is there that does
    not match (changed, damaged, not private), and silently when there is none or it has no record."""
    verdict = check(path)
    why = verdict.why if verdict.data is None else differences(verdict.describes, describes)
    if why is not None:
        warn(f"{path} is not used: {why}; gearsym makes it again")
        return None
    return verdict.data


@record_class
class Verdict:
    """What :func:`check` found: the bytes if they are what gearsym recorded (else None, and why not: None if
    there is no file, or it has no record), and what the record says the file is."""

    data: bytes | None
    why: str | None = None
    describes: Mapping[str, object] = field(default_factory=dict)


def check(path: Path) -> Verdict:
    """Whether ``path`` holds what gearsym recorded for it (read privately, its hash and size compared)."""
    path = Path(path)
    try:
        data = read_private(path)
    except FileNotFoundError:
        return Verdict(None)
    except NotPrivate as exc:
        return Verdict(None, str(exc))
    digest = hashlib.sha256(data).hexdigest()
    try:
        kept = json.loads(read_private(record_path(path, digest)))
    except FileNotFoundError:
        if any(path.parent.glob(f"{_glob_escape(path.name)}.*.json")):
            return Verdict(None, "its content is not what gearsym wrote (cut short, damaged or changed)")
        return Verdict(None)  # (no record at all: written by an older gearsym, or the record was removed)
    except (NotPrivate, ValueError) as exc:
        return Verdict(None, f"its record: {exc}")
    if not isinstance(kept, dict) or kept.get("sha256") != digest or kept.get("size") != len(data):
        return Verdict(None, "its record does not match it")
    said = kept.get("describes")
    return Verdict(data, None, said if isinstance(said, dict) else {})


def differences(said: Mapping[str, object], describes: Mapping[str, object] | None) -> str | None:
    """Why a file whose record says ``said`` is not ``describes`` (None: it is; keys not given are not compared)."""
    wrong = [k for k, v in (describes or {}).items() if said.get(k) != _plain(v)]
    return f"it is not what it was taken for (its {', '.join(wrong)} differ)" if wrong else None


def _plain(value):
    """``value`` as JSON reads it back (tuples are lists)."""
    return json.loads(json.dumps(value))


def _glob_escape(name: str) -> str:
    return "".join(f"[{c}]" if c in "*?[" else c for c in name)
