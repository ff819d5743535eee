"""Small answers kept in the user's cache, so that a later process need not ask again (what a unit text means,
read without importing pint: :mod:`gearsym.units`).

An answer is a sealed private record (:mod:`.sealed`) in ``<cache>/<kind>/``, under a name that hashes its question
and what the answer depends on (the answering library's version and data): another version is another name,
never a stale answer. A process reads the answers of a kind once, all together (:func:`recall_all`), and looks
its questions up in what it read. They are read only from a cache that is private
(:func:`~.private.private_folder`: a cache someone else could write, or reached through their symlink, is not read:
the question is asked again), only if the record is as it was written (a record changed since, or not private, is
said once in a warning and written again) and only if it answers the question it is kept under (a record not to be
trusted is removed: its question is asked again). Keeping one is best effort: a cache that cannot be written leaves
the answer unkept, in silence (the next process asks again).
"""
from __future__ import annotations

import hashlib
from pathlib import Path

from ..errors import GearsymError
from .cache import configured_cache
from .private import private_folder
from .sealed import read_sealed, write_sealed

#: bump when what a kept answer holds changes
MEMO_FORMAT = 1


def recall_all(kind: str, depends: str, what: str) -> dict[str, dict]:
    """Every answer kept for a question of ``kind`` given ``depends`` (question -> answer), read once for all the
    questions a process may ask: a record not to be trusted is said once in a warning naming it as ``what`` and
    removed (its question is asked again, and its answer kept anew); one kept for another ``depends`` (another
    version of the answering library) is left for it."""
    folder = _folder(kind)
    if folder is None:
        return {}
    answers = {}
    for path in sorted(folder.glob("*.json")):
        record = read_sealed(path, MEMO_FORMAT, what)
        if record is None:
            _forget(path)
            continue
        question, answer = record.get("question"), record.get("answer")
        if (record.get("depends") == depends and isinstance(question, str) and isinstance(answer, dict)
                and path.name == _name(question, depends)):
            answers[question] = answer
    return answers


def keep(kind: str, question: str, depends: str, answer: dict) -> None:
    """``answer`` kept for ``question`` (given ``depends``), if the cache is private and can be written."""
    folder = _folder(kind)
    if folder is None:
        return
    try:
        write_sealed(folder / _name(question, depends),
                     {"question": question, "depends": depends, "answer": answer}, MEMO_FORMAT)
    except (GearsymError, OSError):  # (a full or read-only cache: the answer is asked again next time)
        pass


def _forget(path: Path) -> None:
    """A record that cannot be read as one removed, if it can be (best effort: it is read again, and refused)."""
    try:
        path.unlink()
    except OSError:
        pass


def _folder(kind: str) -> Path | None:
    """The private folder ``<cache>/<kind>`` (made if missing), or None if the cache is not private or cannot be
    a folder."""
    try:
        root = private_folder(configured_cache())  # (checked before a level is made in it)
        return private_folder(root / kind, cache=root)
    except (GearsymError, OSError):
        return None


def _name(question: str, depends: str) -> str:
    return hashlib.sha256(f"{depends}\0{question}".encode()).hexdigest()[:40] + ".json"
