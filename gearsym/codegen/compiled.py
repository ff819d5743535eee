"""A model's loops, compiled (or evaluated in-process), behind one small object.

A :class:`CompiledModel` is built by :func:`gearsym.codegen.build.compile_model`
from a :class:`~gearsym.system.FirstOrderSystem` and an
:class:`~gearsym.options.Integration`; the analyses in :mod:`gearsym.analysis`
take one, so that a sweep builds it once and only changes the parameter vector
(the low-level call), or build it from a system themselves (the high-level call).
"""
from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..records import record_class
from ..errors import GearsymError, ModelError, option, warn
from ..checks import check_fits, run_bytes_per_period, whole_number
from ..options import Integration
from .loops import LoopOptions
from .native import NativeFunction, load_native
from .periodicity import NotPeriodicError

if TYPE_CHECKING:  # (CasADi is imported where the in-process backend calls it: a cached run never does)
    import casadi as ca

    from ..system import FirstOrderSystem


@record_class
class RunInputs:
    """What the loops need for one parameter point, computed once: tables of time and constants."""

    p: np.ndarray
    table: np.ndarray  # column-major (3 * table entries, steps per period)
    constants: np.ndarray
    period: float
    t0: float
    model_hash: str  # the code these inputs were prepared for (the loops read them by raw pointer)

    @cached_property
    def table_dm(self) -> ca.DM:  # for the in-process backend
        import casadi as ca

        return ca.DM(self.table)

    @cached_property
    def constants_dm(self) -> ca.DM:
        import casadi as ca

        return ca.DM(self.constants)

    @cached_property
    def addresses(self) -> tuple[int, int]:
        """Where the table and the constants are, for the native calls."""
        return self.table.ctypes.data, self.constants.ctypes.data


@record_class
class TangentRun:
    """Raw output of ``periods`` forcing periods with tangent vectors."""

    strobe: np.ndarray  # n x periods: the state after each period
    log_stretch: np.ndarray  # n x periods: log of each Gram-Schmidt norm
    low: np.ndarray  # observed x periods: minimum over each period's steps
    high: np.ndarray
    Q: np.ndarray  # final orthonormal tangent vectors (columns)


class TangentRuns:
    """Room for the per-period records of up to ``size`` tangent runs, to be summarised together (a sweep's
    batch of points): each record is stacked period after period, as the loops write it, so ``slot(i)`` is
    the ``out`` of :meth:`CompiledModel.tangent_run` for run i, and ``strobe[:k]`` etc. are runs 0..k-1 as
    (runs, periods, rows) arrays. The addresses the native loops need are taken once, here
    (:meth:`CompiledModel.tangent_run_into`)."""

    def __init__(self, dimension: int, observed: int, periods: int, size: int):
        self.strobe, self.log_stretch = (np.empty((size, periods, dimension)) for _ in range(2))
        self.low, self.high = (np.empty((size, periods, observed)) for _ in range(2))
        self.size, self.periods = size, periods
        self.start, self.eye = np.empty(dimension), np.asfortranarray(np.eye(dimension))
        self.Q = [np.empty((dimension, dimension), order="F") for _ in range(2)]
        records = (self.strobe, self.log_stretch, self.low, self.high)
        self._bases = [a.ctypes.data for a in records]
        self.strides = [a.shape[2] * 8 for a in records]  # bytes from one period's column to the next
        self._slot_bytes = [a.shape[1] * a.shape[2] * 8 for a in records]
        self.start_address, self.Q_addresses = self.start.ctypes.data, [q.ctypes.data for q in self.Q]
        self.calls: dict[int, list] = {}  # slot -> its native calls, planned by the model in ``planned_by``
        self.planned_by = None

    def slot(self, i: int) -> tuple[np.ndarray, ...]:
        return tuple(a[i].T for a in (self.strobe, self.log_stretch, self.low, self.high))

    def addresses(self, i: int) -> list[int]:
        """Where run i's strobe, log stretches, lows and highs start."""
        return [base + i * size for base, size in zip(self._bases, self._slot_bytes)]


@record_class
class Shot:
    """Where a shot from y0 lands, with the exact Jacobian of the landing point by y0."""

    state: np.ndarray  # (n,)
    M: np.ndarray  # n x n: d state / d y0 (the monodromy matrix over whole periods), not re-orthonormalised
    low: np.ndarray  # (observed,): the minimum over every step of the shot
    high: np.ndarray


class _ShotBuffers:
    """Two states and two tangent matrices a shot writes into in turn, and the extremes of a call."""

    def __init__(self, n: int, m: int):
        self.eye = np.asfortranarray(np.eye(n))
        self.y = [np.empty(n), np.empty(n)]
        self.M = [np.empty((n, n), order="F"), np.empty((n, n), order="F")]
        self.low, self.high = np.empty(m), np.empty(m)
        self.y_at = [a.ctypes.data for a in self.y]
        self.M_at = [a.ctypes.data for a in self.M]
        self.low_at, self.high_at = self.low.ctypes.data, self.high.ctypes.data


@record_class(frozen=False)
class CompiledModel:
    """One model's generated functions, for any parameter values."""

    system: FirstOrderSystem
    options: LoopOptions
    hash: str
    functions: Mapping[str, ca.Function]
    backend: str  # "compiled" | "in-process"
    library: Path | None = None
    timings: dict[str, float] = field(default_factory=dict)
    native: Mapping[str, NativeFunction] | None = None  # the same functions, called without CasADi
    integration: Integration = field(default_factory=Integration)  # the options it was compiled with
    timed: frozenset[str] = frozenset()  # the parameters in the tables of time or the period (the generator's)
    table_texts: tuple[str, ...] = ()  # the tables of time, as text (for the error of one that does not repeat)
    fastest: float = 0.0  # the rate of the system's fastest linearised mode (what the step was chosen from)

    def run_options(self, options: Integration | None) -> Integration:
        """The options a run on this model uses: its own, or ``options`` if they need the same code; a run longer
        than the memory can hold is refused here, before it starts."""
        options = self.integration if options is None else self._same_code(options)
        check_fits(options.periods, run_bytes_per_period(self.dimension, len(self.observed)),
                   asked=option("periods", options.periods), item="period",
                   what=f"{self.name}'s state, stretches and extremes of each period")
        return options

    def _same_code(self, options: Integration) -> Integration:
        if not isinstance(options, Integration):
            raise GearsymError(f"options must be a gearsym.Integration, got {type(options).__name__}")
        mine = self.integration
        if options.integrator == "auto" and options.steps_per_period <= mine.steps_per_period:
            options = replace(options, integrator=mine.integrator, steps_per_period=mine.steps_per_period,
                              choice=mine.choice)  # (the model's choice for at least the steps asked)
        same = (options.steps_per_period == mine.steps_per_period
                and options.locate_crossings == mine.locate_crossings
                and options.integrator == mine.integrator
                and options.backend in ("auto", self.backend))
        if not same:
            raise GearsymError(
                f"{self.name}: this compiled model integrates with {mine.steps_per_period} {mine.method_name} steps per "
                f"period, {'crossings located' if mine.locate_crossings else 'plain'}, {self.backend}; the options "
                f"ask for {options.steps_per_period} {options.method_name}, "
                f"{'crossings located' if options.locate_crossings else 'plain'}"
                f", {options.backend}: compile the system with these options (compile_model(system, options))")
        return options

    def clone(self) -> "CompiledModel":
        """The same functions with work arrays of its own: one clone per thread runs in parallel
        (the native calls release the GIL; the generated functions keep no other state)."""
        native = load_native(self.library, self.native) if self.native else None
        return replace(self, native=native, timings=dict(self.timings))

    # ---------------------------------------------------------------- names
    @property
    def name(self) -> str:
        return self.system.name

    @property
    def dimension(self) -> int:
        return self.system.dimension

    @cached_property  # read for every row a sweep writes
    def state_names(self) -> tuple[str, ...]:
        return tuple(self.system.state_names)

    @cached_property
    def observed(self) -> tuple[str, ...]:
        return tuple(s for s in self.state_names if s in self.system.observed)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.system.parameters)

    @property
    def steps_per_period(self) -> int:
        """RK4 steps per period of the loops (the options' steps per forcing period times :attr:`cycles`)."""
        return self.options.steps_per_period

    @property
    def cycles(self) -> int:
        """Forcing periods in one period: 1, or a gear's revolution (the hunting period) with shaft-order terms."""
        return self.system.cycles

    @property
    def steps_per_cycle(self) -> int:
        """RK4 steps per forcing period (a mesh period)."""
        return self.steps_per_period // self.cycles

    # ---------------------------------------------------------------- inputs
    def parameter_vector(self, values: Mapping[str, float] | None = None, **more: float) -> np.ndarray:
        """The model's parameter vector: its values, with ``values``/``more`` overriding (names checked)."""
        merged = self.system.parameter_values({**(values or {}), **more})
        return np.array([merged[n] for n in self.parameter_names], dtype=float)

    def prepare(self, p: np.ndarray | Mapping[str, float] | None = None, t0: float = 0.0) -> RunInputs:
        if not isinstance(p, np.ndarray):  # (a sweep's vectors skip the Mapping check)
            p = self.parameter_vector(p) if p is None or isinstance(p, Mapping) else np.asarray(p, dtype=float)
        elif p.dtype != np.float64:
            p = p.astype(float)
        if p.shape != (len(self.parameter_names),) or not all(map(math.isfinite, p.tolist())):
            raise GearsymError(f"{self.name}: expected {len(self.parameter_names)} finite parameter values "
                               f"({', '.join(self.parameter_names)}), got {p}")
        # a sweep's next point often changes only values outside the tables: then only the constants are new
        timed = self._timed_values(p)
        last_timed, last = self.__dict__.get("_last_inputs", (None, None))
        if last is not None and last.t0 == float(t0) and timed == last_timed:
            inputs = self._with_constants(last, p)
        else:
            inputs = self._tables(p, float(t0))
        self.__dict__["_last_inputs"] = (timed, inputs)
        return inputs

    def _tables(self, p: np.ndarray, t0: float) -> RunInputs:
        """New inputs for ``p``: the tables of time computed, the period checked."""
        if self.native:
            return self._native_tables(p, t0)
        c, period = (np.array(v) for v in self.functions["constants"](p))
        table, probe = (np.array(v) for v in self.functions["table"](t0, p))
        period = self._checked_period(p, t0, float(period.reshape(-1)[0]), probe)
        return RunInputs(p, np.asfortranarray(table, dtype=np.float64), np.ascontiguousarray(c.reshape(-1)),
                         period, t0, self.hash)

    def _native_tables(self, p: np.ndarray, t0: float) -> RunInputs:
        """:meth:`_tables` through the library: t0, p, the tables, the probe, the constants and the period in
        one new block, so that one address serves both calls (a paper-scheme sweep in omega makes one a point)."""
        k, (rows, steps), (probe_rows, _), size = self._table_layout
        table_at, probe_at, c_at = 1 + k, 1 + k + rows * steps, 1 + k + rows * steps + 2 * probe_rows
        block = np.zeros(c_at + size + 1)  # (zeros: what the library leaves unwritten reads as CasADi's)
        block[0] = t0
        block[1:table_at] = p
        at = block.ctypes.data
        self.native["constants"].call((at + 8,), (at + 8 * c_at, at + 8 * (c_at + size)))
        self.native["table"].call((at, at + 8), (at + 8 * table_at, at + 8 * probe_at))
        probe = block[probe_at:c_at].reshape((probe_rows, 2), order="F")
        period = self._checked_period(p, t0, float(block[c_at + size]), probe)
        inputs = RunInputs(block[1:table_at], block[table_at:probe_at].reshape((rows, steps), order="F"),
                           block[c_at:c_at + size], period, t0, self.hash)
        inputs.__dict__["addresses"] = (at + 8 * table_at, at + 8 * c_at)  # (the cached property, known already)
        return inputs

    def tables(self, P: np.ndarray, t0: float = 0.0) -> np.ndarray:
        """The tables of time of each parameter vector (row) of ``P``, each flattened as the loops read it
        (column-major), its period checked: what the many points of a chart share, two native calls a row straight
        into the rows of one array (no :class:`RunInputs`: :meth:`prepare` costs twice as much a table), the
        periods and the probes checked at once after them."""
        P = np.ascontiguousarray(P, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != len(self.parameter_names) or not np.isfinite(P).all():
            raise GearsymError(f"{self.name}: expected rows of {len(self.parameter_names)} finite parameter values "
                               f"({', '.join(self.parameter_names)}), got an array of shape {P.shape}")
        if not self.native:
            return np.array([self._tables(p, float(t0)).table.reshape(-1, order="F") for p in P]).reshape(len(P), -1)
        k, (rows, steps), (probe_rows, _), size = self._table_layout
        count = len(P)
        out = np.zeros((count, rows * steps))  # (zeros: what the library leaves unwritten reads as CasADi's)
        probes = np.zeros((count, 2, probe_rows))  # (each row's probe column-major: its two columns)
        periods = np.zeros(count)
        scratch = np.zeros(size + 1)  # t0, then the constants (not kept)
        scratch[0] = t0
        constants, table = self.native["constants"].call, self.native["table"].call
        t_at, c_at = scratch.ctypes.data, scratch.ctypes.data + 8
        p_at, out_at, probe_at, period_at = P.ctypes.data, out.ctypes.data, probes.ctypes.data, periods.ctypes.data
        for r in range(count):
            p = p_at + 8 * k * r
            constants((p,), (c_at, period_at + 8 * r))
            table((t_at, p), (out_at + 8 * rows * steps * r, probe_at + 16 * probe_rows * r))
        a, b = probes[:, 0], probes[:, 1]
        wrong = ~(np.isfinite(periods) & (periods > 0)) | ~(np.abs(a - b) <= 1e-9 * (1 + np.abs(a))).all(axis=1)
        for r in np.flatnonzero(wrong)[:1]:  # (the first one wrong, said as a single point's would be)
            self._checked_period(P[r], float(t0), float(periods[r]), probes[r].T)
        return out

    @cached_property
    def _table_layout(self) -> tuple[int, tuple[int, int], tuple[int, int], int]:
        """Parameters, the shapes of the tables and of the probe, and the number of constants."""
        table, probe = self.native["table"].shapes_out
        return len(self.parameter_names), table, probe, self.native["constants"].shapes_out[0][0]

    def _checked_period(self, p: np.ndarray, t0: float, period: float, probe: np.ndarray) -> float:
        if not (math.isfinite(period) and period > 0):
            raise ModelError(f"the forcing period is {period} at these parameter values; it must be positive",
                             self.name)
        self._check_periodic(p, t0, period, probe)
        return period

    @property
    def timed_parameters(self) -> frozenset[str]:
        """The parameters that enter the tables of time or the period: only a change of one of them needs
        new tables (:meth:`retune`). Found when the code is generated (:func:`.build.compile_model`)."""
        return self.timed

    def retune(self, inputs: RunInputs, p: np.ndarray) -> RunInputs:
        """The inputs for the parameter vector ``p``: those of ``inputs`` with new constants if no parameter that
        changed enters the tables or the period (a continuation in omega of a model in tau), else :meth:`prepare`."""
        p = np.asarray(p, dtype=float)
        if p.shape != inputs.p.shape or not all(map(math.isfinite, p.tolist())) or self._retimed(inputs.p, p):
            return self.prepare(p, inputs.t0)
        return self._with_constants(inputs, p)

    def _with_constants(self, inputs: RunInputs, p: np.ndarray) -> RunInputs:
        """``inputs`` with the constants of ``p``, whose timed parameters are those of ``inputs``."""
        if not self.native:
            c = np.array(self.functions["constants"](p)[0]).reshape(-1)
            return RunInputs(p, inputs.table, c, inputs.period, inputs.t0, inputs.model_hash)
        # straight into the new constants (a continuation asks for thousands of them): p, the constants and
        # the period (not used: it is that of ``inputs``) share one block, so one address serves the call
        k, size = p.size, inputs.constants.size
        block = np.empty(k + size + 1)
        block[:k] = p
        at = block.ctypes.data
        self.native["constants"].call((at,), (at + 8 * k, at + 8 * (k + size)))
        new = RunInputs(block[:k], inputs.table, block[k:k + size], inputs.period, inputs.t0, inputs.model_hash)
        new.__dict__["addresses"] = (inputs.addresses[0], at + 8 * k)  # (the cached property, known already)
        return new

    def _retimed(self, before: np.ndarray, after: np.ndarray) -> bool:
        """Whether a parameter that enters the tables of time or the period differs between the vectors."""
        return self._timed_values(before) != self._timed_values(after)

    def _timed_values(self, p: np.ndarray) -> list[float]:
        """The values of ``p`` that enter the tables of time or the period (plain floats: cheap to compare)."""
        values = p.tolist()
        return [values[i] for i in self._timed_index]

    @cached_property
    def _timed_index(self) -> tuple[int, ...]:
        return tuple(i for i, n in enumerate(self.parameter_names) if n in self.timed_parameters)

    def _check_periodic(self, p: np.ndarray, t0: float, period: float, probe: np.ndarray) -> None:
        """The loops repeat one sampled period; at other parameter values than the defaults
        (checked when the code was generated) the time dependence must still repeat.
        ``probe`` holds the tables at t0 + 0.37 T and one period later."""
        a, b = probe[:, 0].tolist(), probe[:, 1].tolist()  # (a few values: plain floats, the same arithmetic)
        off = [i for i, (x, y) in enumerate(zip(a, b)) if not abs(x - y) <= 1e-9 * (1 + abs(x))]
        if off:
            i = off[0]
            expr = self.table_texts[i] if i < len(self.table_texts) else f"table {i}"
            values = ", ".join(f"{n}={v:g}" for n, v in zip(self.parameter_names, p))
            raise NotPeriodicError(self.name, expr, str(self.system.period), self.system.time_name,
                                   t0 + 0.37 * period, a[i], b[i], f"at {values}")

    def _check_inputs(self, inputs: RunInputs) -> None:
        if inputs.model_hash != self.hash:
            raise GearsymError(f"{self.name}: these run inputs were prepared by another model "
                               "(a different code hash); call prepare() on this one")

    def initial_state(self, y0=None) -> np.ndarray:
        if y0 is None:
            return np.array(self.system.initial_vector)
        if isinstance(y0, Mapping):
            unknown = set(y0) - set(self.state_names)
            if unknown:
                raise GearsymError(f"{self.name}: unknown states {sorted(unknown)} in the initial state; "
                                   f"states are {', '.join(self.state_names)}")
            declared = self.system.initial
            zeroed = [s for s in self.state_names if s not in y0 and declared.get(s, 0.0) != 0.0]
            if zeroed:
                warn(f"{self.name}: the initial state does not name {', '.join(zeroed)}, so "
                     f"{'they start' if len(zeroed) > 1 else 'it starts'} at 0, not at the model's "
                     + ", ".join(f"{s}={declared[s]:g}" for s in zeroed) + "; name every state to choose")
            y0 = [float(y0.get(s, 0.0)) for s in self.state_names]
        y = np.array(y0, dtype=np.float64).reshape(-1)  # a contiguous copy: the C loop reads it by address
        if y.shape != (self.dimension,):
            raise GearsymError(f"{self.name}: the initial state needs {self.dimension} values "
                               f"({', '.join(self.state_names)}), got {y.size}")
        if not all(map(math.isfinite, y.tolist())):
            raise GearsymError(f"{self.name}: the initial state must be finite, got {y}")
        return y

    # ---------------------------------------------------------------- runs
    def tangent_run(self, y0, periods: int, inputs: RunInputs, Q0=None,
                    out: tuple[np.ndarray, ...] | None = None, check_finite: bool = True) -> TangentRun:
        """``periods`` forcing periods of the state and n tangent vectors, re-orthonormalised every period.
        ``out``: where to write the strobe, log stretches, lows and highs (a slot of :class:`TangentRuns`).
        ``check_finite=False``: a run that becomes non-finite is returned as it is (the caller judges it)."""
        self._check_inputs(inputs)
        n, m = self.dimension, len(self.observed)
        y = self.initial_state(y0)
        Q = None if Q0 is None else np.asarray(Q0, dtype=np.float64)
        if Q is not None and Q.shape != (n, n):
            raise GearsymError(f"{self.name}: tangent vectors must be a {n}x{n} matrix, got {Q.shape}")
        schedule = self._schedule(periods, "lyapunov")
        if out is not None and [(a.shape, a.flags.f_contiguous) for a in out] != [
                ((rows, periods), True) for rows in (n, n, m, m)]:
            raise GearsymError(f"{self.name}: tangent_run(out=...) needs column-major arrays of {n}, {n}, {m} and "
                               f"{m} rows by {periods} periods (a TangentRuns slot)")
        if not self.native:
            records, Q = self._casadi_loop(schedule, y, np.array(np.eye(n) if Q is None else Q, order="F"), inputs,
                                           (n, n, m, m))
            if out is not None:
                for into, record in zip(out, records):
                    into[...] = record
            strobe, logs, low, high = out or records
            if check_finite:
                self.check_finite(inputs.p, strobe, logs)
            return TangentRun(strobe, logs, low, high, Q)
        # one new block for the start, both tangent buffers and (without ``out``) the records: one address
        rows = (n, n, m, m)
        sizes = [n, n * n, n * n] + ([] if out else [r * periods for r in rows])
        block = np.empty(sum(sizes))
        views = [block[a - size:a] for a, size in zip(itertools.accumulate(sizes), sizes)]
        views[0][:] = y
        Qs = [v.reshape(n, n).T for v in views[1:3]]  # (column-major views)
        if Q is None:
            views[1][:] = 0.0
            views[1][::n + 1] = 1.0
        else:
            Qs[0][...] = Q
        at = block.ctypes.data
        if out:
            strobe, logs, low, high = out
            bases, strides = _addresses(*out)
        else:
            strobe, logs, low, high = (v.reshape(periods, r).T for v, r in zip(views[3:], rows))
            first = at + 8 * (n + 2 * n * n)
            bases = [first + 8 * periods * k for k in (0, n, 2 * n, 2 * n + m)]
            strides = [8 * r for r in rows]
        final = self._native_loop(schedule, at, [at + 8 * n, at + 8 * (n + n * n)], inputs, bases, strides)
        # one sum over the strobe and log stretches (adjacent in the block): finite, unless told otherwise
        if check_finite and (out or not math.isfinite(block[n + 2 * n * n:n + 2 * n * n + 2 * n * periods].sum())):
            self.check_finite(inputs.p, strobe, logs)
        return TangentRun(strobe, logs, low, high, Qs[final])

    def tangent_run_into(self, runs: TangentRuns, i: int, y: np.ndarray, inputs: RunInputs,
                         check_finite: bool = True) -> None:
        """:meth:`tangent_run` of ``runs.periods`` periods from ``y`` (a state already checked) with tangent
        vectors from the identity, into run i of ``runs``: a sweep's per-point path, every address taken
        beforehand. ``check_finite=False``: the caller checks the records (a sweep checks a batch at once,
        with :meth:`check_finite`)."""
        if not self.native:
            self.tangent_run(y, runs.periods, inputs, out=runs.slot(i))
            return
        self._check_inputs(inputs)
        if runs.planned_by is not self:  # (the calls are this model's: a clone has work arrays of its own)
            runs.calls, runs.planned_by = {}, self
        calls = runs.calls.get(i)
        if calls is None:
            calls = runs.calls[i] = self._chunk_calls(self._schedule(runs.periods, "lyapunov"), runs.start_address,
                                                      runs.Q_addresses, runs.addresses(i), runs.strides)
        runs.start[:] = y
        runs.Q[0][...] = runs.eye
        _make_calls(calls, inputs)
        if check_finite:
            self.check_finite(inputs.p, runs.strobe[i].T, runs.log_stretch[i].T)

    def _native_loop(self, schedule, y: int, Q: list[int], inputs: RunInputs, bases: list[int],
                     strides: list[int]) -> int:
        """Chunk after chunk from the state at address ``y``, writing straight into the outputs (the first
        is the strobe), one column of ``strides`` bytes per period from ``bases``; with tangent vectors
        (``Q``: the addresses of two n x n buffers) returns the index of the one holding the final Q."""
        calls = self._chunk_calls(schedule, y, Q, bases, strides)
        _make_calls(calls, inputs)
        return len(calls) % 2

    def _chunk_calls(self, schedule, y: int, Q: list[int], bases: list[int], strides: list[int]) -> list[tuple]:
        """The native calls of a run, as (function, arguments before the table and constants, results).

        The start state of each chunk is read where the previous chunk wrote its last period; Q ping-pongs
        between its two buffers. The addresses depend only on the buffers, so a sweep plans the calls of each
        of its buffers' slots once (:meth:`tangent_run_into`)."""
        strobe, stride, col, calls = bases[0], strides[0], 0, []
        for fname, count in schedule:
            f, width = self.native[fname], (self.options.chunk_periods if fname.endswith("chunk") else 1)
            for _ in range(count):
                at = [b + col * s for b, s in zip(bases, strides)]
                if Q:
                    k = len(calls) % 2
                    calls.append((f, (y, Q[k]), (at[0], Q[1 - k], *at[1:])))
                else:
                    calls.append((f, (y,), tuple(at)))
                col += width
                y = strobe + (col - 1) * stride
        return calls

    def _casadi_loop(self, schedule, y, Q, inputs: RunInputs, rows: tuple[int, ...]):
        """The in-process twin of ``_native_loop``: the same chunks through CasADi's calls, outputs stacked
        per period (``rows``: their heights, for an empty run). ``Q`` None: no tangent vectors."""
        import casadi as ca

        yd, Qd, parts = ca.DM(y), (None if Q is None else ca.DM(Q)), []
        for fname, count in schedule:
            f = self.functions[fname]
            for _ in range(count):
                if Qd is None:
                    out, *rest = f(yd, inputs.table_dm, inputs.constants_dm)
                else:
                    out, Qd, *rest = f(yd, Qd, inputs.table_dm, inputs.constants_dm)
                yd = out[:, -1]
                parts.append((out, *rest))
        stacked = [_hcat([p[i] for p in parts], r) for i, r in enumerate(rows)]
        return stacked, (None if Qd is None else np.array(Qd))

    @cached_property
    def shooting_pieces(self) -> int:
        """The pieces the generated code cuts a forcing period into for multiple shooting (4, or fewer
        when the steps per period do not divide by 4)."""
        table = self.native["monodromy_segment"].shapes_in[2] if self.native \
            else self.functions["monodromy_segment"].size_in(2)
        return self.steps_per_period // int(table[1])

    def shoot(self, y0, inputs: RunInputs, pieces: int | None = None, first: int = 0) -> Shot:
        """The state and the exact Jacobian d state/d y0 after ``pieces`` pieces of a period (default one
        whole period; see :attr:`shooting_pieces`), starting at piece ``first`` of the period (the phase
        t0 + first/pieces_per_period of ``inputs``): the exact variational equations along the same
        (crossing-located) steps as every run, with no re-orthonormalisation."""
        self._check_inputs(inputs)
        pieces = self.shooting_pieces if pieces is None else whole_number(pieces, "pieces", 1)
        y = y0 if isinstance(y0, np.ndarray) and y0.shape == (self.dimension,) else self.initial_state(y0)
        shot = (self._native_shot if self.native else self._casadi_shot)(y, inputs, first, first + pieces)
        if not (np.isfinite(shot.state).all() and np.isfinite(shot.M).all() and np.isfinite(y).all()):
            self.check_finite(inputs.p, np.full((1, 1), np.nan))
        return shot

    def _shot_plan(self, first: int, end: int):
        """(function, piece) calls from piece ``first`` to ``end``: whole periods where they line up."""
        S, k = self.shooting_pieces, first
        while k < end:
            whole = k % S == 0 and end - k >= S
            yield ("monodromy_period" if whole else "monodromy_segment"), k % S
            k += S if whole else 1

    @cached_property
    def _shot_buffers(self) -> "_ShotBuffers":
        return _ShotBuffers(self.dimension, len(self.observed))

    def _native_shot(self, y, inputs: RunInputs, first: int, end: int) -> Shot:
        """Piece after piece into two buffers taken in turn (Newton calls this thousands of times: nothing
        here but the calls)."""
        b = self._shot_buffers
        b.y[0][:] = y
        b.M[0][:] = b.eye
        table, c = inputs.addresses
        piece_bytes = inputs.table.shape[0] * 8 * (self.steps_per_period // self.shooting_pieces)
        low = high = None
        i = 0
        for name, piece in self._shot_plan(first, end):
            self.native[name].call((b.y_at[i], b.M_at[i], table + piece * piece_bytes, c),
                                   (b.y_at[1 - i], b.M_at[1 - i], b.low_at, b.high_at))
            i = 1 - i
            low = b.low.copy() if low is None else np.minimum(low, b.low)
            high = b.high.copy() if high is None else np.maximum(high, b.high)
        return Shot(b.y[i].copy(), b.M[i].copy(), low, high)

    def _casadi_shot(self, y, inputs: RunInputs, first: int, end: int) -> Shot:
        import casadi as ca

        m, width = len(self.observed), self.steps_per_period // self.shooting_pieces
        yd, Md = ca.DM(y), ca.DM.eye(self.dimension)
        low, high = np.full(m, np.inf), np.full(m, -np.inf)
        for name, piece in self._shot_plan(first, end):
            table = inputs.table_dm if name == "monodromy_period" else \
                inputs.table_dm[:, piece * width:(piece + 1) * width]
            yd, Md, lo, hi = self.functions[name](yd, Md, table, inputs.constants_dm)
            low, high = np.minimum(low, np.array(lo).reshape(-1)), np.maximum(high, np.array(hi).reshape(-1))
        return Shot(np.array(yd).reshape(-1), np.array(Md), low, high)

    def orbit_run(self, y0, periods: int, inputs: RunInputs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The state after each of ``periods`` periods (stroboscopic samples), with each period's min and max."""
        self._check_inputs(inputs)
        y, n, m = self.initial_state(y0), self.dimension, len(self.observed)
        schedule = self._schedule(periods, "orbit")
        if self.native:
            strobe = np.empty((n, periods), order="F")
            low, high = (np.empty((m, periods), order="F") for _ in range(2))
            self._native_loop(schedule, y.ctypes.data, [], inputs, *_addresses(strobe, low, high))
        else:
            (strobe, low, high), _ = self._casadi_loop(schedule, y, None, inputs, (n, m, m))
        self.check_finite(inputs.p, strobe)
        return strobe, low, high

    def trajectory(self, y0, periods: int, inputs: RunInputs) -> tuple[np.ndarray, np.ndarray]:
        """Every RK4 step of ``periods`` periods: times (steps,) and states (n, steps), the start included."""
        self._check_inputs(inputs)
        whole_number(periods, "periods")
        check_fits(periods, 16 * self.steps_per_period * (self.dimension + 1),
                   asked=f"a trajectory of {periods} periods", item="period",
                   what=f"{self.name}'s time and state at every RK4 step, twice while joined")
        y, n, N = self.initial_state(y0), self.dimension, self.steps_per_period
        if self.native:  # (period after period straight into one array: each starts at the previous one's end)
            states = np.empty((n, periods * N + 1), order="F")
            states[:, 0] = y
            first, (table, c) = states.ctypes.data, inputs.addresses
            for k in range(periods):
                at = first + 8 * n * N * k
                self.native["trajectory"].call((at, table, c), (at + 8 * n,))
        else:
            import casadi as ca

            y = ca.DM(y)
            cols = [np.array(y)]
            for _ in range(periods):
                block = self.functions["trajectory"](y, inputs.table_dm, inputs.constants_dm)
                cols.append(np.array(block))
                y = block[:, -1]
            states = np.hstack(cols)
        h = inputs.period / self.steps_per_period
        return inputs.t0 + h * np.arange(states.shape[1]), states

    def rhs(self, t: float, y, p) -> np.ndarray:
        return self._at("rhs", t, y, p).reshape(-1)

    def jacobian(self, t: float, y, p) -> np.ndarray:
        return self._at("jacobian", t, y, p)

    def _at(self, name: str, t: float, y, p) -> np.ndarray:
        """The right-hand side or the Jacobian at (t, y, p): by the library's own call where the sizes are the
        function's (a tenth of CasADi's call and copy of the result), else CasADi's (which says what is wrong)."""
        args = [np.asarray(a, dtype=np.float64) for a in (t, y, p)]
        if self.native:
            f = self.native[name]
            if [a.size for a in args] == [rows * cols for rows, cols in f.shapes_in] and f.dense_out[0]:
                return f(*args)[0]
        return np.array(self.functions[name](t, y, p))

    def check_finite(self, p: np.ndarray, *per_period: np.ndarray) -> None:
        """Raise the error of a run at the parameter vector ``p`` that became non-finite, if one of the
        ``per_period`` records (rows x periods) did."""
        # one pass each: a finite sum has finite terms (an infinite one may not: an overflow; the test below tells)
        if math.isfinite(sum(float(a.sum()) for a in per_period)):
            return
        bad = ~np.logical_and.reduce([np.isfinite(a).all(axis=0) for a in per_period])
        if bad.any():
            k = int(np.argmax(bad))
            values = ", ".join(f"{n}={v:g}" for n, v in zip(self.parameter_names, p))
            raise GearsymError(
                f"{self.name}: the solution became non-finite in period {k + 1} ({values}). The orbit diverges "
                f"or the step T/{self.steps_per_period} is too large for it: try more --steps-per-period, "
                "another initial state or other parameter values."
            )

    def _schedule(self, periods: int, kind: str) -> list[tuple[str, int]]:
        chunks, rest = divmod(whole_number(periods, "periods"), self.options.chunk_periods)
        return [(f"{kind}_chunk", chunks), (f"{kind}_period", rest)]


def _make_calls(calls: list[tuple], inputs: RunInputs) -> None:
    """The native calls planned by :meth:`CompiledModel._chunk_calls`, with the table and constants of ``inputs``."""
    shared = inputs.addresses
    for f, args, results in calls:
        f.call((*args, *shared), results)


def _addresses(*columns: np.ndarray) -> tuple[list[int], list[int]]:
    """Where each column-major (rows x periods) array starts, and the bytes from one column to the next."""
    return [a.ctypes.data for a in columns], [a.shape[0] * 8 for a in columns]


def _hcat(blocks, rows: int) -> np.ndarray:
    return np.hstack([np.array(b) for b in blocks]) if blocks else np.zeros((rows, 0))
