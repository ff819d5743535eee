"""What a request needs in memory, from its sizes, against what this machine has.

Checked where a size enters (the options, a verb's own counts), before the memory is taken: a size that cannot fit
is a one-line error with the number asked and the number that fits, not a ``MemoryError`` (or a machine swapping)
after minutes of work.
"""
from __future__ import annotations

import os

from .errors import GearsymError

#: requests below this size are not checked (they fit anywhere gearsym runs, and reading the memory costs a call)
SMALL = 1 << 26


def available() -> int | None:
    """Bytes of memory available now: ``MemAvailable`` (Linux), else the physical memory; None if unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def readable(count: float) -> str:
    """A size in bytes as people read it: 512 B, 3.2 MiB, 14.9 GiB."""
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if count >= size:
            return f"{count / size:.3g} {unit}"
    return f"{count:.0f} B"


def check_fits(count: int, per_item: float, *, asked: str, item: str, what: str, base: float = 0.0) -> None:
    """Refuse ``count`` items of ``per_item`` bytes each (and ``base`` bytes besides) if they do not fit in the
    memory available. ``asked`` is the request as the caller wrote it (``--periods 1000000000``,
    ``periods=1000000000``), ``item`` what is counted (period, initial state), ``what`` what the bytes hold."""
    needed = base + count * per_item
    if needed < SMALL:
        return
    free = available()
    if free is None or needed <= free:
        return
    allowed = max(0, int((free - base) // per_item)) if per_item > 0 else 0
    raise GearsymError(f"{asked} needs {readable(needed)} of memory ({what}: {readable(per_item)} per {item}), more "
                       f"than the {readable(free)} available: at most {allowed} {item}s fit")
