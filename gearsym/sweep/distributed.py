"""Sweeps on a Dask cluster: ``run_sweep(..., scheduler="local" | "tcp://HOST:PORT" | Client)``.

The optional extra ``pip install "gearsym[distributed]"``. The client (the
process that called :func:`~gearsym.sweep.run_sweep`) still plans the sweep,
checks every parameter value, writes the files and moves the progress bar;
only the points are computed on the workers.

What travels, once per worker (``scatter(broadcast=True)``): the model as a
:class:`~gearsym.codegen.portable.ShippedModel` (library bytes, C source,
system; about 0.4 MB) and the sweep's shared settings (a ``PointRuns`` without its
compiled model). Each worker process loads the model once (from the bytes, or
rebuilt from the C on another kind of machine: see
:mod:`gearsym.codegen.portable`) and keeps it by code hash; each worker thread
has its own clone.

Tasks: independent points in chunks (at least ``TASKS_PER_THREAD`` per
worker thread, at most ``POINTS_PER_TASK`` points each); a continuation line
in consecutive segments of at most ``POINTS_PER_TASK`` points, each a task that
starts from the state the previous one ended in (read back from its last row,
exactly as a resume does), so finished points reach the files while the line
goes on. Neither changes a bit of the results: every point gets exactly the
start state and the model it gets on one thread.
"""
from __future__ import annotations

import logging
import math
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .. import codegen
from ..codegen import CompiledModel
from ..errors import GearsymError
from .grid import INDEPENDENT, Point

if TYPE_CHECKING:  # (the type only: the code generator and SymPy load when a model is shipped, on Dask alone)
    from ..codegen.portable import ShippedModel

#: the optional dependency, as the error says it
EXTRA = 'pip install "gearsym[distributed]"'
#: seconds to reach a scheduler (an unreachable one fails with its address instead of hanging)
CONNECT_TIMEOUT = 5.0
#: seconds to wait for a first worker when the scheduler has none
WORKER_TIMEOUT = 60.0
#: independent points: at least this many tasks per worker thread (a slow worker does not hold back the end) ...
TASKS_PER_THREAD = 6
#: ... and at most this many points per task, so the files and the bar follow the work and Ctrl-C loses little
#: (a point takes 5-50 ms, a task costs the scheduler about 1 ms)
POINTS_PER_TASK = 20


def require_distributed():
    """The ``distributed`` module, or a GearsymError saying which extra to install."""
    try:
        import distributed
    except ImportError as exc:
        raise GearsymError(f"running a sweep on Dask (--dask, --scheduler) needs the distributed extra: {EXTRA} "
                           f"({exc})") from None
    return distributed


def check_scheduler(scheduler, jobs: int) -> None:
    """Refuse a bad ``scheduler`` before any work: no Dask installed, not an address, --jobs with a remote cluster."""
    distributed = require_distributed()
    if scheduler == "local":
        return
    client = isinstance(scheduler, distributed.Client)
    if not client and (not isinstance(scheduler, str) or ":" not in scheduler):
        raise GearsymError(f"scheduler {scheduler!r}: expected a Dask scheduler address (tcp://HOST:PORT), "
                           '"local" or a distributed.Client')
    if jobs:
        where = "the client's cluster" if client else f"the cluster of {scheduler}"
        raise GearsymError(f"--jobs sets threads, or the worker processes of a --dask cluster; {where} has its "
                           "own workers: drop --jobs")


@contextmanager
def connect(scheduler, workers: int):
    """A Client for ``scheduler``: a Client as given; "local": a LocalCluster of ``workers`` single-threaded
    processes, closed on leaving; an address: a connection, closed on leaving."""
    distributed = require_distributed()
    if isinstance(scheduler, distributed.Client):
        yield scheduler
        return
    if scheduler == "local":
        with _workers_ignore_ctrl_c():
            cluster = distributed.LocalCluster(  # no dashboard; its HTTP server on any free port, not 8787
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.ERROR)
        with cluster, distributed.Client(cluster) as client:
            yield client
        return
    try:
        client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as exc:
        raise GearsymError(f"could not reach a Dask scheduler at {scheduler} within {CONNECT_TIMEOUT:g} s ({exc}). "
                           f"Start one there with `dask scheduler` and workers with `dask worker {scheduler}`") from None
    with client:
        yield client


@contextmanager
def _workers_ignore_ctrl_c():
    """Worker processes started meanwhile ignore SIGINT (an ignored signal stays ignored through exec).
    Ctrl-C in a terminal reaches the whole process group; only the client should act on it (cancel the
    tasks, keep the finished points, close the cluster), not every worker with a traceback of its own."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def execute_dask(run, tasks: list[tuple[list[Point], np.ndarray]], client,
                 info: dict | None = None) -> Iterator[list[tuple[dict, list]]]:
    """Yield batches of (row, Poincare rows) as points finish on the cluster of ``client``, like
    ``threads.execute_threads``;
    ``info`` is filled with the scheduler's address and the workers and threads it has.

    On an error or Ctrl-C (the generator closed) every outstanding task is cancelled; the points already
    yielded are on disk, the others are computed again on resume.
    """
    distributed = require_distributed()
    if not tasks:
        return
    if not client.nthreads():
        try:
            client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
        except (OSError, TimeoutError):
            raise GearsymError(f"the Dask scheduler at {client.scheduler.address} has no workers (waited "
                               f"{WORKER_TIMEOUT:g} s); start some with `dask worker {client.scheduler.address}`"
                               ) from None
    threads = sum(client.nthreads().values())
    if info is not None:
        info.setdefault("scheduler", client.scheduler.address)
        info.update(workers=len(client.nthreads()), threads=threads)
    outstanding = set()  # a finished task is let go once its rows are yielded: the cluster frees them
    try:
        model, shared = client.scatter([codegen.ship(run.compiled), run], broadcast=True, hash=False)
        outstanding |= {model, shared}
        for points, start in _pieces(tasks, threads):
            if points[0].direction == INDEPENDENT:
                outstanding.add(client.submit(sweep_points, model, shared, points, start, pure=False))
                continue
            previous = start
            for segment in _split(points, math.ceil(len(points) / POINTS_PER_TASK)):
                previous = client.submit(sweep_points, model, shared, segment, previous, pure=False)
                outstanding.add(previous)
            del previous
        finished = distributed.as_completed(outstanding - {model, shared})
        for future in finished:
            rows = future.result()  # raises the task's error here
            outstanding.discard(future)
            del future
            yield from rows
    finally:
        if outstanding:
            try:
                client.cancel(list(outstanding))
            except (OSError, RuntimeError, TimeoutError):  # the scheduler is gone: nothing left to cancel, and
                pass  # the error that brought us here is the one to report


def _pieces(tasks, threads: int) -> list[tuple[list[Point], np.ndarray]]:
    """Independent points regrouped into chunks; continuation lines as they are."""
    if tasks[0][0][0].direction != INDEPENDENT:
        return tasks
    start = tasks[0][1]
    points = [p for task, _ in tasks for p in task]  # every independent point starts from ``start``
    parts = max(TASKS_PER_THREAD * max(threads, 1), math.ceil(len(points) / POINTS_PER_TASK))
    return [(chunk, start) for chunk in _split(points, parts)]


def _split(points: list[Point], parts: int) -> list[list[Point]]:
    """``points`` in at most ``parts`` consecutive pieces of nearly equal length."""
    parts = max(1, min(parts, len(points)))
    size, extra = divmod(len(points), parts)
    bounds = [i * size + min(i, extra) for i in range(parts + 1)]
    return [points[a:b] for a, b in zip(bounds, bounds[1:])]


# ---------------------------------------------------------------------------- on the workers
_MODELS: dict[tuple[str, str], CompiledModel] = {}
_MODELS_LOCK = threading.Lock()
_THREAD = threading.local()


def sweep_points(shipped: ShippedModel, run, points: list[Point], previous) -> list[list[tuple[dict, list]]]:
    """A task on a worker: the rows of ``points`` in batches, started from ``previous`` (a state, or the
    batches of the segment before: its last row's final state, read back exactly as a resume reads it)."""
    compiled = worker_model(shipped)
    state = previous if isinstance(previous, np.ndarray) else run.final_state(previous[-1][-1][0], compiled.state_names)
    return list(run.task(compiled, points, state))


def worker_model(shipped: ShippedModel) -> CompiledModel:
    """This thread's clone of the shipped model: loaded once per process, cloned once per thread."""
    key = (shipped.hash, shipped.backend)
    clones = _THREAD.__dict__.setdefault("models", {})
    clone = clones.get(key)
    if clone is None:
        with _MODELS_LOCK:
            if key not in _MODELS:
                _MODELS[key] = codegen.load_shipped(shipped)
            base = _MODELS[key]
        clone = clones[key] = base.clone()
    if clone.system is not shipped.system:  # the same code, another sweep's parameter defaults
        clone = clones[key] = replace(clone, system=shipped.system)
    return clone


def execute_on_dask(run, tasks: list[tuple[list[Point], np.ndarray]], scheduler, workers: int, ran: dict):
    """``threads.execute_threads`` on a Dask cluster, connected (or started) only if there is something to compute;
    ``ran`` is filled with where it ran."""
    if not tasks:
        return

    if scheduler == "local":
        ran["scheduler"] = "local"  # not the cluster's passing port
    with connect(scheduler, workers) as client:
        yield from execute_dask(run, tasks, client, ran)
