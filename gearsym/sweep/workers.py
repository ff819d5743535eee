"""Where a sweep's points run: :class:`Workers` (processes, threads or a Dask cluster, as the call's
:class:`~gearsym.options.Execution` says) and the cores this process may use."""
from __future__ import annotations

import multiprocessing
import os
from dataclasses import dataclass

from ..checks import whole_number
from ..errors import GearsymError, option, warn
from ..options import PARALLEL, Execution
from .distributed import check_scheduler


def cores() -> int:
    """The cores this process may run on (its affinity where the OS says it, else every core)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:
        return os.cpu_count() or 1


@dataclass(frozen=True)
class Workers:
    """Where a sweep's points run: ``jobs`` workers (0: one per core) on this machine, as ``"processes"``
    (this one and ``jobs - 1`` forked from it: nothing is rebuilt; no lock shared between them, so the Python
    around each point does not serialise them), ``"threads"``, or ``"auto"`` (processes where the OS can fork:
    Linux, macOS); or, with ``scheduler``, on Dask (the ``distributed`` extra): ``"local"`` starts a cluster of
    ``jobs`` single-threaded worker processes on this machine for this sweep, ``"tcp://HOST:PORT"`` uses the
    cluster of that scheduler, a ``distributed.Client`` its cluster. The files are the same, byte for byte, however
    the points run (on Dask as long as the workers run the client's library: see
    :mod:`gearsym.codegen.portable`)."""

    jobs: int = 0
    parallel: str = "auto"
    scheduler: object = None

    def __post_init__(self):
        jobs = whole_number(self.jobs, "jobs")
        if self.parallel not in PARALLEL:
            raise GearsymError(f"parallel={self.parallel!r}: choose one of {', '.join(PARALLEL)}")
        if self.scheduler is not None:
            check_scheduler(self.scheduler, self.jobs)  # no Dask, a bad address: said before any work
        here = cores()
        if jobs > here and self.scheduler in (None, "local"):  # (a cluster elsewhere has cores of its own)
            warn(f"{option('jobs', jobs)}: this machine has {here} core{'s' if here > 1 else ''}; running "
                 f"{here} worker{'s' if here > 1 else ''} (more would only share them)")
            object.__setattr__(self, "jobs", here)

    @classmethod
    def of(cls, execution: Execution) -> "Workers":
        """Where the points of a sweep run with ``execution``: its jobs, parallel and scheduler (checked here,
        before any work: no Dask, a bad address, more jobs than cores)."""
        return cls(execution.jobs, execution.parallel, execution.scheduler)

    @property
    def count(self) -> int:
        return self.jobs or cores()

    @property
    def mode(self) -> str:
        """"processes" or "threads" (on this machine)."""
        if self.parallel != "auto":
            return self.parallel
        return "processes" if "fork" in multiprocessing.get_all_start_methods() else "threads"
