"""First guesses of each window's start state: from the data where they give it, else from runs of the model (warmed
up from its initial state, carried over from the previous window, or integrated from a measured acceleration), per
window the one that fits best."""
from __future__ import annotations

import numpy as np
import sympy as sp

from .problem import Problem

#: periods a start state is run in from the model's initial state when the data do not give it
WARM_UP_PERIODS = 60


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


def carried_over(problem: Problem, u: np.ndarray) -> np.ndarray | None:
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
