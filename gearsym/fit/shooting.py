"""Fitting parameters to measured windows by multiple shooting, through compiled code.

A gear pair can be chaotic, so one long simulation compared with a long measurement is no fit
criterion: any error in the start or a parameter grows until the two have nothing in common.
Multiple shooting cuts the measurement into one-forcing-period windows and gives each window its
own start state, a free variable of the fit beside the parameters. Within one period trajectories
stay close, so the least-squares problem is smooth, and its exact derivatives come from the
variational equations of the same RK4 (:mod:`gearsym.codegen.windows`: one compiled call computes
every window's outputs and their derivatives by the start state and by every parameter).

What is compared: each measured channel h(tau, y, p) (a state, x_ddot = dv/dtau, a combination:
:mod:`gearsym.data.channels`) plus, for a channel named in ``bias``, an unknown constant offset
estimated with the fit (an accelerometer's). Residuals are scaled per channel by its standard
deviation, so channels of different size count alike.

The minimiser is Levenberg-Marquardt, projected onto the parameters' bounds (the physical signs of
:mod:`.effects` and of the model's constraints): a parameter at a bound that the gradient pushes
outward is held there for the step. Uncertainties are the Gauss-Newton ones, sigma^2 (J^T J)^-1 with
sigma^2 = RSS / (residuals - unknowns); a parameter whose column of J is zero, or lies in the
(numerical) null space of the normalised J, is *not identifiable*: reported as such, never as 0 +- 0.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import GearsymError
from ..options import Integration
from ..system import FirstOrderSystem
from .levenberg_marquardt import levenberg_marquardt
from .problem import Problem
from .result import Fit
from .segment import Segment, simulate_segment, substeps_for
from .starts import carried_over, data_starts
from .uncertainty import uncertainty

#: times the fitted start states of windows are carried over to the next window and the fit rerun, where some
#: state is unmeasured (each window then has its own local minima, e.g. an accelerometer in the backlash gap)
POLISH_ROUNDS = 2

#: (Fit, Segment, simulate_segment and substeps_for were defined here before the fit was split into one file per
#: idea, and stay importable from here)
__all__ = ["Fit", "POLISH_ROUNDS", "Segment", "fit_windows", "simulate_segment", "substeps_for"]


def fit_windows(system: FirstOrderSystem, segments: Sequence[Segment], fit: Sequence[str], *,
                guess: Mapping[str, float] | None = None, starts: np.ndarray | None = None,
                period: float = 2 * np.pi, max_iterations: int = 200, options: Integration = Integration(),
                bias: Sequence[str] = (), bounds: Mapping[str, tuple] | None = None,
                guess_bias: Mapping[str, float] | None = None, slots: Sequence = (),
                ridge: Mapping[str, float] | None = None) -> Fit:
    """Estimate the parameters ``fit`` (every window's start state, and the offsets of the channels named in
    ``bias``) from ``segments``.

    ``guess``: starting values of the fitted parameters (default: the segments' own values).
    ``starts``: starting start states (n x windows; default from the data: measured states at the first
    sample, a finite-difference rate for an unmeasured velocity, else a run of the model).
    ``fit`` may be empty: then only the start states (and biases) are fitted.
    ``bounds``: (low, high[, why]) per fitted parameter, beside the model's own constraints (a damping
    ratio >= 0 ...). ``options``: its steps per period set the RK4 steps between samples, its backend
    where they run. ``slots``: tooth-by-tooth forms (:class:`gearsym.fit.tooth_forms.Slots`), whose per-tooth
    parameters ``fit`` may name. ``ridge``: per fitted parameter, a weight w: the cost gains w theta^2 (a Gaussian
    prior of spread sigma / sqrt(w) around 0, sigma the residuals' noise), and the uncertainties are the posterior's.
    """
    if not segments:
        raise GearsymError("nothing to fit: no whole forcing period in the data")
    names = tuple(system.parameters)
    twice = [p for i, p in enumerate(fit) if p in fit[:i]]
    if twice:
        raise GearsymError(f"{twice[0]} is named twice among the parameters to fit; name each once")
    per_tooth = {name for sl in slots for name in sl.teeth_names}
    unknown = [p for p in fit if p not in names and p not in per_tooth]
    if unknown:
        raise GearsymError(f"cannot fit {', '.join(unknown)}: not parameters of {system.name} ({', '.join(names)})")
    problem = Problem(system, segments, list(fit), list(bias), period, options, slots)
    theta = np.array([(guess or {}).get(p, segments[0].parameters.get(p, 0.0)) for p in fit], dtype=float)
    b0 = np.array([(guess_bias or {}).get(c, 0.0) for c in problem.bias], dtype=float)
    S = np.array(starts if starts is not None else data_starts(problem, theta), dtype=float)
    low, high, why = _bounds(system, fit, bounds or {}, problem.unknowns(S.shape[1]))
    u0 = np.clip(np.concatenate([theta, b0, S.reshape(-1, order="F")]), low, high)
    weights = np.array([float((ridge or {}).get(p, 0.0)) for p in fit] + [0.0] * len(problem.bias))
    u, J, r, iterations, converged = levenberg_marquardt(problem, u0, low, high, max_iterations, weights)
    for _ in range(POLISH_ROUNDS if problem.unmeasured else 0):
        better = carried_over(problem, u)
        if better is None:
            break
        u, J, r, more, converged = levenberg_marquardt(problem, better, low, high, max_iterations, weights)
        iterations += more
    return _result(problem, u, J, r, iterations, converged, low, high, why, weights)


def _bounds(system: FirstOrderSystem, fit: Sequence[str], given: Mapping[str, tuple], count: int):
    """Lower and upper bounds of every unknown, and why each fitted parameter's are there."""
    low, high, why = np.full(count, -np.inf), np.full(count, np.inf), {}
    for i, name in enumerate(fit):
        if name in given:
            lo, hi, *reason = given[name]
            low[i], high[i] = lo, hi
            why[name] = reason[0] if reason else "bounded"
        elif name in system.constraints:
            constraint = system.constraints[name]
            low[i] = 0.0
            if constraint.below is not None:  # (exclusive: the largest double below it)
                high[i] = np.nextafter(constraint.below, 0.0)
            why[name] = f"{name} is {constraint.meaning}"
    return low, high, why


def _result(problem: Problem, u, J, r, iterations, converged, low, high, why, ridge) -> Fit:
    theta, b, S = problem.split(u)
    nb = len(problem.bias)
    names = [*problem.fit, *(f"bias:{c}" for c in problem.bias)]
    tol = 1e-12 * np.maximum(1.0, np.abs(u))
    at = {}
    for i, name in enumerate(problem.fit):
        for bound, side in ((low[i], u[i] - low[i]), (high[i], high[i] - u[i])):
            if np.isfinite(bound) and side <= tol[i]:
                at[name] = (float(bound), why.get(name, "bounded"))
    held = np.array([n in at for n in problem.fit] + [False] * nb, dtype=bool)
    dof = max(1, r.size - int((~held).sum()) - S.size)
    sigma2 = float(r @ r) / dof
    stderr, identifiable, correlations, covariance = uncertainty(J, r, sigma2, names, held, ridge)
    estimates = dict(zip(problem.fit, map(float, theta)))
    for name in at:
        stderr[name] = None
    run = problem.run_at(u)  # (the run that ended the fit, kept by the problem)
    predicted, residuals, states = [], [], []
    for k, seg in enumerate(problem.segments):
        cols = slice(problem.offsets[k], problem.offsets[k + 1])
        out = {name: run.outputs[c, cols] + (b[problem.bias.index(name)] if name in problem.bias else 0.0)
               for name, c in problem.channel_index[k].items()}
        predicted.append(out)
        residuals.append({name: seg.observed[name] - out[name] for name in seg.observed})
        states.append(run.states[:, cols])
    return Fit(problem.system, estimates, {n: stderr[n] for n in problem.fit}, S, predicted, residuals,
               float(np.sqrt(sigma2)), converged, iterations,
               {"residuals": int(r.size), "unknowns": int(u.size)}, states,
               dict(zip(problem.bias, map(float, b))), {c: stderr[f"bias:{c}"] for c in problem.bias},
               {n: identifiable[n] for n in problem.fit if n not in at}, at, correlations, covariance)
