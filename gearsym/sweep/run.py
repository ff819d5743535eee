"""Running a sweep: the Lyapunov spectrum and amplitudes at every point of a grid.

The model is compiled once; every point only changes the parameter vector
(the low-level loops of :func:`~gearsym.analysis.lyapunov_spectrum`, summarised in batches). Tasks
(single points, or whole continuation lines) run on ``jobs`` workers: this
process and ``jobs - 1`` processes forked from it where the OS can fork (they
inherit the loaded model, so nothing is rebuilt, and they do not share Python's
lock), else threads (the native loops release the GIL), each with work arrays of
its own.
Workers hand finished points to the main process, which alone writes the files
and moves the progress bar. With ``scheduler`` the tasks run on a Dask cluster
instead (:mod:`gearsym.sweep.distributed`); the main process still writes
everything.
"""
from __future__ import annotations

import ctypes
import functools
import math
import multiprocessing
import multiprocessing.connection
import os
import queue
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.divergence import counted_coordinates, run_failure, within_bound
from ..analysis.lyapunov import summarise_runs
from ..analysis.regime import DIVERGED
from .. import caller
from ..checks import run_bytes_per_period, whole_number
from ..codegen import CompiledModel, TangentRuns, engine_verb
from ..errors import GearsymError, UnknownParameterError, warn
from ..memory import check_fits
from ..options import Integration
from ..version import __version__
from .distributed import check_scheduler, connect, execute_dask
from .grid import axes_from, Axis, INDEPENDENT, plan, Point, points
from .result import SweepResult
from .store import PoincareRows, SweepStore, number, overwrite_option, row_key, start_again

#: stroboscopic samples kept per point for bifurcation diagrams
POINCARE_SAMPLES = 50
#: a task's points are summarised and handed on in batches of at most this many points, this much time
#: (what a Ctrl-C or kill can cost) and this many bytes of per-period records
POINTS_PER_BATCH, BATCH_SECONDS, BATCH_BYTES = 32, 0.2, 1 << 24
#: ways to use more than one core of this machine (``run_sweep(parallel=...)``)
PARALLEL = ("auto", "processes", "threads")


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep: the finished points are on disk; the same command resumes."""

    def __init__(self, done: int, planned: int, path: Path | None):
        self.done, self.planned, self.path = done, planned, path
        where = f" in {path}; run the same command again to resume" if path else ""
        super().__init__(f"interrupted: kept {done} of {planned} points{where}")


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
            warn(f"{caller.option('jobs', jobs)}: this machine has {here} core{'s' if here > 1 else ''}; running "
                 f"{here} worker{'s' if here > 1 else ''} (more would only share them)")
            object.__setattr__(self, "jobs", here)

    @property
    def count(self) -> int:
        return self.jobs or cores()

    @property
    def mode(self) -> str:
        """"processes" or "threads" (on this machine)."""
        if self.parallel != "auto":
            return self.parallel
        return "processes" if "fork" in multiprocessing.get_all_start_methods() else "threads"


@engine_verb
def run_sweep(
    model: CompiledModel,
    axes: Mapping[str, Sequence[float]] | Sequence[Axis | str],
    *,
    options: Integration | None = None,
    mode: str = "continuation",
    direction: str = "up",
    y0=None,
    out: str | Path | None = None,
    overwrite: bool | str = False,
    poincare: int = POINCARE_SAMPLES,
    workers: Workers = Workers(),
    progress: bool = True,
    on_point: Callable[[dict], None] | None = None,
    **values: float,
) -> SweepResult:
    """Sweep ``model`` over ``axes`` (``{"omega": values}`` or ``["omega=0.1:2.0:0.01", ...]``).

    ``model`` is a :class:`CompiledModel` (or a system, compiled first with ``options``); ``values`` fix
    other parameters for the whole sweep; ``options`` (an :class:`~gearsym.options.Integration`) give the
    periods per point and the scheme. ``mode="continuation"`` hands each point's final state to the next
    along the first axis (the paper's procedure), ``"independent"`` starts every point from ``y0``
    (default: the model's declared initial state). ``out``: write ``out`` (CSV), its ``.json`` record and
    ``.poincare.csv`` as points finish, resuming if they exist (``overwrite=True``: starting again;
    ``"stale"``: starting again only files another sweep or model wrote). ``workers``: where the points run
    (:class:`Workers`). ``on_point(row)`` is called in the main thread after each point is stored.
    """
    options = model.run_options(options)
    plan = _SweepPlan.make(model, axes, options, mode, direction, y0, poincare, values)
    at_once = 1 if workers.scheduler is not None else min(workers.count, len(plan.points))
    if at_once > 1:  # each worker holds the records of a point
        check_fits(options.periods, at_once * run_bytes_per_period(model.dimension, len(model.observed)),
                   asked=caller.option("periods", options.periods), item="period",
                   what=f"{at_once} workers' states, stretches and extremes of each period")
    store = SweepStore(out, plan.columns, plan.strobe_columns, [*plan.names, "direction"], plan.record) \
        if out else None
    opened = False
    try:  # the files stay locked against a second writer until this sweep returns or fails
        done, strobes = store.open(overwrite) if store else ({}, {})
        opened = store is not None
        unknown = set(done) - {p.key for p in plan.points}
        if unknown:
            raise GearsymError(f"{out}: holds points this sweep does not plan, e.g. {sorted(unknown)[0]}; "
                               + start_again())
        run = _Run(model, plan.base, plan.names, plan.start, options, plan.poincare, plan.columns,
                   plan.strobe_columns)
        todo = [t for t in (run.remaining(task, done) for task in plan.tasks) if t[0]]
        t_start, already, ran = time.perf_counter(), len(done), {}  # ran: where the points ran (Dask only)
        finished = _execute_on(workers, run, todo, ran)
        _store_as_finished(finished, store, plan, done, strobes, progress, on_point, ran)
        rows = [done[p.key] for p in plan.points]
        poincare = [strobes[p.key] for p in plan.points if p.key in strobes]
        result = SweepResult.from_rows(model.name, plan.axes, mode, plan.columns, rows, poincare, plan.record,
                                       path=store.path if store else None, strobe_columns=plan.strobe_columns)
        if store:
            _finish_files(store, result, rows, poincare, len(done) - already, time.perf_counter() - t_start, ran)
        return result
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # a point that failed, the disk full, ...: the record says so, not "running"
        error = _one_line(exc, store)
        if opened:
            store.write_failure(error, len(plan.points))
        if error is exc:
            raise
        raise error from None
    finally:
        if store:
            store.release()


def _one_line(exc: BaseException, store: SweepStore | None) -> BaseException:
    """A failure to write the sweep's files (the disk full: an OSError) as a one-line error; others as they are."""
    if store is None or not isinstance(exc, OSError):
        return exc
    where = f" ({exc.filename})" if exc.filename else ""
    return GearsymError(f"writing the sweep {store.path} failed: {exc.strerror or exc}{where}; the points finished "
                        "before are kept whole: make room (or choose another --out) and run the same command again "
                        "to resume")


@dataclass(frozen=True)
class _SweepPlan:
    """Everything a sweep decides before its first point: the checked grid, the start, columns and record."""

    axes: tuple[Axis, ...]
    names: tuple[str, ...]
    tasks: list
    points: list[Point]
    base: dict[str, float]
    start: np.ndarray
    poincare: int
    columns: list[str]
    strobe_columns: list[str]
    record: dict

    @classmethod
    def make(cls, compiled: CompiledModel, axes, options: Integration, mode: str, direction: str, y0, poincare: int,
             values: dict) -> "_SweepPlan":
        poincare = min(whole_number(poincare, "poincare samples"), options.measured)
        if mode == INDEPENDENT and direction != "up":
            raise GearsymError(f"--direction {direction} applies to a continuation; independent points have no "
                               "direction")
        axes = tuple(axes_from(axes))
        for axis in axes:
            if axis.name not in compiled.parameter_names:
                raise UnknownParameterError(axis.name, compiled.parameter_names, f"{compiled.name}: --param")
            if axis.name in values:
                raise GearsymError(f"{axis.name} is both swept (--param) and fixed (--set); drop one")
            for v in axis.values:
                compiled.parameter_vector(values, **{axis.name: v})  # every value checked before any work
        base = dict(zip(compiled.parameter_names, map(float, compiled.parameter_vector(values))))
        start = compiled.initial_state(y0)
        tasks = plan(axes, mode, direction)
        names = tuple(a.name for a in axes)
        n = compiled.dimension
        columns = [*names, "direction", *(f"A_{c}" for c in compiled.observed),
                   *(f"lambda_{i}" for i in range(1, n + 1)), *(f"stderr_{i}" for i in range(1, n + 1)),
                   "regime", *(f"final_{s}" for s in compiled.state_names)]
        strobe_columns = [*names, "direction", "sample", *compiled.state_names]
        record = {
            "model": compiled.name, "model_hash": compiled.hash, "backend": compiled.backend,
            "settings": {k: str(v) for k, v in values.items()}, "parameters": base,
            "axes": {a.name: list(a.values) for a in axes}, "mode": mode, "direction": direction,
            "periods": options.periods, "discard": options.discard, "steps_per_period": compiled.steps_per_period,
            "initial_state": dict(zip(compiled.state_names, map(float, start))), "poincare_samples": poincare,
        }
        if compiled.options.locate_crossings:  # (only then: records of plain sweeps keep their keys)
            record["locate_crossings"] = True
        return cls(axes, names, tasks, list(points(tasks)), base, start, poincare, columns, strobe_columns, record)


def _execute_on(workers: Workers, run: "_Run", todo: list, ran: dict):
    """The rows of ``todo`` as they finish, from wherever ``workers`` says the points run."""
    if workers.scheduler is not None:
        return _execute_dask(run, todo, workers.scheduler, workers.jobs, ran)
    todo = _guided(todo, min(workers.count, len(todo)))
    if workers.mode == "processes" and workers.count > 1 and len(todo) > 1:
        return _execute_processes(run, todo, workers.count)
    return _execute(run, todo, workers.count)


def _guided(tasks: list[tuple[list[Point], np.ndarray]], workers: int) -> list[tuple[list[Point], np.ndarray]]:
    """Independent points (a task each, all from the same start) regrouped into tasks that shrink as the
    sweep goes: each takes half of what is left per worker, down to single points. A task's points are
    summarised as one batch, so few large tasks cost little around each point, and the small ones at the
    end keep the workers finishing together. Continuation lines are left as they are."""
    if not tasks or tasks[0][0][0].direction != INDEPENDENT:
        return tasks
    points, start, out = [p for task, _ in tasks for p in task], tasks[0][1], []
    while points:
        size = max(1, -(-len(points) // (2 * workers))) if workers > 1 else len(points)
        out.append((points[:size], start))
        points = points[size:]
    return out


def _store_as_finished(finished, store: SweepStore | None, plan: _SweepPlan, done: dict, strobes: dict,
                       progress: bool, on_point, ran: dict) -> None:
    """Write each finished point (a point counts once it is on disk) and move the bar; on Ctrl-C keep what
    is done, mark the record interrupted and say how to resume."""
    bar = _progress(len(plan.points), len(done), plan.record["model"], progress)
    try:
        for batch in finished:
            for row, poincare in batch:
                if store:
                    store.append(row, poincare)
                key = row_key(row, plan.names)
                done[key], strobes[key] = row, poincare
                if on_point:
                    on_point(row)
            if store:
                store.flush()
            bar.update(len(batch))
    except KeyboardInterrupt:
        finished.close()  # now, not when the traceback lets go of it: workers stop, cluster tasks are cancelled
        bar.close()
        if store:
            store.close()
            store.write_record(status="interrupted", points={"planned": len(plan.points), "done": store.stored},
                               **({"dask": ran} if ran else {}))
        raise SweepInterrupted(store.stored if store else len(done), len(plan.points),
                               store.path if store else None) from None
    except BaseException:
        finished.close()
        bar.close()
        raise
    bar.close()


def _finish_files(store: SweepStore, result: SweepResult, rows, poincare, computed: int, seconds: float,
                  ran: dict) -> None:
    """Both tables rewritten in the plan's order, and the record completed with what the sweep found."""
    timing = {"seconds": round(seconds, 3), **({"dask": ran} if ran else {})}
    if not computed:  # a rerun of a finished sweep: keep the time it took, and where
        previous = store.previous_record()
        timing = {k: previous[k] for k in ("seconds", "dask") if k in previous} or timing
    store.finish(rows, poincare)
    store.write_record(status="complete",
                       points={"planned": len(result), "done": len(rows), "computed": computed},
                       **timing, gearsym=__version__, **result.findings())


class _Run:
    """What every point of one sweep shares, and how a point becomes a row."""

    def __init__(self, compiled, base, names, start, options, poincare, columns, strobe_columns):
        self.compiled, self.base, self.names, self.start = compiled, base, names, start
        self.options, self.poincare = options, poincare
        self.columns, self.strobe_columns = columns, strobe_columns

    def __getstate__(self) -> dict:  # sent to Dask workers without the compiled model: each loads its own
        return {**self.__dict__, "compiled": None}

    @staticmethod
    def final_state(row: dict, state_names) -> np.ndarray:
        """The state a point ended in, read back from its row (``repr`` floats: the same bits)."""
        return np.array([float(row[f"final_{s}"]) for s in state_names])

    def remaining(self, task: list[Point], done: dict) -> tuple[list[Point], np.ndarray]:
        """The points of a task still to run, and the state to start from (a continuation's last done point)."""
        finished = [p.key in done for p in task]
        count = sum(finished)
        if not all(finished[:count]) or any(finished[count:]):
            raise GearsymError("the sweep file holds points of a continuation line out of order (not its first "
                               f"points), so it cannot be resumed: pass {overwrite_option()} to start again")
        state = self.start
        if task[0].direction != INDEPENDENT:  # from the last point that did not diverge
            for point in reversed(task[:count]):
                if done[point.key]["regime"] != DIVERGED:
                    state = self.final_state(done[point.key], self.compiled.state_names)
                    break
        return task[count:], state

    def task(self, compiled: CompiledModel, points: list[Point], state: np.ndarray):
        """Yield the (row, Poincare rows) of ``points`` in batches; a continuation hands each final state on.

        The loops of each point write into a batch's shared records, which are summarised at once
        (:func:`~gearsym.analysis.lyapunov.summarise_runs`) when the batch is full or has taken
        ``BATCH_SECONDS``: the Python around a point is a few array operations shared by the batch, not its
        own. A point that fails ends the task after the points before it are yielded; a point that diverged is
        a row like any other ("diverged"), and a continuation goes on from the last state that stayed within
        the bound of :mod:`gearsym.analysis.divergence`."""
        periods, n = self.options.periods, compiled.dimension
        size = min(len(points), _batch_size(n, len(compiled.observed), periods))  # (a task of one point: one)
        runs = TangentRuns(n, len(compiled.observed), periods, max(size, 1))
        base = compiled.parameter_vector(self.base)
        swept = [compiled.parameter_names.index(name) for name in self.names]
        batch, started = [], time.perf_counter()
        counted = functools.partial(counted_coordinates, compiled)
        for point in points:
            p = base.copy()
            p[swept] = point.values
            try:
                inputs = compiled.prepare(p)
                compiled.tangent_run_into(runs, len(batch), state, inputs, check_finite=False)
            except GearsymError as exc:
                if batch:
                    yield from self.checked_rows(compiled, runs, batch)
                raise self.failed(point, exc) from None
            batch.append((point, p, inputs.period, state))
            final = runs.strobe[len(batch) - 1, -1]
            if point.direction != INDEPENDENT and within_bound(final, state, compiled.state_names, counted):
                state = final.copy()
            if len(batch) == runs.size or time.perf_counter() - started >= BATCH_SECONDS:
                yield from self.checked_rows(compiled, runs, batch)
                batch, started = [], time.perf_counter()
        if batch:
            yield from self.checked_rows(compiled, runs, batch)

    def checked_rows(self, compiled: CompiledModel, runs: TangentRuns, batch: list):
        """Yield the rows of ``batch`` (a point that diverged is a row); a run that failed instead (non-finite
        tangent vectors, or a step too large for RK4: :func:`~gearsym.analysis.divergence.run_failure`) ends
        the task after the rows of the points before it (the points after it, run from its state, are
        dropped)."""
        rows, failed = self.rows(compiled, runs, batch)
        if failed is None:
            yield rows
            return
        i, exc = failed
        if i:
            yield rows[:i]
        raise self.failed(batch[i][0], exc) from None

    def failed(self, point: Point, exc: GearsymError) -> GearsymError:
        """The error of a point, saying where it is."""
        where = ", ".join(f"{n_}={v:g}" for n_, v in zip(self.names, point.values))
        return GearsymError(f"at {where} ({point.direction}): {exc}")

    def rows(self, compiled: CompiledModel, runs: TangentRuns, batch: list) -> tuple[list, tuple | None]:
        """The table rows and Poincare rows of the runs of ``batch`` ((point, parameters, period, start) each),
        and (index, error) of the first that failed (None: none did)."""
        points, p, period, starts = zip(*batch)
        summary = summarise_runs(compiled, runs, np.array(p), np.array(period), self.options.discard)
        failed = None
        if not math.isfinite(float(runs.log_stretch[:len(batch)].sum())) or any(summary.divergences):
            failed = next(((i, e) for i, e in ((i, run_failure(compiled, p[i], period[i], starts[i], runs.strobe[i],
                                                                runs.log_stretch[i], summary.divergences[i]))
                                               for i in range(len(batch))) if e is not None), None)
        count, n = len(batch), compiled.dimension
        numbers = np.hstack([summary.amplitude, summary.exponents, summary.stderr]).tolist()
        finals = runs.strobe[:count, -1].tolist()
        strobes = runs.strobe[:count, self.options.periods - self.poincare:].copy()
        fields, final_fields = self.columns[len(self.names) + 1:len(self.columns) - n - 1], self.columns[-n:]
        out = []
        for point, values, regime, final, strobe in zip(points, numbers, summary.regimes, finals, strobes):
            where = (*map(number, point.values), point.direction)
            row = dict(zip(self.names, where))
            row["direction"] = point.direction
            row.update(zip(fields, map(repr, values)))
            row["regime"] = regime
            row.update(zip(final_fields, map(repr, final)))
            out.append((row, PoincareRows(where, strobe)))
        return out, failed


def _batch_size(n: int, observed: int, periods: int) -> int:
    """Points per batch: ``POINTS_PER_BATCH``, fewer when their records would pass ``BATCH_BYTES``."""
    return max(1, min(POINTS_PER_BATCH, BATCH_BYTES // (8 * periods * (2 * n + 2 * observed))))


def _execute(run: _Run, tasks: list[tuple[list[Point], np.ndarray]], jobs: int):
    """Yield batches of (row, Poincare rows) as points finish; tasks run on up to ``jobs`` threads."""
    if not tasks:
        return
    if jobs == 1 or len(tasks) == 1:  # no threads: simplest, and Ctrl-C stops at once
        for task, state in tasks:
            yield from run.task(run.compiled, task, state)
        return
    results: queue.Queue = queue.Queue()
    stop = threading.Event()
    local = threading.local()

    def work(task, state):
        compiled = getattr(local, "compiled", None)
        if compiled is None:
            compiled = local.compiled = run.compiled.clone()
        if stop.is_set():
            return
        for batch in run.task(compiled, task, state):
            results.put(batch)
            if stop.is_set():  # checked before the next batch is computed
                return

    pool = ThreadPoolExecutor(max_workers=min(jobs, len(tasks)), thread_name_prefix="gearsym-sweep")
    futures = [pool.submit(work, task, state) for task, state in tasks]
    try:
        pending = sum(len(t) for t, _ in tasks)
        while pending:
            try:
                item = results.get(timeout=0.2)
            except queue.Empty:
                failed = next((f for f in futures if f.done() and f.exception()), None)
                if failed:
                    raise failed.exception()
                continue
            pending -= len(item)
            yield item
    finally:
        stop.set()  # on an error or Ctrl-C: threads stop after their current batch
        pool.shutdown(wait=True, cancel_futures=True)  # points finished meanwhile are redone on resume


def _execute_processes(run: _Run, tasks: list[tuple[list[Point], np.ndarray]], jobs: int):
    """``_execute`` on ``jobs`` workers: this process and ``jobs - 1`` processes forked from it (they inherit
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


def _own_and_received(run: _Run, tasks: list, next_task, done, procs: list):
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
                           f"are kept: repeat the {'command' if caller.on_command_line() else 'call'} with "
                           + ("--parallel threads" if caller.on_command_line() else 'workers=Workers(parallel="threads")')
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


def _execute_dask(run: _Run, tasks: list[tuple[list[Point], np.ndarray]], scheduler, workers: int, ran: dict):
    """``_execute`` on a Dask cluster, connected (or started) only if there is something to compute;
    ``ran`` is filled with where it ran."""
    if not tasks:
        return

    if scheduler == "local":
        ran["scheduler"] = "local"  # not the cluster's passing port
    with connect(scheduler, workers) as client:
        yield from execute_dask(run, tasks, client, ran)


def _progress(total: int, done: int, name: str, enabled: bool):
    """A tqdm bar on stderr: points done, rate and time left (updated less often off a terminal)."""
    from tqdm import tqdm

    tty = sys.stderr.isatty()
    return tqdm(total=total, initial=done, desc=f"{name} sweep", unit="pt", disable=not enabled,
                mininterval=0.2 if tty else 10.0, file=sys.stderr, dynamic_ncols=True)
