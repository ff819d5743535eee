"""Fitting parameters to measured windows by multiple shooting (CasADi + IPOPT).

A gear pair can be chaotic, so one long simulation compared with a long
measurement is no fit criterion: any error in the start or a parameter grows
until the two have nothing in common. Multiple shooting cuts the measurement
into one-forcing-period windows and gives each window its own start state, a
free variable of the fit beside the parameters. Within one period trajectories
stay close, so the least-squares problem is smooth, and its exact derivatives
come from CasADi's automatic differentiation of the model's own equations
(the same SymPy -> CasADi translation the compiled engine uses).

Residuals are scaled per measured coordinate by its standard deviation, so
coordinates of different size count alike. Uncertainties are the Gauss-Newton
ones: sigma^2 (J^T J)^-1 with sigma^2 = RSS / (residuals - unknowns).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..codegen.functions import SystemSymbols, rk4_step
from ..errors import GearsymError
from ..options import Integration
from ..system import FirstOrderSystem



@dataclass(frozen=True)
class Segment:
    """What the fit sees of one window: sample times, measured values and the record's parameters."""

    tau: np.ndarray  # (S,)
    observed: dict[str, np.ndarray]  # name -> (S,)
    parameters: dict[str, float]  # every parameter value of the window's record
    label: str = ""


@dataclass(frozen=True)
class Fit:
    """The estimates, their standard errors, and what each window looks like under them."""

    system: FirstOrderSystem
    estimates: dict[str, float]
    stderr: dict[str, float]
    starts: np.ndarray  # (n, windows): the fitted start state of each window
    predicted: list[dict[str, np.ndarray]]  # per window: the fitted trajectory at the samples
    residuals: list[dict[str, np.ndarray]]  # per window: measured - fitted, unscaled
    sigma: float  # RMS of the scaled residuals
    success: bool
    iterations: int
    info: dict = field(default_factory=dict)


class _Model:
    """The model's equations in CasADi, and a window integrator for a given number of samples."""

    def __init__(self, system: FirstOrderSystem):
        self.system = system
        self.names = tuple(system.parameters)
        self.states = tuple(s.name for s in system.states)
        sym = SystemSymbols.of(system)
        self.rhs = ca.Function("rhs", [sym.t, sym.y, sym.p], [sym.rhs(system)])
        self._windows: dict[tuple[int, int], ca.Function] = {}

    def window(self, samples: int, substeps: int) -> ca.Function:
        """(start state, first sample time, sample step, p) -> states at the ``samples`` sample times,
        ``substeps`` steps of the engine's RK4 between samples."""
        key = (samples, substeps)
        if key not in self._windows:
            n = self.system.dimension
            y0, t0, dt, p = ca.SX.sym("y0", n), ca.SX.sym("t0"), ca.SX.sym("dt"), ca.SX.sym("p", len(self.names))
            h = dt / substeps
            y, t, cols = y0, t0, [y0]

            def f(x, time):
                return self.rhs(time, x, p)

            for _ in range(samples - 1):
                for _ in range(substeps):
                    y, _ = rk4_step(f, None, y, None, h, t, t + h / 2, t + h)
                    t = t + h
                cols.append(y)
            self._windows[key] = ca.Function(f"window{samples}", [y0, t0, dt, p], [ca.horzcat(*cols)])
        return self._windows[key]


_MODELS: dict[tuple, _Model] = {}


def _model(system: FirstOrderSystem) -> _Model:
    """One _Model per distinct set of equations (building the window integrators is the slow part)."""
    key = (system.name, system.time, system.states, system.rhs, tuple(system.parameters))
    if key not in _MODELS:
        _MODELS[key] = _Model(system)
    return _MODELS[key]


def substeps_for(step: float, period: float, options: Integration) -> int:
    """RK4 steps per sample interval: at least the options' steps per forcing period."""
    return max(1, int(np.ceil(options.steps_per_period * step / period - 1e-9)))


def fit_windows(system: FirstOrderSystem, segments: Sequence[Segment], fit: Sequence[str], *,
                guess: Mapping[str, float] | None = None, starts: np.ndarray | None = None,
                period: float = 2 * np.pi, max_iterations: int = 200, options: Integration = Integration()) -> Fit:
    """Estimate the parameters ``fit`` (and every window's start state) from ``segments``.

    ``guess``: starting values of the fitted parameters (default: the segments' own values).
    ``starts``: starting start states (n x windows; default from the data: the measured states at
    the first sample, a finite-difference rate for an unmeasured velocity, 0 otherwise).
    ``fit`` may be empty: then only the start states are fitted (the parameters are known).
    ``options``: its steps per period set the RK4 steps between samples (the windows are plain RK4).
    """
    if not segments:
        raise GearsymError("nothing to fit: no whole forcing period in the data")
    model = _model(system)
    unknown = [p for p in fit if p not in model.names]
    if unknown:
        raise GearsymError(f"cannot fit {', '.join(unknown)}: not parameters of {system.name} "
                           f"({', '.join(model.names)})")
    problem = _Problem(model, segments, list(fit), period, options)
    theta = np.array([(guess or {}).get(p, segments[0].parameters[p]) for p in fit], dtype=float)
    S = np.array(starts if starts is not None else _data_starts(model, segments), dtype=float)
    theta, S, J, r, iterations, converged = _levenberg_marquardt(problem, theta, S, max_iterations)
    m = len(fit)
    dof = max(1, r.size - J.shape[1])
    sigma2 = float(r @ r) / dof
    err = np.sqrt(np.maximum(np.diag(sigma2 * np.linalg.pinv(J.T @ J))[:m], 0.0))
    estimates = dict(zip(fit, map(float, theta)))
    predicted, resid = _evaluate(model, segments, estimates, S, period, options)
    return Fit(system, estimates, dict(zip(fit, map(float, err))), S, predicted, resid, float(np.sqrt(sigma2)),
               converged, iterations, {"residuals": int(r.size), "unknowns": int(J.shape[1])})


class _Problem:
    """Scaled residuals of every window and their exact Jacobian (CasADi forward derivatives)."""

    def __init__(self, model: _Model, segments: Sequence[Segment], fit: list[str], period: float,
                 options: Integration):
        self.model, self.segments, self.fit = model, segments, fit
        self.index = [model.names.index(p) for p in fit]
        observed = sorted({k for s in segments for k in s.observed}, key=model.states.index)
        self.scale = {k: float(np.std(np.concatenate([s.observed[k] for s in segments if k in s.observed]))) or 1.0
                      for k in observed}
        self.calls = []
        for seg in segments:
            dt = float(np.median(np.diff(seg.tau)))
            rows = [model.states.index(k) for k in seg.observed]
            f = _window_jacobian(model, len(seg.tau), substeps_for(dt, period, options))
            data = np.concatenate([seg.observed[k] / self.scale[k] for k in seg.observed])
            weights = np.concatenate([np.full(len(seg.tau), 1 / self.scale[k]) for k in seg.observed])
            base = np.array([seg.parameters[n] for n in model.names], dtype=float)
            self.calls.append((f, float(seg.tau[0]), dt, rows, data, weights, base))

    def __call__(self, theta: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residuals (model - data, scaled) and the Jacobian by [theta, S[:, 0], S[:, 1], ...]."""
        n, K, m = S.shape[0], S.shape[1], len(theta)
        blocks_r, rows_J = [], []
        for k, (f, t0, dt, rows, data, weights, base) in enumerate(self.calls):
            p = base.copy()
            p[self.index] = theta
            Y, dY_dy0, dY_dp = (np.array(a) for a in f(S[:, k], t0, dt, p))
            samples = Y.shape[1]
            sel = np.concatenate([np.arange(samples) * n + row for row in rows])  # vec(Y) is column-major
            blocks_r.append(Y.reshape(-1, order="F")[sel] * weights - data)
            Jk = np.zeros((sel.size, m + n * K))
            Jk[:, :m] = dY_dp[sel][:, self.index] * weights[:, None]
            Jk[:, m + n * k:m + n * (k + 1)] = dY_dy0[sel] * weights[:, None]
            rows_J.append(Jk)
        return np.concatenate(blocks_r), np.vstack(rows_J)


def _window_jacobian(model: _Model, samples: int, substeps: int) -> ca.Function:
    key = ("jac", samples, substeps)
    if key not in model._windows:
        W = model.window(samples, substeps)
        y0, t0, dt, p = ca.SX.sym("y0", model.system.dimension), ca.SX.sym("t0"), ca.SX.sym("dt"), \
            ca.SX.sym("p", len(model.names))
        Y = ca.vec(W(y0, t0, dt, p))
        model._windows[key] = ca.Function("window_jacobian", [y0, t0, dt, p],
                                          [ca.reshape(Y, model.system.dimension, samples),
                                           ca.jacobian(Y, y0), ca.jacobian(Y, p)])
    return model._windows[key]


def _levenberg_marquardt(problem: _Problem, theta, S, max_iterations: int):
    """Gauss-Newton steps with Marquardt's damping: robust where the backlash makes the exact
    Hessian jump, and it needs only the Jacobian."""
    m = theta.size
    r, J = problem(theta, S)
    cost, mu = float(r @ r), 1e-3
    converged, iteration = False, 0
    for iteration in range(1, max_iterations + 1):
        A, b = J.T @ J, J.T @ r
        diag = np.maximum(np.diag(A), 1e-12)
        while True:
            try:
                step = -np.linalg.solve(A + mu * np.diag(diag), b)
            except np.linalg.LinAlgError:
                mu *= 10
                continue
            t_new, S_new = theta + step[:m], S + step[m:].reshape(S.shape, order="F")
            r_new, J_new = problem(t_new, S_new)
            new_cost = float(r_new @ r_new) if np.all(np.isfinite(r_new)) else np.inf
            if new_cost < cost:
                break
            mu *= 10
            if mu > 1e12:
                return theta, S, J, r, iteration, converged
        gain = cost - new_cost
        theta, S, r, J, cost = t_new, S_new, r_new, J_new, new_cost
        mu = max(mu / 3, 1e-9)
        if gain <= 1e-12 * max(cost, 1e-300) or np.max(np.abs(step)) < 1e-10:
            converged = True
            break
    return theta, S, J, r, iteration, converged


def _evaluate(model: _Model, segments, estimates, starts, period, options: Integration):
    predicted, resid = [], []
    for k, seg in enumerate(segments):
        Y = simulate_segment(model.system, seg, starts[:, k], estimates, period, options=options)
        predicted.append({name: Y[model.states.index(name)] for name in seg.observed})
        resid.append({name: seg.observed[name] - predicted[-1][name] for name in seg.observed})
    return predicted, resid


def simulate_segment(system: FirstOrderSystem, seg: Segment, start, estimates: Mapping[str, float] | None = None,
                     period: float = 2 * np.pi, samples: int | None = None,
                     options: Integration = Integration()) -> np.ndarray:
    """The states at ``seg``'s sample times (or ``samples`` of them) from ``start`` (n x samples)."""
    model = _model(system)
    values = {**seg.parameters, **(estimates or {})}
    dt = float(np.median(np.diff(seg.tau)))
    samples = samples or len(seg.tau)
    out = model.window(samples, substeps_for(dt, period, options))(np.asarray(start, float), float(seg.tau[0]), dt,
                                                         [values[n] for n in model.names])
    return np.array(out)


def _data_starts(model: _Model, segments: Sequence[Segment]) -> np.ndarray:
    """Start states from the data: measured values at the first sample; an unmeasured velocity v of a
    measured coordinate x (dx/dtau = v) from a finite difference; anything else 0."""
    rates = {}
    for i, s in enumerate(model.system.states):
        rate = model.system.rhs[i]
        if rate.is_Symbol and rate in model.system.states:
            rates[rate.name] = s.name
    out = np.zeros((model.system.dimension, len(segments)))
    for k, seg in enumerate(segments):
        dt = float(np.median(np.diff(seg.tau)))
        for i, name in enumerate(model.states):
            if name in seg.observed:
                out[i, k] = seg.observed[name][0]
            elif name in rates and rates[name] in seg.observed:
                x = seg.observed[rates[name]]
                out[i, k] = (-3 * x[0] + 4 * x[1] - x[2]) / (2 * dt)
    return out
