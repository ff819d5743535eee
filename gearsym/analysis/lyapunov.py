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
from ..codegen import CompiledModel, engine_verb
from ..errors import warn
from ..options import Integration
from .orbits import amplitudes
from .regime import EQUILIBRIUM, classify_regime
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
    run = model.tangent_run(y0, options.periods, inputs)
    discard = options.discard

    measured = run.log_stretch[:, discard:] / inputs.period  # per unit time, each period
    count = measured.shape[1]
    exponents = measured.mean(axis=1)
    stderr = batch_means_stderr(measured)
    history = np.cumsum(measured, axis=1).T / np.arange(1, count + 1)[:, None]
    final = run.strobe[:, -1]
    eigenvalues = _fixed_point_eigenvalues(model, run, discard, p)
    if eigenvalues is not None:  # the exponents of a fixed point, exactly
        exponents, stderr = eigenvalues.real.copy(), np.zeros_like(stderr)
    order = np.argsort(-exponents, kind="stable")
    return LyapunovSpectrum(
        model=model.name,
        parameters=dict(zip(model.parameter_names, map(float, p))),
        exponents=exponents[order],
        stderr=stderr[order],
        history=history[:, order],
        amplitude=amplitudes(model.observed, run.low[:, discard:], run.high[:, discard:]),
        final_state=dict(zip(model.state_names, map(float, final))),
        strobe=run.strobe[:, discard:],
        periods=options.periods,
        discard=discard,
        steps_per_period=model.steps_per_period,
        period=inputs.period,
        backend=model.backend,
        autonomous=model.system.autonomous,
        info={"Q": run.Q, "locate_crossings": model.options.locate_crossings},
        eigenvalues=None if eigenvalues is None else eigenvalues[order],
    )


def _rests(compiled, y: np.ndarray, p: np.ndarray) -> bool:
    """f(y) = 0, to rounding (autonomous systems: any time)."""
    return bool(np.max(np.abs(compiled.rhs(0.0, y, p))) <= AT_REST * (1 + np.max(np.abs(y))))


def _fixed_point_eigenvalues(compiled, run, discard: int, p: np.ndarray) -> np.ndarray | None:
    """The Jacobian's eigenvalues where an autonomous run stayed over its measured periods, if it stayed
    on a fixed point; None otherwise (and always for forced systems, whose fixed points of the
    stroboscopic map are periodic orbits)."""
    if not compiled.system.autonomous:
        return None
    strobe = run.strobe[:, discard:]
    y = strobe[:, -1]
    moved = max(np.ptp(strobe, axis=1).max(), np.max(run.high[:, discard:] - run.low[:, discard:], initial=0.0))
    if moved > AT_REST * (1 + np.max(np.abs(y))) or not _rests(compiled, y, p):
        return None
    return np.linalg.eigvals(compiled.jacobian(0.0, y, p))
