"""Tasks of a sweep on this process and processes forked from it: they inherit the loaded model (nothing is
rebuilt or shipped) and share no Python lock; whoever is free takes the next task, and a worker ends with the
sweep's process however it ends."""
from __future__ import annotations

import ctypes
import multiprocessing
import multiprocessing.connection
import os
import queue
import signal
import sys
import threading

import numpy as np

from ..errors import GearsymError, on_command_line
from .grid import Point
from .point_runs import PointRuns

def execute_processes(run: PointRuns, tasks: list[tuple[list[Point], np.ndarray]], jobs: int):
    """``execute_threads`` on ``jobs`` workers: this process and ``jobs - 1`` processes forked from it (they inherit
    the loaded model: nothing is rebuilt or shipped). Whoever is free takes the next task. This process
    computes too, with its warm model, rather than fork one more worker and wait; between its own
    batches it passes on the rows that came back through a queue, so the files, the progress bar and
    Ctrl-C behave as with threads. The threads' shared lock, which serialises the Python around every
    point (analysis, row formatting), is gone."""
    global _FORKED
    if not tasks:
        return
    ctx = multiprocessing.get_context("fork")
    next_task, done = ctx.Value("l", 0), ctx.Queue()
    _FORKED = (run, tasks, os.getpid())  # what the children inherit
    procs = [ctx.Process(target=_process_worker, args=(next_task, done), daemon=True, name=f"gearsym-sweep-{k}")
             for k in range(min(jobs, len(tasks)) - 1)]
    try:
        for proc in procs:
            proc.start()
        _FORKED = None
        pending = sum(len(t) for t, _ in tasks)
        for batch in _own_and_received(run, tasks, next_task, done, procs):
            pending -= len(batch)
            yield batch
            if not pending:
                return
    finally:
        _FORKED = None
        for proc in procs:  # on an error or Ctrl-C: stop at once; unfinished points are redone on resume
            if proc.is_alive():
                proc.terminate()
        for proc in procs:
            proc.join()
        done.close()


def _own_and_received(run: PointRuns, tasks: list, next_task, done, procs: list):
    """This process's batches as it computes them, each followed by the workers' batches that have arrived
    meanwhile; once no task is left, the workers' as they arrive (endlessly: the caller counts)."""
    while (index := _claim(next_task, len(tasks), procs)) is not None:
        for batch in run.task(run.compiled, *tasks[index]):
            yield batch
            yield from _received(done, procs, wait=False)
    while True:
        yield from _received(done, procs, wait=True)


def _received(done, procs: list, wait: bool):
    """The batches the workers have sent (``wait``: a batch, or none after 0.2 s); a worker's error raised here."""
    while True:
        try:
            kind, item = done.get(timeout=0.2) if wait else done.get_nowait()
        except queue.Empty:
            _check_alive(procs)
            return
        if kind == "error":
            raise GearsymError(item)
        yield item
        if wait:
            return


def _claim(next_task, count: int, procs: list = ()) -> int | None:
    """The index of the next task nobody has taken (None: all are taken). The sweep's process (``procs``:
    its workers) does not wait forever for a lock that a worker died holding."""
    lock = next_task.get_lock()
    while not lock.acquire(timeout=1.0):
        _check_alive(procs)
    try:
        index = next_task.value
        next_task.value = index + 1
    finally:
        lock.release()
    return index if index < count else None


def _check_alive(procs: list) -> None:
    """Raise if a worker process has died (one that ran out of tasks ends with 0)."""
    dead = next((p for p in procs if p.exitcode not in (None, 0)), None)
    if dead is not None:
        raise GearsymError(f"a sweep worker process died (exit code {dead.exitcode}); the points finished so far "
                           f"are kept: repeat the {'command' if on_command_line() else 'call'} with "
                           + ("--parallel threads" if on_command_line()
                              else 'execution=Execution(parallel="threads")')
                           + " to resume")


_FORKED = None  # (run, tasks, parent pid) of the sweep being forked, read by _process_worker in the children


def _process_worker(next_task, done) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle: it stops us
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the command line's handler: the parent's terminate() ends us
    run, tasks, parent = _FORKED
    _end_with_parent(parent)
    compiled = run.compiled.clone()  # work arrays of its own (the parent's are its own business)
    while (index := _claim(next_task, len(tasks))) is not None:
        task, state = tasks[index]
        try:
            for batch in run.task(compiled, task, state):
                done.put(("rows", batch))
        except Exception as exc:  # the message is what the parent reports
            done.put(("error", str(exc)))
            return


#: prctl's request for a signal when the parent ends (linux/prctl.h)
_PR_SET_PDEATHSIG = 1


def _end_with_parent(parent: int) -> None:
    """Make this forked worker end when the sweep's process ``parent`` does, however it ends (``kill -9``
    included): an orphan would compute on for nothing, holding the open files.

    Where the kernel can do it (Linux), it does: at once, with nothing asked of the worker, whose thread
    may be deep in a native loop. Elsewhere (macOS, the BSDs) a thread of the worker ends it when the
    sentinel multiprocessing gives a forked child, a pipe whose write end the parent keeps, reads end of
    file. (A sibling forked later inherits that write end too; it ends the same way, first.)"""
    if _kernel_ends_orphans():
        if os.getppid() != parent:  # it died before the request was made
            os._exit(1)
        return
    sentinel = multiprocessing.parent_process().sentinel

    def watch() -> None:
        multiprocessing.connection.wait([sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="gearsym-parent-watch", daemon=True).start()


def _kernel_ends_orphans() -> bool:
    """Ask the kernel to SIGKILL this process when the thread that forked it ends (Linux's
    PR_SET_PDEATHSIG: here the thread running the sweep, which stops its workers before it returns);
    False where it cannot."""
    if not sys.platform.startswith("linux"):
        return False
    return ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
