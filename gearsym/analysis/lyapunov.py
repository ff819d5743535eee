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

Before any regime, a run that grew without bound is reported as ``diverged`` (the rule:
:mod:`gearsym.analysis.divergence`); two exponents of one rotating plane (a complex pair of Floquet
multipliers) are reported as their common real part (:mod:`gearsym.analysis.pairs`); and where the largest
exponent cannot be told from zero, the Poincare points decide between a torus and a transient, or say
``undetermined`` and how many periods would decide (:mod:`gearsym.analysis.regime`).
"""
from __future__ import annotations

import functools
from dataclasses import field

import numpy as np

from ..records import record_class
from ..checks import json_safe
from ..codegen import CompiledModel, TangentRuns, engine_verb
from ..errors import warn
from ..options import Integration
from .divergence import Divergence, counted_coordinates, find_divergence, own_rate, run_failure
from .pairs import merge_pairs
from .resolution import Resolution, resolution
from .regime import DIVERGED, EQUILIBRIUM, UNDETERMINED, classify_regimes, periods_to_decide, zero_band
from .settling import Settling, brief_run, long_run_rate, poincare_settling
from .statistics import batch_means_stderr

#: a run rests on a fixed point when, over the measured periods, the state moves by no more than this and
#: the right-hand side there is no larger (both relative to 1 + the largest |state|)
AT_REST = 1e-9


@record_class
class LyapunovSpectrum:
    """All n exponents at one point, with what the run saw along the way."""

    model: str
    parameters: dict[str, float]
    exponents: np.ndarray  # descending, per unit time (a rotating pair's two: their common real part)
    stderr: np.ndarray  # batch-means standard error of each exponent (a pair's: with its finite-time bias)
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
    #: periodic, quasi-periodic, chaotic or hyperchaotic (see :mod:`gearsym.analysis.regime`); equilibrium for a
    #: run at rest on a fixed point, stable or not; undetermined where neither the exponents nor the Poincare
    #: points decide; diverged for a run that grew without bound (``divergence`` says how)
    regime: str = ""
    pairs: tuple[tuple[int, int], ...] = ()  # (0-based) exponents reported as one rotating pair's real part
    divergence: Divergence | None = None
    settling: Settling | None = None  # what the Poincare points did, where the exponents needed them
    #: which exponents the step and the re-orthonormalisation resolved (:mod:`.resolution`); one not resolved is
    #: reported as such, never as a value
    resolution: Resolution | None = None

    @property
    def at_rest(self) -> bool:
        """The run never left a fixed point: the exponents are the real parts of ``eigenvalues``."""
        return self.eigenvalues is not None

    @property
    def measured_time(self) -> float:
        """The time the exponents are averaged over (after the transient)."""
        return (self.periods - self.discard) * self.period

    @property
    def periods_to_decide(self) -> int | None:
        """An undetermined run: the measured periods that would put lambda_1 outside the zero band (None
        otherwise; see :func:`gearsym.analysis.regime.periods_to_decide`)."""
        if self.regime != UNDETERMINED:
            return None
        rate = self.settling.rate if self.settling is not None else None
        return periods_to_decide(self.exponents[0], self.stderr[0], self.measured_time, self.period, rate)

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
            "pairs": [[i + 1, j + 1] for i, j in self.pairs],  # lambda_i = lambda_j: one complex pair's real part
            "divergence": None if self.divergence is None else self.divergence.as_dict(),
            "resolution": None if self.resolution is None else self.resolution.as_dict(),
            "periods_to_decide": self.periods_to_decide,
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
    start = model.initial_state(y0)
    run = model.tangent_run(start, options.periods, inputs, out=runs.slot(0), check_finite=False)
    summary = summarise_runs(model, runs, p[None, :], np.array([inputs.period]), options.discard)
    failure = run_failure(model, p, inputs.period, start, runs.strobe[0], runs.log_stretch[0], summary.divergences[0])
    if failure is not None:
        raise failure
    measured = runs.log_stretch[0, options.discard:] / inputs.period  # (measured periods, n), each period
    history = np.cumsum(measured, axis=0) / np.arange(1, measured.shape[0] + 1)[:, None]
    history = history[:, summary.order[0]]
    for i, j in summary.pairs[0]:  # a pair's running estimate: its common real part's
        history[:, [i, j]] = history[:, [i, j]].mean(axis=1, keepdims=True)
    return LyapunovSpectrum(
        model=model.name,
        parameters=dict(zip(model.parameter_names, map(float, p))),
        exponents=summary.exponents[0],
        stderr=summary.stderr[0],
        history=history,
        amplitude=dict(zip(model.observed, map(float, summary.amplitude[0]))),
        final_state=dict(zip(model.state_names, map(float, runs.strobe[0, -1]))),
        strobe=run.strobe[:, options.discard:],
        periods=options.periods,
        discard=options.discard,
        steps_per_period=model.steps_per_period,
        period=inputs.period,
        backend=model.backend,
        autonomous=model.system.autonomous,
        info={"Q": run.Q, "locate_crossings": model.options.locate_crossings, "integration": model.integration},
        eigenvalues=summary.eigenvalues[0],
        regime=summary.regimes[0],
        pairs=tuple(summary.pairs[0]),
        divergence=summary.divergences[0],
        settling=summary.settlings[0],
        resolution=spectrum_resolution(model, summary.exponents[0], p, runs.strobe[0, -1], inputs.period,
                               summary.divergences[0]),
    )


def spectrum_resolution(model, exponents, p, state, period, divergence) -> Resolution | None:
    """What the run resolved (none for a run that diverged)."""
    if divergence is not None or not np.all(np.isfinite(state)):
        return None
    return resolution(model, exponents, p, state, period)


@record_class
class RunsSummary:
    """What the per-period records of several tangent runs of one model say, computed for all at once."""

    exponents: np.ndarray  # (runs, n): descending, per unit time
    stderr: np.ndarray  # (runs, n): batch-means standard errors, in the order of the exponents
    order: np.ndarray  # (runs, n): the Gram-Schmidt index of each exponent
    amplitude: np.ndarray  # (runs, observed): A = (max - min)/2 over the measured periods
    eigenvalues: list  # per run: the Jacobian's eigenvalues at the fixed point it rested on (sorted), or None
    regimes: list[str]
    pairs: list  # per run: the (i, i + 1) reported as one rotating pair's common real part
    divergences: list  # per run: its Divergence, or None
    settlings: list  # per run: its Poincare points' Settling where the exponents could not decide, or None


def summarise_runs(model: CompiledModel, runs: TangentRuns, p: np.ndarray, period: np.ndarray,
                   discard: int) -> RunsSummary:
    """The spectra of the first ``len(p)`` runs of ``runs``, made at the parameter vectors ``p`` (runs x
    parameters) with forcing periods ``period``, averaged over the periods after ``discard``. One set of
    array operations serves them all: a sweep summarises its points in batches, and
    :func:`lyapunov_spectrum` is the batch of one."""
    count = len(p)
    autonomous = model.system.autonomous
    measured = runs.log_stretch[:count, discard:] / period[:, None, None]  # per unit time, each period
    with np.errstate(invalid="ignore", over="ignore"):  # (a run that diverged: judged below)
        exponents = measured.mean(axis=1)
        stderr = batch_means_stderr(measured, axis=1)
    finite = np.isfinite(runs.strobe[:count]).all(axis=(1, 2)) & np.isfinite(exponents).all(axis=1)
    eigenvalues = [_fixed_point_eigenvalues(model, runs.strobe[i, discard:], runs.low[i, discard:],
                                            runs.high[i, discard:], p[i]) if finite[i] else None
                   for i in range(count)] if autonomous else [None] * count
    for i, values in enumerate(eigenvalues):
        if values is not None:  # the exponents of a fixed point, exactly
            exponents[i], stderr[i] = values.real, 0.0
    order = np.argsort(-np.nan_to_num(exponents, nan=-np.inf), axis=1, kind="stable")
    exponents, stderr = (np.take_along_axis(a, order, axis=1) for a in (exponents, stderr))
    eigenvalues = [None if e is None else e[o] for e, o in zip(eigenvalues, order)]
    pairs = [[] for _ in range(count)]
    for i in range(count):
        if finite[i] and eigenvalues[i] is None:
            exponents[i], stderr[i], pairs[i] = merge_pairs(measured[i][:, order[i]], exponents[i], stderr[i])
    measured_time = (runs.log_stretch.shape[1] - discard) * period
    band = zero_band(stderr, measured_time[:, None])
    contracting = np.where(finite, exponents[:, 0] < -band[:, 0], False)
    counted = functools.partial(counted_coordinates, model)
    divergences = [find_divergence(runs.strobe[i], runs.low[i], runs.high[i], model.state_names, model.observed,
                                   discard, bool(contracting[i]), counted) for i in range(count)]
    live = [i for i in range(count) if divergences[i] is None and np.isfinite(exponents[i]).all()]
    regimes, settlings = [DIVERGED if d is not None else FAILED for d in divergences], [None] * count
    if live:
        exps = classify_regimes(exponents[live], stderr[live], measured_time[live], autonomous)
        for i, r in zip(live, exps):
            if r == "quasi-periodic" and not autonomous and eigenvalues[i] is None:
                rate = own_rate(model, runs.strobe[i, -1], p[i], period[i], enough=long_run_rate(measured_time[i]))
                settlings[i] = brief_run(rate, measured_time[i]) \
                    or poincare_settling(runs.strobe[i, discard:], period[i])
        regimes_live = classify_regimes(exponents[live], stderr[live], measured_time[live], autonomous,
                                        [settlings[i] for i in live])
        for i, r in zip(live, regimes_live):
            regimes[i] = EQUILIBRIUM if eigenvalues[i] is not None else r
    with np.errstate(invalid="ignore", over="ignore"):
        amplitude = (runs.high[:count, discard:].max(axis=1) - runs.low[:count, discard:].min(axis=1)) / 2
    return RunsSummary(exponents, stderr, order, amplitude, eigenvalues, regimes, pairs, divergences, settlings)


#: the regime of a run whose tangent vectors became non-finite while its state did not (an error for the caller:
#: :func:`gearsym.analysis.divergence.run_failure`)
FAILED = "failed"


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
