"""Running a sweep: the Lyapunov spectrum and amplitudes at every point of a grid.

The model is compiled once; every point only changes the parameter vector (:mod:`.point_runs`: the
low-level loops of :func:`~gearsym.analysis.lyapunov.lyapunov_spectrum`, summarised in batches). Tasks (single points,
or whole continuation lines) run where :class:`~.workers.Workers` says: this process and processes forked
from it (:mod:`.processes`), threads (:mod:`.threads`), or a Dask cluster (:mod:`.distributed`). Workers hand
finished points to the main process, which alone writes the files (:mod:`.store`) and moves the progress bar.
"""
from __future__ import annotations

import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..checks import check_fits, run_bytes_per_period, whole_number
from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError, UnknownParameterError, option
from ..options import Execution, Integration
from ..version import __version__
from .distributed import execute_on_dask
from .grid import axes_from, Axis, INDEPENDENT, plan, Point, points
from .point_runs import PointRuns
from .processes import execute_processes
from .result import SweepResult
from .store import SweepStore, row_key, start_again
from .threads import execute_threads, guided
from .workers import Workers

#: stroboscopic samples kept per point for bifurcation diagrams
POINCARE_SAMPLES = 50


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep: the finished points are on disk; the same command resumes."""

    def __init__(self, done: int, planned: int, path: Path | None):
        self.done, self.planned, self.path = done, planned, path
        where = f" in {path}; run the same command again to resume" if path else ""
        super().__init__(f"interrupted: kept {done} of {planned} points{where}")


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
    execution: Execution | None = None,
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
    ``"stale"``: starting again only files another sweep or model wrote). ``execution``: where the points run
    (its jobs, parallel, scheduler), a progress bar, and with ``lanes`` independent points L at a time in the lanes
    (:mod:`gearsym.codegen.lane_runs`: each lane with its point's tables and constants), each giving the scalar
    loop's numbers (to the bit without fused multiply-adds; with them, to rounding); off by default, so that a
    sweep's files stay those of the scalar loops wherever it runs. ``on_point(row)`` is called in the main thread
    after each point is stored.
    """
    options = model.run_options(options)
    execution = execution or Execution()
    workers, lanes, progress = Workers.of(execution), execution.with_lanes(False), execution.verbose
    plan = _SweepPlan.make(model, axes, options, mode, direction, y0, poincare, values)
    at_once = 1 if workers.scheduler is not None else min(workers.count, len(plan.points))
    if at_once > 1:  # each worker holds the records of a point
        check_fits(options.periods, at_once * run_bytes_per_period(model.dimension, len(model.observed)),
                   asked=option("periods", options.periods), item="period",
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
        run = PointRuns(model, plan.base, plan.names, plan.start, options, plan.poincare, plan.columns,
                        plan.strobe_columns, lanes)
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


def poincare_samples_of(poincare: int, options: Integration) -> int:
    """The Poincare samples a sweep's point keeps: ``poincare``, checked against the periods ``options`` measure
    (the default: as many as they measure, up to POINCARE_SAMPLES)."""
    poincare = whole_number(poincare, "poincare samples")
    if poincare > options.measured and poincare != POINCARE_SAMPLES:  # (the default fits what a run measures)
        raise GearsymError(f"{option('poincare', poincare)}: a point has one Poincare sample per measured "
                           f"period, {options.measured} here ({option('periods', options.periods)} minus "
                           f"{option('discard', options.discard)}): give at most {options.measured}, or "
                           "more periods")
    return min(poincare, options.measured)


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
        poincare = poincare_samples_of(poincare, options)
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


def _execute_on(workers: Workers, run: PointRuns, todo: list, ran: dict):
    """The rows of ``todo`` as they finish, from wherever ``workers`` says the points run."""
    if workers.scheduler is not None:
        return execute_on_dask(run, todo, workers.scheduler, workers.count, ran)  # (0 jobs: one per core)
    todo = guided(todo, min(workers.count, len(todo)))
    if workers.mode == "processes" and workers.count > 1 and len(todo) > 1:
        return execute_processes(run, todo, workers.count)
    return execute_threads(run, todo, workers.count)


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


def _progress(total: int, done: int, name: str, enabled: bool):
    """A tqdm bar on stderr: points done, rate and time left (updated less often off a terminal)."""
    from tqdm import tqdm

    tty = sys.stderr.isatty()
    return tqdm(total=total, initial=done, desc=f"{name} sweep", unit="pt", disable=not enabled,
                mininterval=0.2 if tty else 10.0, file=sys.stderr, dynamic_ncols=True)
