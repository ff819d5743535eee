"""Small argument checks shared by the engine and the analyses (a command line's checks of its own flags are
the command line's: :mod:`gearsym.cli.arguments.integration`), and what a request needs in memory against what
this machine has.

A size is checked where it enters (the options, a verb's own counts), before the memory is taken: a size that
cannot fit is a one-line error with the number asked and the number that fits, not a ``MemoryError`` (or a machine
swapping) after minutes of work.
"""
from __future__ import annotations

import math
import operator
import os

import numpy as np

from .errors import GearsymError, suggest

#: at most this many RK4 steps per forcing period: 200 steps for each natural period 5000 times shorter than the
#: forcing's. The compiled time tables hold every step: building them takes some KiB and tenths of a millisecond a
#: step (one_stage at 10^6 steps: 3 GB and 100 s), so 10^8 steps ran out of memory after minutes
MAX_STEPS_PER_PERIOD = 1_000_000
#: the least memory compiling the time tables takes per step (one_stage: 3 KiB)
TABLE_BYTES_PER_STEP = 2048


def run_bytes_per_period(dimension: int, observed: int) -> int:
    """The memory a run with tangent vectors keeps per forcing period: the state after it and the log stretch of
    each tangent vector, each observed coordinate's minimum and maximum, and the stretches per unit time its
    summary makes (doubles)."""
    return 8 * (4 * dimension + 2 * observed)


#: the least memory a run takes per forcing period (one state, observed)
RUN_BYTES_PER_PERIOD = run_bytes_per_period(1, 1)


def whole_number(value, what: str, minimum: int = 0) -> int:
    """``value`` as an int (any integer type: int, numpy.int64, ...) of at least ``minimum``, or a clear error."""
    if isinstance(value, bool):  # an int to Python, never meant as a count
        raise GearsymError(f"{what} must be a whole number, got {value!r}")
    try:
        count = operator.index(value)
    except TypeError:
        raise GearsymError(f"{what} must be a whole number, got {value!r}") from None
    if count < minimum:
        raise GearsymError(f"{what} must be at least {minimum}, got {count}")
    return count


def json_safe(x):
    """JSON-safe: numpy scalars to Python, NaN and infinities to None, tuples to lists."""
    if isinstance(x, dict):
        return {str(k): json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return [json_safe(v) for v in x.tolist()]
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer, int)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.str_):
        return str(x)
    return x


def chosen_coordinate(name: str | None, coordinates, plot) -> str | None:
    """``--coordinate name`` checked: it chooses what ``--plot`` draws, so it needs ``plot``, and it must be one of
    ``coordinates``. None stays None (the plot's default, the first coordinate)."""
    if name is None:
        return None
    if not plot:
        raise GearsymError(f"--coordinate {name} chooses what --plot draws; add --plot FILE.png")
    if name not in coordinates:
        raise GearsymError(f"--coordinate {name}: no such coordinate.{suggest(name, coordinates)} "
                           f"The coordinates are {', '.join(coordinates)}")
    return name


def sign_violation(number: float, allow_zero: bool) -> str | None:
    """What is wrong with the sign of a physical quantity ('must be positive', ...), or None."""
    if number < 0 or (number == 0 and not allow_zero):
        return "must not be negative" if allow_zero else "must be positive"
    return None


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
