"""How a sweep's point becomes a row: the Lyapunov spectrum, amplitudes and Poincare samples of its runs,
summarised in batches (what every point of one sweep shares is one :class:`PointRuns`)."""
from __future__ import annotations

import functools
import math
import time

import numpy as np

from ..analysis.divergence import counted_coordinates, run_failure, within_bound
from ..analysis.lyapunov import summarise_runs
from ..analysis.regime import DIVERGED
from ..codegen import CompiledModel, TangentRuns
from ..codegen.lane_runs import LaneRunner
from ..errors import GearsymError
from .grid import INDEPENDENT, Point
from .store import number, overwrite_option, PoincareRows

#: a task's points are summarised and handed on in batches of at most this many points, this much time
#: (what a Ctrl-C or kill can cost) and this many bytes of per-period records
POINTS_PER_BATCH, BATCH_SECONDS, BATCH_BYTES = 32, 0.2, 1 << 24


class PointRuns:
    """What every point of one sweep shares, and how a point becomes a row."""

    def __init__(self, compiled, base, names, start, options, poincare, columns, strobe_columns, lanes=False):
        self.compiled, self.base, self.names, self.start = compiled, base, names, start
        self.options, self.poincare = options, poincare
        self.columns, self.strobe_columns = columns, strobe_columns
        self.lanes = lanes

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
        if self.lanes and len(points) > 1 and points[0].direction == INDEPENDENT and compiled.backend == "compiled":
            yield from self.lane_task(compiled, points, state)
            return
        periods, n = self.options.periods, compiled.dimension
        size = min(len(points), batch_size(n, len(compiled.observed), periods))  # (a task of one point: one)
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

    def lane_task(self, compiled: CompiledModel, points: list[Point], state: np.ndarray):
        """:meth:`task` of independent points, L at a time in the lanes, each lane with its point's tables and
        constants."""
        periods, n = self.options.periods, compiled.dimension
        size = min(len(points), batch_size(n, len(compiled.observed), periods))
        runs = TangentRuns(n, len(compiled.observed), periods, max(size, 1))
        runner = LaneRunner(compiled, 0, periods)
        base = compiled.parameter_vector(self.base)
        swept = [compiled.parameter_names.index(name) for name in self.names]
        batch, block = [], []  # block: (point, p, inputs) of the points of the next call

        def call():
            records = runner.orbits(np.tile(state, (len(block), 1)), [inputs for _, _, inputs in block], tangent=True)
            for i, (point, p, inputs) in enumerate(block):
                k = len(batch)
                runs.strobe[k], runs.log_stretch[k] = records.strobe[i], records.log_stretch[i]
                runs.low[k], runs.high[k] = records.low[i], records.high[i]
                batch.append((point, p, inputs.period, state))
            block.clear()

        for point in points:
            p = base.copy()
            p[swept] = point.values
            try:
                inputs = compiled.prepare(p)
            except GearsymError as exc:
                if block:
                    call()
                if batch:
                    yield from self.checked_rows(compiled, runs, batch)
                raise self.failed(point, exc) from None
            if block and (len(block) == runner.width or len(batch) + len(block) == runs.size):
                call()
            if len(batch) == runs.size:
                yield from self.checked_rows(compiled, runs, batch)
                batch = []
            block.append((point, p, inputs))
        if block:
            call()
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


def batch_size(n: int, observed: int, periods: int) -> int:
    """Points per batch: ``POINTS_PER_BATCH``, fewer when their records would pass ``BATCH_BYTES``."""
    return max(1, min(POINTS_PER_BATCH, BATCH_BYTES // (8 * periods * (2 * n + 2 * observed))))
