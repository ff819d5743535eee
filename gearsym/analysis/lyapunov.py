"""The Lyapunov spectrum at one parameter point.

Exponents come from the exact variational equations integrated with the
state (:mod:`gearsym.codegen.functions`) and Gram-Schmidt once per forcing
period: lambda_i = sum of log stretches / time, over the periods after the
transient. Exponents are per unit of the model's time (tau for the gear
models). The paper's criterion for chaos is lambda_1 > 0 (it prints "> 1").

An autonomous run that never leaves a fixed point (Lorenz started at the
origin) has exponents too, the real parts of the Jacobian's eigenvalues there,
and a positive one says the point is unstable, not that the motion is chaotic:
such a run is reported as an ``equilibrium`` with those eigenvalues, exactly.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..checks import json_safe
from ..codegen import CompiledModel, TangentRuns, engine_verb
from ..codegen.lane_runs import LaneRunner
from ..errors import GearsymError, warn
from ..options import Integration
from .regime import EQUILIBRIUM, classify_regime, classify_regimes
from .statistics import batch_means_stderr

#: a run rests on a fixed point when, over the measured periods, the state moves by no more than this and
#: the right-hand side there is no larger (both relative to 1 + the largest |state|)
AT_REST = 1e-9


@dataclass(frozen=True)
class LyapunovSpectrum:
    """All n exponents at one point, with what the run saw along the way."""

    model: str
    parameters: dict[str, float]
    exponents: np.ndarray  # descending, per unit time
    stderr: np.ndarray  # batch-means standard error of each exponent
    history: np.ndarray  # (measured periods, n): running estimates after each period
    amplitude: dict[str, float]  # A = (max - min)/2 of each relative coordinate over the measured periods
    final_state: dict[str, float]
    strobe: np.ndarray  # (n, measured periods): stroboscopic (Poincare) samples
    periods: int
    discard: int
    steps_per_period: int
    period: float
    backend: str
    autonomous: bool = False  # time-free equations: one exponent is zero along the flow
    info: dict = field(default_factory=dict)
    eigenvalues: np.ndarray | None = None  # of the Jacobian at the fixed point the run rested on, if it did

    @property
    def at_rest(self) -> bool:
        """The run never left a fixed point: the exponents are the real parts of ``eigenvalues``."""
        return self.eigenvalues is not None

    @property
    def measured_time(self) -> float:
        """The time the exponents are averaged over (after the transient)."""
        return (self.periods - self.discard) * self.period

    @property
    def regime(self) -> str:
        """periodic, quasi-periodic, chaotic or hyperchaotic (see :mod:`gearsym.analysis.regime`);
        equilibrium for a run at rest on a fixed point, stable or not."""
        if self.at_rest:
            return EQUILIBRIUM
        return classify_regime(self.exponents, self.stderr, self.measured_time, self.autonomous)

    @property
    def sum(self) -> float:
        return float(np.sum(self.exponents))

    @property
    def kaplan_yorke_dimension(self) -> float:
        """D_KY = j + (lambda_1 + ... + lambda_j) / |lambda_(j+1)|, j the largest with a non-negative partial sum."""
        partial = np.cumsum(self.exponents)
        nonneg = np.nonzero(partial >= 0)[0]
        if nonneg.size == 0:
            return 0.0
        j = int(nonneg[-1]) + 1
        if j == len(self.exponents):
            return float(j)
        return j + float(partial[j - 1]) / abs(float(self.exponents[j]))

    def as_dict(self) -> dict:
        """JSON-ready: the keys of ``gearsym lyap --format json``."""
        return {
            "model": self.model,
            "parameters": self.parameters,
            "exponents": json_safe(self.exponents),
            "stderr": json_safe(self.stderr),  # null with too few periods to estimate it
            "sum": self.sum,
            "kaplan_yorke_dimension": json_safe(self.kaplan_yorke_dimension),
            "regime": self.regime,
            "equilibrium": None if not self.at_rest else {  # the exponents are the real parts of these
                "state": self.final_state,
                "eigenvalues": [{"re": float(e.real), "im": float(e.imag)} for e in self.eigenvalues],
                "stable": bool(np.all(self.eigenvalues.real < 0)),
            },
            "amplitude": self.amplitude,
            "final_state": self.final_state,
            "periods": self.periods,
            "discard": self.discard,
            "steps_per_period": self.steps_per_period,
            "period": self.period,
            "backend": self.backend,
        }


@engine_verb
def lyapunov_spectrum(model: CompiledModel, *, options: Integration | None = None, y0=None,
                      **values: float) -> LyapunovSpectrum:
    """Full Lyapunov spectrum of ``model`` at the parameter ``values`` (the model's own for the rest).

    ``model`` is a :class:`~gearsym.codegen.CompiledModel` (the low-level call: nothing is rebuilt, for
    sweeps) or a :class:`~gearsym.system.FirstOrderSystem` (compiled first with ``options``).
    ``options``: an :class:`~gearsym.options.Integration` (default: the compiled model's; the exponents
    average over ``periods - discard`` periods). ``y0`` is the initial state (sequence or mapping;
    default: the model's declared initial state).
    """
    options = model.run_options(options)
    p = model.parameter_vector(values)
    inputs = model.prepare(p)
    if y0 is None and model.system.autonomous and _rests(model, model.initial_state(), p):
        start = ", ".join(f"{n}={v:g}" for n, v in zip(model.state_names, model.initial_state()))
        warn(f"{model.name}: the initial state ({start}) is a fixed point, so the run stays there; "
             "give another initial state (initial=... in the model, y0=... or --y0)")
    runs = TangentRuns(model.dimension, len(model.observed), options.periods, 1)
    run = model.tangent_run(y0, options.periods, inputs, out=runs.slot(0))
    summary = summarise_runs(model, runs, p[None, :], np.array([inputs.period]), options.discard)
    measured = runs.log_stretch[0, options.discard:] / inputs.period  # (measured periods, n), each period
    history = np.cumsum(measured, axis=0) / np.arange(1, measured.shape[0] + 1)[:, None]
    return LyapunovSpectrum(
        model=model.name,
        parameters=dict(zip(model.parameter_names, map(float, p))),
        exponents=summary.exponents[0],
        stderr=summary.stderr[0],
        history=history[:, summary.order[0]],
        amplitude=dict(zip(model.observed, map(float, summary.amplitude[0]))),
        final_state=dict(zip(model.state_names, map(float, runs.strobe[0, -1]))),
        strobe=run.strobe[:, options.discard:],
        periods=options.periods,
        discard=options.discard,
        steps_per_period=model.steps_per_period,
        period=inputs.period,
        backend=model.backend,
        autonomous=model.system.autonomous,
        info={"Q": run.Q, "locate_crossings": model.options.locate_crossings},
        eigenvalues=summary.eigenvalues[0],
    )


def lyapunov_spectra(model: CompiledModel, starts: np.ndarray, options: Integration, p: np.ndarray, *,
                     lanes: bool = True) -> list[LyapunovSpectrum]:
    """:func:`lyapunov_spectrum` of ``model`` at the parameter vector ``p`` from each of ``starts`` (runs x n),
    many at once in the lanes (:mod:`gearsym.codegen.lane_runs`: each lane the scalar loop's numbers); a run that
    does not stay finite raises the error :func:`lyapunov_spectrum` raises, naming its start."""
    inputs = model.prepare(p)
    records = LaneRunner(model, 0, options.periods, lanes=lanes).orbits(starts, inputs, tangent=True)
    count, n, o = len(starts), model.dimension, len(model.observed)
    runs = TangentRuns(n, o, options.periods, max(count, 1))
    for i in range(count):
        try:
            model.check_finite(p, records.strobe[i].T, records.log_stretch[i].T)
        except GearsymError as exc:
            start = ", ".join(f"{name}={v:g}" for name, v in zip(model.state_names, starts[i]))
            raise GearsymError(f"initial state #{i} ({start}): {exc}") from None
    runs.strobe[:count], runs.log_stretch[:count] = records.strobe, records.log_stretch
    runs.low[:count], runs.high[:count] = records.low, records.high
    summary = summarise_runs(model, runs, np.tile(p, (count, 1)), np.full(count, inputs.period), options.discard)
    out = []
    for i in range(count):
        measured = runs.log_stretch[i, options.discard:] / inputs.period
        history = np.cumsum(measured, axis=0) / np.arange(1, measured.shape[0] + 1)[:, None]
        out.append(LyapunovSpectrum(
            model=model.name, parameters=dict(zip(model.parameter_names, map(float, p))),
            exponents=summary.exponents[i], stderr=summary.stderr[i], history=history[:, summary.order[i]],
            amplitude=dict(zip(model.observed, map(float, summary.amplitude[i]))),
            final_state=dict(zip(model.state_names, map(float, records.final[i]))),
            strobe=runs.strobe[i].T[:, options.discard:], periods=options.periods, discard=options.discard,
            steps_per_period=model.steps_per_period, period=inputs.period, backend=model.backend,
            autonomous=model.system.autonomous,
            info={"Q": records.Q[i], "locate_crossings": model.options.locate_crossings},
            eigenvalues=summary.eigenvalues[i]))
    return out


@dataclass(frozen=True)
class RunsSummary:
    """What the per-period records of several tangent runs of one model say, computed for all at once."""

    exponents: np.ndarray  # (runs, n): descending, per unit time
    stderr: np.ndarray  # (runs, n): batch-means standard errors, in the order of the exponents
    order: np.ndarray  # (runs, n): the Gram-Schmidt index of each exponent
    amplitude: np.ndarray  # (runs, observed): A = (max - min)/2 over the measured periods
    eigenvalues: list  # per run: the Jacobian's eigenvalues at the fixed point it rested on (sorted), or None
    regimes: list[str]


def summarise_runs(model: CompiledModel, runs: TangentRuns, p: np.ndarray, period: np.ndarray,
                   discard: int) -> RunsSummary:
    """The spectra of the first ``len(p)`` runs of ``runs``, made at the parameter vectors ``p`` (runs x
    parameters) with forcing periods ``period``, averaged over the periods after ``discard``. One set of
    array operations serves them all: a sweep summarises its points in batches, and
    :func:`lyapunov_spectrum` is the batch of one."""
    count = len(p)
    measured = runs.log_stretch[:count, discard:] / period[:, None, None]  # per unit time, each period
    exponents = measured.mean(axis=1)
    stderr = batch_means_stderr(measured, axis=1)
    eigenvalues = [_fixed_point_eigenvalues(model, runs.strobe[i, discard:], runs.low[i, discard:],
                                            runs.high[i, discard:], p[i]) for i in range(count)] \
        if model.system.autonomous else [None] * count
    for i, values in enumerate(eigenvalues):
        if values is not None:  # the exponents of a fixed point, exactly
            exponents[i], stderr[i] = values.real, 0.0
    order = np.argsort(-exponents, axis=1, kind="stable")
    exponents, stderr = (np.take_along_axis(a, order, axis=1) for a in (exponents, stderr))
    eigenvalues = [None if e is None else e[o] for e, o in zip(eigenvalues, order)]
    measured_time = (runs.log_stretch.shape[1] - discard) * period
    regimes = classify_regimes(exponents, stderr, measured_time, model.system.autonomous)
    regimes = [EQUILIBRIUM if e is not None else r for e, r in zip(eigenvalues, regimes)]
    amplitude = (runs.high[:count, discard:].max(axis=1) - runs.low[:count, discard:].min(axis=1)) / 2
    return RunsSummary(exponents, stderr, order, amplitude, eigenvalues, regimes)


def _rests(compiled, y: np.ndarray, p: np.ndarray) -> bool:
    """f(y) = 0, to rounding (autonomous systems: any time)."""
    return bool(np.max(np.abs(compiled.rhs(0.0, y, p))) <= AT_REST * (1 + np.max(np.abs(y))))


def _fixed_point_eigenvalues(compiled, strobe: np.ndarray, low: np.ndarray, high: np.ndarray,
                             p: np.ndarray) -> np.ndarray | None:
    """The Jacobian's eigenvalues where an autonomous run stayed over its measured periods (``strobe``,
    ``low``, ``high``: periods x rows), if it stayed on a fixed point; None otherwise (the fixed points of
    a forced system's stroboscopic map are periodic orbits, not rests)."""
    y = strobe[-1]
    moved = max(np.ptp(strobe, axis=0).max(), np.max(high - low, initial=0.0))
    if moved > AT_REST * (1 + np.max(np.abs(y))) or not _rests(compiled, y, p):
        return None
    return np.linalg.eigvals(compiled.jacobian(0.0, y, p))
