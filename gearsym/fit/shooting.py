"""Fitting parameters to measured windows by multiple shooting, through compiled code.

A gear pair can be chaotic, so one long simulation compared with a long measurement is no fit
criterion: any error in the start or a parameter grows until the two have nothing in common.
Multiple shooting cuts the measurement into one-forcing-period windows and gives each window its
own start state, a free variable of the fit beside the parameters. Within one period trajectories
stay close, so the least-squares problem is smooth, and its exact derivatives come from the
variational equations of the same RK4 (:mod:`gearsym.codegen.windows`: one compiled call computes
every window's outputs and their derivatives by the start state and by every parameter).

What is compared: each measured channel h(tau, y, p) (a state, x_ddot = dv/dtau, a combination:
:mod:`gearsym.data.measurements`) plus, for a channel named in ``bias``, an unknown constant offset
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
from dataclasses import dataclass, field, replace

import numpy as np
import sympy as sp

from ..codegen.windows import Windows, compile_windows
from ..data.measurements import channel_expression
from ..errors import GearsymError
from ..options import Integration
from ..system import FirstOrderSystem

#: a parameter whose direction has a singular value below this fraction of the largest (columns
#: normalised) cannot be told from the others by the data
NULL_SPACE = 1e-6
#: correlations of estimates above this (in absolute value) are flagged
STRONG_CORRELATION = 0.95
#: periods a start state is run in from the model's initial state when the data do not give it
WARM_UP_PERIODS = 60
#: times the fitted start states of windows are carried over to the next window and the fit rerun, where some
#: state is unmeasured (each window then has its own local minima, e.g. an accelerometer in the backlash gap)
POLISH_ROUNDS = 2


@dataclass(frozen=True)
class Segment:
    """What the fit sees of one window: sample times, measured channels and the record's parameters.
    ``channels``: what each observed name measures (states and derivative placeholders); default the
    names are states."""

    tau: np.ndarray  # (S,)
    observed: dict[str, np.ndarray]  # channel name -> (S,)
    parameters: dict[str, float]  # every parameter value of the window's record
    label: str = ""
    channels: Mapping[str, sp.Expr] | None = None
    key: tuple | None = None  # (record, window index): which windows follow each other

    def channel(self, name: str) -> sp.Expr:
        return (self.channels or {}).get(name, sp.Symbol(name, real=True))


@dataclass(frozen=True)
class Fit:
    """The estimates, their standard errors, and what each window looks like under them.

    ``stderr[p]`` is None where ``p`` is not identifiable (``identifiable[p]`` False) or held at a bound
    (``at_bound[p]``: the bound and why it is there). ``correlations``: pairs of estimates correlated
    beyond :data:`STRONG_CORRELATION`. ``bias``: the fitted offset of each biased channel.
    """

    system: FirstOrderSystem
    estimates: dict[str, float]
    stderr: dict[str, float | None]
    starts: np.ndarray  # (n, windows): the fitted start state of each window
    predicted: list[dict[str, np.ndarray]]  # per window: the fitted channels at the samples (bias included)
    residuals: list[dict[str, np.ndarray]]  # per window: measured - fitted, unscaled
    sigma: float  # RMS of the scaled residuals
    success: bool
    iterations: int
    info: dict = field(default_factory=dict)
    states: list[np.ndarray] = field(default_factory=list)  # per window: (n, S) the fitted states
    bias: dict[str, float] = field(default_factory=dict)
    bias_stderr: dict[str, float | None] = field(default_factory=dict)
    identifiable: dict[str, bool] = field(default_factory=dict)
    at_bound: dict[str, tuple[float, str]] = field(default_factory=dict)
    correlations: list[tuple[str, str, float]] = field(default_factory=list)
    covariance: dict[str, dict[str, float]] = field(default_factory=dict)  # of the identifiable estimates


def substeps_for(step: float, period: float, options: Integration) -> int:
    """RK4 steps per sample interval: at least the options' steps per forcing period."""
    return max(1, int(np.ceil(options.steps_per_period * step / period - 1e-9)))


def fit_windows(system: FirstOrderSystem, segments: Sequence[Segment], fit: Sequence[str], *,
                guess: Mapping[str, float] | None = None, starts: np.ndarray | None = None,
                period: float = 2 * np.pi, max_iterations: int = 200, options: Integration = Integration(),
                bias: Sequence[str] = (), bounds: Mapping[str, tuple] | None = None,
                guess_bias: Mapping[str, float] | None = None) -> Fit:
    """Estimate the parameters ``fit`` (every window's start state, and the offsets of the channels named in
    ``bias``) from ``segments``.

    ``guess``: starting values of the fitted parameters (default: the segments' own values).
    ``starts``: starting start states (n x windows; default from the data: measured states at the first
    sample, a finite-difference rate for an unmeasured velocity, else a run of the model).
    ``fit`` may be empty: then only the start states (and biases) are fitted.
    ``bounds``: (low, high[, why]) per fitted parameter, beside the model's own constraints (a damping
    ratio >= 0 ...). ``options``: its steps per period set the RK4 steps between samples, its backend
    where they run.
    """
    if not segments:
        raise GearsymError("nothing to fit: no whole forcing period in the data")
    names = tuple(system.parameters)
    unknown = [p for p in fit if p not in names]
    if unknown:
        raise GearsymError(f"cannot fit {', '.join(unknown)}: not parameters of {system.name} ({', '.join(names)})")
    problem = Problem(system, segments, list(fit), list(bias), period, options)
    theta = np.array([(guess or {}).get(p, segments[0].parameters[p]) for p in fit], dtype=float)
    b0 = np.array([(guess_bias or {}).get(c, 0.0) for c in problem.bias], dtype=float)
    S = np.array(starts if starts is not None else data_starts(problem, theta), dtype=float)
    low, high, why = _bounds(system, fit, bounds or {}, problem.unknowns(S.shape[1]))
    u0 = np.clip(np.concatenate([theta, b0, S.reshape(-1, order="F")]), low, high)
    u, J, r, iterations, converged = _levenberg_marquardt(problem, u0, low, high, max_iterations)
    for _ in range(POLISH_ROUNDS if problem.unmeasured else 0):
        better = _carried_over(problem, u)
        if better is None:
            break
        u, J, r, more, converged = _levenberg_marquardt(problem, better, low, high, max_iterations)
        iterations += more
    return _result(problem, u, J, r, iterations, converged, low, high, why)


class Problem:
    """Scaled residuals of every window and their exact Jacobian, by u = [theta, bias, S[:, 0], S[:, 1], ...]."""

    def __init__(self, system: FirstOrderSystem, segments: Sequence[Segment], fit: list[str], bias: list[str],
                 period: float, options: Integration):
        self.system, self.segments, self.fit, self.period = system, list(segments), fit, period
        self._integrated = None
        self.names = tuple(system.parameters)
        self.index = np.array([self.names.index(p) for p in fit], dtype=int)
        self.n, self.m = system.dimension, len(fit)
        keys = list(dict.fromkeys((name, seg.channel(name)) for seg in segments for name in seg.observed))
        self.channel_names = [k[0] for k in keys]
        self.channel_index = [{name: keys.index((name, seg.channel(name))) for name in seg.observed}
                              for seg in segments]
        missing = [c for c in bias if c not in self.channel_names]
        if missing:
            raise GearsymError(f"bias of {missing[0]}: no such channel in the data ({', '.join(dict.fromkeys(self.channel_names))})")
        self.bias = list(dict.fromkeys(bias))
        twice = [c for c in self.bias if self.channel_names.count(c) > 1]
        if twice:
            raise GearsymError(f"bias of {twice[0]}: the channel measures different things in different files (a "
                               "t file and a tau file?); one offset cannot serve both")
        self.engine: Windows = compile_windows(system, [channel_expression(e, system) for _, e in keys],
                                               options.backend)
        self.scale = {}
        for name in dict.fromkeys(self.channel_names):
            values = np.concatenate([s.observed[name] for s in segments if name in s.observed])
            self.scale[name] = float(np.std(values)) or 1.0
        self.samples = np.array([len(s.tau) for s in segments], dtype=np.int64)
        self.t0 = np.array([float(s.tau[0]) for s in segments])
        self.dt = np.array([float(np.median(np.diff(s.tau))) for s in segments])
        self.substeps = np.array([substeps_for(dt, period, options) for dt in self.dt], dtype=np.int64)
        self.base = np.array([[s.parameters[n] for n in self.names] for s in segments], dtype=float).T
        offsets = np.concatenate([[0], np.cumsum(self.samples)])
        channel, column, window, data, weight, bias_of = [], [], [], [], [], []
        for k, seg in enumerate(segments):
            for name, c in self.channel_index[k].items():
                S = len(seg.tau)
                channel.append(np.full(S, c))
                column.append(offsets[k] + np.arange(S))
                window.append(np.full(S, k))
                data.append(seg.observed[name] / self.scale[name])
                weight.append(np.full(S, 1 / self.scale[name]))
                bias_of.append(np.full(S, self.bias.index(name) if name in self.bias else -1))
        self.rows = (np.concatenate(channel), np.concatenate(column))
        self.window = np.concatenate(window)
        self.data, self.weight = np.concatenate(data), np.concatenate(weight)
        self.bias_of = np.concatenate(bias_of)
        self.offsets = offsets
        self.row_offsets = np.concatenate([[0], np.cumsum(np.bincount(self.window, minlength=self.K))])
        measured = {name for seg in segments for name in seg.observed if seg.channel(name) == sp.Symbol(name, real=True)}
        rates = {f.name: s.name for s, f in zip(system.states, system.rhs) if f.is_Symbol and f in system.states}
        # states neither measured nor the rate of a measured coordinate: their start is only guessed
        self.unmeasured = any(s not in measured and rates.get(s) not in measured for s in system.state_names)

    @property
    def K(self) -> int:
        return len(self.segments)

    def integrated(self) -> list:
        """Per window and coordinate x (with x' = v) measured through its acceleration or rate only: ((row of x,
        row of v), (window, x - mean, v, amplitude of x)) from :func:`from_rate`, computed once."""
        if self._integrated is None:
            names = self.system.state_names
            pairs = [(names.index(s.name), names.index(f.name)) for s, f in zip(self.system.states, self.system.rhs)
                     if f.is_Symbol and f in self.system.states]
            self._integrated = [((i, j), (k, *found)) for k, seg in enumerate(self.segments) for i, j in pairs
                                if (found := from_rate(seg, names[i], self.period)) is not None]
        return self._integrated

    def unknowns(self, windows: int) -> int:
        return self.m + len(self.bias) + self.n * windows

    def split(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        m, nb = self.m, len(self.bias)
        return u[:m], u[m:m + nb], u[m + nb:].reshape(self.n, -1, order="F")

    def parameters(self, theta: np.ndarray) -> np.ndarray:
        P = self.base.copy()
        P[self.index, :] = theta[:, None]
        return P

    def run(self, theta: np.ndarray, S: np.ndarray, tangent: bool):
        return self.engine.run(S, self.t0, self.dt, self.samples, self.substeps, self.parameters(theta), tangent,
                               columns=self.index)

    def __call__(self, u: np.ndarray, jacobian: bool = True):
        theta, b, S = self.split(u)
        run = self.run(theta, S, jacobian)
        offset = np.where(self.bias_of >= 0, b[np.maximum(self.bias_of, 0)] if b.size else 0.0, 0.0)
        r = (run.outputs[self.rows] + offset) * self.weight - self.data
        if not jacobian:
            return r, None
        D = run.derivatives[self.rows[0], :, self.rows[1]] * self.weight[:, None]  # (residuals, n + fitted)
        offsets = np.stack([np.where(self.bias_of == j, self.weight, 0.0) for j in range(len(self.bias))], axis=1) \
            if self.bias else np.zeros((r.size, 0))
        return r, Jacobian(np.hstack([D[:, self.n:], offsets]), D[:, :self.n], self.window,
                           self.row_offsets)


@dataclass(frozen=True)
class Jacobian:
    """The Jacobian of the residuals by u = [theta, bias, S[:, 0], S[:, 1], ...], kept in its structure: the
    columns of the parameters and offsets (``P``, dense) and each residual's derivatives by its own window's
    start state (``S``; the rows of window k are ``rows[k]:rows[k + 1]``). The normal equations are then
    solved by the Schur complement on the parameters: O(windows) work, and small arrays only (threaded BLAS
    on a busy machine made the dense products of the whole J 10x slower)."""

    P: np.ndarray  # (residuals, parameters + offsets)
    S: np.ndarray  # (residuals, n)
    window: np.ndarray  # (residuals,)
    rows: np.ndarray  # (windows + 1,)

    @property
    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.P)) and np.all(np.isfinite(self.S)))

    def blocks(self, X: np.ndarray) -> np.ndarray:
        """Per window, the sum over its rows of ``X`` (rows first)."""
        return np.add.reduceat(X, self.rows[:-1], axis=0)

    def normal(self, r: np.ndarray):
        """U = P^T P, W_k = P_k^T S_k, V_k = S_k^T S_k and the gradients P^T r, S_k^T r."""
        P, S = self.P, self.S
        return (np.einsum("ri,rj->ij", P, P), self.blocks(np.einsum("ri,rj->rij", P, S)),
                self.blocks(np.einsum("ri,rj->rij", S, S)), np.einsum("ri,r->i", P, r),
                self.blocks(S * r[:, None]))

    def project_out(self, Y: np.ndarray) -> np.ndarray:
        """``Y`` (residuals x q) with what the start states and then the parameters' columns can make removed."""
        def out_of_starts(X):
            V = np.linalg.pinv(self.blocks(np.einsum("rn,rm->rnm", self.S, self.S)))
            SX = self.blocks(np.einsum("rn,rq->rnq", self.S, X))
            return X - np.einsum("rn,rnq->rq", self.S, np.einsum("knm,kmq->knq", V, SX)[self.window])

        Y, P = out_of_starts(Y), out_of_starts(self.P)
        if P.shape[1]:
            Y = Y - P @ (np.linalg.pinv(np.einsum("ri,rj->ij", P, P)) @ np.einsum("ri,rq->iq", P, Y))
        return Y


def score_columns(system: FirstOrderSystem, segments: Sequence[Segment], fit: Fit, extra: Sequence[str],
                  bias: Sequence[str], options: Integration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The score test's pieces at ``fit`` with the parameters ``extra`` added at 0: the scaled residual (data -
    model) and the exact sensitivity columns of ``extra``, both with what the fit already moves (its parameters,
    start states and offsets) projected out; and the columns before the projection."""
    fitted = list(fit.estimates)
    problem = Problem(system, segments, fitted + list(extra), list(bias), 2 * np.pi, options)
    theta = np.array([fit.estimates[p] for p in fitted] + [0.0] * len(extra))
    u = np.concatenate([theta, [fit.bias[c] for c in problem.bias], fit.starts.reshape(-1, order="F")])
    r, J = problem(u)
    m = len(fitted)
    columns = J.P[:, m:m + len(extra)]
    nuisance = replace(J, P=np.delete(J.P, np.s_[m:m + len(extra)], axis=1))
    both = nuisance.project_out(np.hstack([-r[:, None], columns]))
    return both[:, 0], both[:, 1:], columns


def _bounds(system: FirstOrderSystem, fit: Sequence[str], given: Mapping[str, tuple], count: int):
    """Lower and upper bounds of every unknown, and why each fitted parameter's are there."""
    low, high, why = np.full(count, -np.inf), np.full(count, np.inf), {}
    for i, name in enumerate(fit):
        if name in given:
            lo, hi, *reason = given[name]
            low[i], high[i] = lo, hi
            why[name] = reason[0] if reason else "bounded"
        elif name in system.constraints:
            low[i] = 0.0
            why[name] = f"{name} is {system.constraints[name].meaning}"
    return low, high, why


def _levenberg_marquardt(problem: Problem, u, low, high, max_iterations: int):
    """Gauss-Newton steps with Marquardt's damping, projected onto the bounds: robust where the backlash makes
    the exact Hessian jump, and it needs only the Jacobian."""
    r, J = problem(u)
    cost, mu = float(r @ r), 1e-3
    converged, iteration = False, 0
    if not (np.isfinite(cost) and J.finite):  # the model does not even run from the first guess
        return u, J, r, iteration, converged
    p = J.P.shape[1]
    for iteration in range(1, max_iterations + 1):
        U, W, V, gP, gS = J.normal(r)
        held = ((u[:p] <= low[:p]) & (gP > 0)) | ((u[:p] >= high[:p]) & (gP < 0))  # the descent would leave the box
        while True:
            try:
                step = _damped_step(U, W, V, gP, gS, mu, ~held)
            except np.linalg.LinAlgError:
                step = None
            if step is None or not np.all(np.isfinite(step)):
                mu *= 10
                if mu > 1e12:
                    return u, J, r, iteration, converged
                continue
            u_new = np.clip(u + step, low, high)
            r_new, J_new = problem(u_new)
            new_cost = float(r_new @ r_new) if np.all(np.isfinite(r_new)) and J_new.finite else np.inf
            if new_cost < cost:
                break
            mu *= 10
            if mu > 1e12:
                return u, J, r, iteration, True  # no step lowers the cost: a (bounded) minimum
        gain = cost - new_cost
        moved = np.max(np.abs(u_new - u))
        u, r, J, cost = u_new, r_new, J_new, new_cost
        mu = max(mu / 3, 1e-9)
        if gain <= 1e-12 * max(cost, 1e-300) or moved < 1e-10:
            converged = True
            break
    return u, J, r, iteration, converged


def _damped_step(U, W, V, gP, gS, mu: float, free: np.ndarray) -> np.ndarray:
    """The Levenberg-Marquardt step for [parameters (the ``free`` ones), start states] from the normal equations'
    blocks, by the Schur complement on the parameters (the start-state blocks are n x n per window)."""
    n = V.shape[1]
    dV = np.maximum(np.diagonal(V, axis1=1, axis2=2), 1e-12)
    Vinv = np.linalg.inv(V + mu * dV[:, :, None] * np.eye(n))
    dP = np.zeros(U.shape[0])
    if free.any():
        Uf, Wf = U[np.ix_(free, free)], W[:, free, :]
        WVi = np.einsum("kpn,knm->kpm", Wf, Vinv)
        schur = Uf + mu * np.diag(np.maximum(np.diag(Uf), 1e-12)) - np.einsum("kpm,kqm->pq", WVi, Wf)
        dP[free] = -np.linalg.solve(schur, gP[free] - np.einsum("kpm,km->p", WVi, gS))
    dS = -np.einsum("knm,km->kn", Vinv, gS + np.einsum("kpn,p->kn", W, dP))
    return np.concatenate([dP, dS.reshape(-1)])


def _result(problem: Problem, u, J, r, iterations, converged, low, high, why) -> Fit:
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
    stderr, identifiable, correlations, covariance = _uncertainty(J, r, sigma2, names, held)
    estimates = dict(zip(problem.fit, map(float, theta)))
    for name in at:
        stderr[name] = None
    run = problem.run(theta, S, False)
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


def _uncertainty(J: Jacobian, r: np.ndarray, sigma2: float, names: list[str], held: np.ndarray):
    """Standard errors (None: not identifiable), identifiability, strong correlations and the covariance of the
    parameters and offsets ``names`` (those ``held`` at a bound left out), with the start states profiled out:
    the information matrix on them is the Schur complement U - sum_k W_k V_k^+ W_k^T."""
    free_names = [n for n, h in zip(names, held) if not h]
    p = len(free_names)
    if not J.finite or not np.isfinite(sigma2):  # a fit that went nowhere: nothing is determined
        return {n: None for n in names}, {n: False for n in names}, [], {}
    U, W, V, _, _ = J.normal(r)
    free = ~np.asarray(held, dtype=bool)
    U, W = U[np.ix_(free, free)], W[:, free, :]
    info = U - np.einsum("kpn,knm,kqm->pq", W, np.linalg.pinv(V), W)
    norms = np.sqrt(np.maximum(np.diag(U), 0.0))
    scale = np.where(norms > 0, norms, 1.0)
    eigenvalues, vectors = np.linalg.eigh(info / np.outer(scale, scale))
    top = max(float(eigenvalues.max(initial=0.0)), 1e-300)
    null = eigenvalues < NULL_SPACE**2 * top  # the column-normalised J's singular values below NULL_SPACE
    weight = (vectors[:, null] ** 2).sum(axis=1)
    bad = (norms <= 1e-300) | (weight > 0.5)
    inverse = np.where(null, 0.0, 1 / np.where(null, 1.0, eigenvalues))
    cov = sigma2 * (vectors * inverse) @ vectors.T / np.outer(scale, scale)
    stderr = {n: None for n in names}
    identifiable = {n: False for n in names}
    for i, name in enumerate(free_names):
        identifiable[name] = not bool(bad[i])
        stderr[name] = float(np.sqrt(max(cov[i, i], 0.0))) if identifiable[name] else None
    covariance = {a: {b: float(cov[i, j]) for j, b in enumerate(free_names) if identifiable[b]}
                  for i, a in enumerate(free_names) if identifiable[a]}
    correlations = []
    for i in range(p):
        for j in range(i + 1, p):
            if bad[i] or bad[j] or cov[i, i] <= 0 or cov[j, j] <= 0:
                continue
            rho = cov[i, j] / np.sqrt(cov[i, i] * cov[j, j])
            if abs(rho) > STRONG_CORRELATION:
                correlations.append((free_names[i], free_names[j], float(rho)))
    return stderr, identifiable, correlations, covariance


def data_starts(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """Start states from the data: a measured state's first sample; an unmeasured velocity v of a measured
    coordinate x (dx/dtau = v) from a finite difference; any other state from a run of the model (at the
    guessed parameters) from its initial state, ``WARM_UP_PERIODS`` periods up to the window's start, or,
    where a coordinate's acceleration is measured, from its integral (:func:`_integrated`): per window, the
    guess that fits the window best."""
    system = problem.system
    names = system.state_names
    rates = {}
    for i, s in enumerate(system.states):
        rate = system.rhs[i]
        if rate.is_Symbol and rate in system.states:
            rates[rate.name] = s.name
    out = np.full((problem.n, problem.K), np.nan)
    for k, seg in enumerate(problem.segments):
        dt = problem.dt[k]
        for i, name in enumerate(names):
            if name in seg.observed and seg.channel(name) == sp.Symbol(name, real=True):
                out[i, k] = seg.observed[name][0]
            elif name in rates and rates[name] in seg.observed and \
                    seg.channel(rates[name]) == sp.Symbol(rates[name], real=True):
                x = seg.observed[rates[name]]
                out[i, k] = (-3 * x[0] + 4 * x[1] - x[2]) / (2 * dt)
    if np.isnan(out).any():
        free = np.where(np.isnan(out), _free_run(problem, theta), out)
        out = _best_of(problem, theta, [free, *_integrated(problem, free, np.isnan(out))])
    return out


def _carried_over(problem: Problem, u: np.ndarray) -> np.ndarray | None:
    """``u`` with the start of each window replaced, where that fits the window better, by its predecessor's fitted
    start run on to it (a window in a wrong local minimum takes over its neighbour's good one) or by the first
    guesses of :func:`data_starts` made again at the fitted parameters; None if no window gains."""
    theta, b, S = problem.split(u)
    follows = [k for k in range(1, problem.K) if problem.segments[k].key and problem.segments[k - 1].key
               and problem.segments[k].key[0] == problem.segments[k - 1].key[0]
               and problem.segments[k].key[1] == problem.segments[k - 1].key[1] + 1]
    if not follows:
        return None
    prev = np.array(follows) - 1
    dt = problem.t0[follows] - problem.t0[prev]
    steps = np.maximum(1, np.ceil(problem.substeps[prev] * dt / problem.dt[prev])).astype(np.int64)
    run = problem.engine.run(S[:, prev], problem.t0[prev], dt, np.full(len(follows), 2), steps,
                             problem.parameters(theta)[:, prev], tangent=False)
    carried = S.copy()
    carried[:, follows] = run.states[:, 1::2]
    unknown = np.ones_like(S, dtype=bool)  # every state may be in a wrong minimum: fresh guesses at these values
    free = _free_run(problem, theta)
    best = _best_of(problem, theta, [S, carried, free, *_integrated(problem, free, unknown)], b)
    if np.array_equal(best, S):
        return None
    m, nb = problem.m, len(problem.bias)
    return np.concatenate([u[:m + nb], best.reshape(-1, order="F")])


def _integrated(problem: Problem, free: np.ndarray, unknown: np.ndarray) -> list[np.ndarray]:
    """More first guesses where a coordinate x is unmeasured but its acceleration (or rate) is: x and v at each
    window's start from the window's Fourier series integrated in time (one period: the oscillating part), the
    mean of x, which the integral cannot give, tried at several offsets around the model's run."""
    known = problem.integrated()
    if not known:
        return []
    guesses = []
    for offset in np.linspace(-1.0, 1.0, 9):
        guess = free.copy()
        for (i, j), (k, x0, v0, amplitude) in known:
            if unknown[i, k]:
                guess[i, k] = free[i, k] + x0 + offset * (2 * amplitude + 1)
            if unknown[j, k]:
                guess[j, k] = v0
        guesses.append(guess)
    return guesses


def from_rate(seg: Segment, name: str, period: float):
    """(x - mean, v, amplitude of x) at the window's first sample from its x_ddot (or x_dot) channel, if it has one
    that is a multiple of the derivative alone; None otherwise."""
    for suffix, order in (("_ddot", 2), ("_dot", 1)):
        placeholder = sp.Symbol(name + suffix, real=True)
        channel = next((c for c in seg.observed if seg.channel(c).free_symbols == {placeholder}
                        and sp.diff(seg.channel(c), placeholder, 2) == 0), None)
        if channel is None:
            continue
        scale = float(sp.diff(seg.channel(channel), placeholder))
        rate = seg.observed[channel] / scale
        t = seg.tau - seg.tau[0]
        w = 2 * np.pi / period
        n = np.arange(1, max(1, min(8, len(t) // 2 - 1)) + 1)
        A = np.hstack([np.ones((t.size, 1)), np.cos(np.outer(t, n * w)), np.sin(np.outer(t, n * w))])
        coef = np.linalg.lstsq(A, rate, rcond=None)[0]
        a, b = coef[1:n.size + 1], coef[n.size + 1:]
        nw = n * w
        if order == 2:  # x'' = sum a cos + b sin: v = sum (a sin - b cos)/nw, x = -sum (a cos + b sin)/nw^2
            return float(-np.sum(a / nw**2)), float(-np.sum(b / nw)), float(np.sum(np.hypot(a, b) / nw**2))
        return float(-np.sum(b / nw)), float(rate[0]), float(np.sum(np.hypot(a, b) / nw))
    return None


def _best_of(problem: Problem, theta: np.ndarray, guesses: list[np.ndarray], offsets=None) -> np.ndarray:
    """Per window, the guess whose model run fits the window's samples best (parameters at ``theta``); the first
    guess unless another is better by more than rounding."""
    if len(guesses) == 1:
        return guesses[0]
    cost = []
    offsets = np.zeros(len(problem.bias)) if offsets is None else offsets
    for S in guesses:
        r, _ = problem(np.concatenate([theta, offsets, S.reshape(-1, order="F")]), jacobian=False)
        r = np.where(np.isfinite(r), r, 1e300)
        cost.append(np.bincount(problem.window, r * r, minlength=problem.K))
    cost = np.array(cost)
    best = np.argmin(cost, axis=0)
    best[cost[best, np.arange(problem.K)] >= cost[0] * (1 - 1e-9)] = 0
    return np.column_stack([guesses[b][:, k] for k, b in enumerate(best)])


def _free_run(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """The model's state at each window's first sample: one run per record from the model's initial state,
    ``WARM_UP_PERIODS`` periods before the record's first window and on through its windows, then a hop of a
    fraction of a sample step to each window's first sample."""
    period, K = problem.period, problem.K
    records = [seg.key[0] if seg.key else k for k, seg in enumerate(problem.segments)]
    firsts = list(dict.fromkeys(records))
    first = np.array([records.index(r) for r in firsts])
    whole = np.array([np.round((problem.t0[k] - problem.t0[first[firsts.index(records[k])]]) / period)
                      for k in range(K)], dtype=np.int64)
    count = np.array([max(whole[k] for k in range(K) if records[k] == r) for r in firsts], dtype=np.int64)
    steps = np.ceil(problem.substeps[first] * period / problem.dt[first]).astype(np.int64)
    y0 = np.tile(np.array(problem.system.initial_vector)[:, None], (1, len(firsts)))
    P = problem.parameters(theta)
    samples = WARM_UP_PERIODS + count + 1
    run = problem.engine.run(y0, problem.t0[first] - WARM_UP_PERIODS * period, np.full(len(firsts), period),
                             samples, steps, P[:, first], tangent=False)
    offsets = np.concatenate([[0], np.cumsum(samples)])
    which = np.array([firsts.index(r) for r in records])
    nodes = run.states[:, offsets[which] + WARM_UP_PERIODS + whole]
    hop = problem.t0 - (problem.t0[first[which]] + whole * period)
    if not np.any(hop):
        return nodes
    hopped = problem.engine.run(nodes, problem.t0 - hop, np.where(hop == 0, 1e-300, hop), np.full(K, 2),
                                np.ones(K, dtype=np.int64), P, tangent=False)
    return np.where(hop == 0, nodes, hopped.states[:, 1::2])


def simulate_segment(system: FirstOrderSystem, seg: Segment, start, estimates: Mapping[str, float] | None = None,
                     period: float = 2 * np.pi, samples: int | None = None,
                     options: Integration = Integration()) -> np.ndarray:
    """The states at ``seg``'s sample times (or ``samples`` of them) from ``start`` (n x samples)."""
    values = {**seg.parameters, **(estimates or {})}
    dt = float(np.median(np.diff(seg.tau)))
    engine = compile_windows(system, [], options.backend)
    run = engine.run(np.asarray(start, float)[:, None], [float(seg.tau[0])], [dt], [samples or len(seg.tau)],
                     [substeps_for(dt, period, options)],
                     np.array([[values[n] for n in system.parameters]]).T, tangent=False)
    return run.states
