"""Held-out error: how well a fitted model predicts one forcing period ahead.

For each pair of consecutive held-out windows (k, k+1) of a record, the state at the start of
window k is estimated from window k's samples alone (parameters and channel offsets fixed at the
fit), the model is run on through window k+1 (the record's samples continue on one even grid, so
window k+1 may hold one sample more or less than window k), and its outputs there are compared
with the measurement. The error is the normalised RMS: per measured channel,
RMS(prediction - measurement) / std(measurement), averaged over the channels. None of the
held-out samples enters the parameter fit, so an effect that only fits noise does not lower it.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .problem import Problem
from .segment import Segment, substeps_for
from .shooting import fit_windows


@dataclass(frozen=True)
class Prediction:
    """The held-out error and what it is made of (for the residual figures)."""

    error: float  # normalised RMS over all predicted samples, averaged over channels
    tau: np.ndarray  # the predicted samples' times
    measured: dict[str, np.ndarray]
    predicted: dict[str, np.ndarray]
    states: np.ndarray  # (n, samples): the model's states along the prediction
    pairs: int
    errors: dict[str, float] | None = None  # per channel
    windows: tuple[tuple[str, int], ...] = ()  # per predicted window, in order: its label and sample count

    def shown(self, limit: int = 3) -> tuple[int, str]:
        """(samples, what they are) of the first ``limit`` predicted windows of the first record: what a
        figure of the prediction shows, e.g. 'measured.csv record 1 (omega=1.2), periods 13-15'."""
        if not self.windows:
            return min(len(self.tau), limit * len(self.tau) // max(self.pairs, 1)), "the held-out data"
        record = self.windows[0][0].rpartition(" period ")[0]
        same = [(label, n) for label, n in self.windows[:limit] if label.rpartition(" period ")[0] == record]
        first, last = same[0][0].rpartition(" period ")[2], same[-1][0].rpartition(" period ")[2]
        periods = f"period {first}" if first == last else f"periods {first}-{last}"
        return sum(n for _, n in same), f"{record}, {periods}"

    def records(self) -> list[str]:
        """The records whose held-out windows were predicted, in order."""
        return list(dict.fromkeys(label.rpartition(" period ")[0] for label, _ in self.windows))

    @property
    def residual(self) -> dict[str, np.ndarray]:
        return {k: self.measured[k] - self.predicted[k] for k in self.measured}


def _run_on(system: FirstOrderSystem, firsts: Sequence[Segment], anchors: Sequence, period: float,
            options: Integration) -> np.ndarray | None:
    """The model's state at each window's first sample, run from its record's anchor (None without one each).

    The windows of one anchor (one record's) share one run on the record's own sample grid, with the fit's RK4 steps
    between samples, read at each window's first sample: the held-out part once, not once per window from the anchor
    (which cost the square of its length: 800 periods for a record of 40 held out). A window off the anchor's grid is
    run to on its own."""
    if any(a is None for a in anchors):
        return None
    problem = Problem(system, firsts, [], [], period, options)
    t0 = np.array([float(t) for t, _ in anchors])
    dt = problem.t0 - t0
    if np.any(dt <= 0):
        return None
    y0 = np.column_stack([np.asarray(y, float) for _, y in anchors])
    groups: dict[tuple, list[int]] = {}
    for k in range(len(firsts)):
        groups.setdefault((t0[k], *y0[:, k], *problem.base[:, k], problem.dt[k]), []).append(k)
    shared, alone = [], []
    for members in groups.values():
        step = problem.dt[members[0]]
        at = np.rint(dt[members] / step).astype(np.int64)
        on_grid = np.abs(at * step - dt[members]) <= 1e-6 * step
        shared.append(([k for k, ok in zip(members, on_grid) if ok], at[on_grid]))
        alone += [k for k, ok in zip(members, on_grid) if not ok]
    out = np.empty((system.dimension, len(firsts)))
    shared = [(members, at) for members, at in shared if members]
    if shared:
        first = [members[0] for members, _ in shared]
        run = problem.engine.run(y0[:, first], t0[first], problem.dt[first],
                                 np.array([int(at.max()) + 1 for _, at in shared]),
                                 [substeps_for(problem.dt[k], period, options) for k in first], problem.base[:, first],
                                 tangent=False)
        offsets = np.concatenate([[0], np.cumsum([int(at.max()) + 1 for _, at in shared])])
        for (members, at), offset in zip(shared, offsets):
            out[:, members] = run.states[:, offset + at]
    if alone:
        steps = np.maximum(1, np.ceil(options.steps_per_period * dt[alone] / period)).astype(np.int64)
        run = problem.engine.run(y0[:, alone], t0[alone], dt[alone], np.full(len(alone), 2), steps,
                                 problem.base[:, alone], tangent=False)
        out[:, alone] = run.states[:, 1::2]
    return out


def _starts(system: FirstOrderSystem, firsts: Sequence[Segment], anchors, period: float,
            options: Integration) -> np.ndarray:
    """Each window's start state fitted to its own samples, from two first guesses (the data's, and the model
    run on from the record's anchor), keeping per window the better fit: a window that spends time in the
    backlash gap, seen through an accelerometer, can have another local minimum near either guess."""
    fits = [fit_windows(system, firsts, [], period=period, options=options)]
    guess = _run_on(system, firsts, anchors, period, options) if anchors else None
    if guess is not None:
        fits.append(fit_windows(system, firsts, [], period=period, options=options, starts=guess))
    cost = np.array([[sum(float(np.sum(r ** 2) / np.var(s.observed[k]) if np.var(s.observed[k]) else 0.0)
                          for k, r in res.items()) for res, s in zip(f.residuals, firsts)] for f in fits])
    best = np.argmin(cost, axis=0)
    return np.column_stack([fits[b].starts[:, k] for k, b in enumerate(best)])


def pairs_of(keys: Sequence[tuple]) -> list[tuple[int, int]]:
    """Indices (k, k+1) of consecutive windows of one record. ``keys``: per segment (record id, window index)."""
    return [(i, i + 1) for i, (a, b) in enumerate(zip(keys, keys[1:])) if a[0] == b[0] and b[1] == a[1] + 1]


def predict_ahead(system: FirstOrderSystem, segments: Sequence[Segment], keys: Sequence[tuple],
                  estimates: Mapping[str, float], period: float = 2 * np.pi,
                  options: Integration = Integration(), bias: Mapping[str, float] | None = None,
                  anchors: Mapping | None = None) -> Prediction:
    """One-forcing-period-ahead prediction of every held-out pair (see the module docstring).
    ``bias``: the fitted offset of each biased channel, removed from the data first. ``anchors``: per record
    (the first item of its keys) a known state (time, state), e.g. the fitted start of its last training
    window: the model run on from there gives the first guess of each start state (the fit refines it from
    the window's own samples), so that the guess is on the attractor the record is on."""
    pairs = pairs_of(keys)
    if not pairs:
        raise ValueError("the held-out part has no two consecutive whole forcing periods of one record")
    bias = dict(bias or {})

    def unbiased(seg: Segment) -> Segment:
        observed = {k: v - bias.get(k, 0.0) for k, v in seg.observed.items()}
        return replace(seg, observed=observed, parameters={**seg.parameters, **estimates})

    firsts = [unbiased(segments[i]) for i, _ in pairs]
    starts = _starts(system, firsts, [anchors.get(keys[i][0]) for i, _ in pairs] if anchors else None, period,
                     options)
    joined = [replace(unbiased(segments[i]),
                      tau=np.concatenate([segments[i].tau, segments[j].tau]),
                      observed={k: np.concatenate([segments[i].observed[k], segments[j].observed[k]]) - bias.get(k, 0.0)
                                for k in segments[j].observed if k in segments[i].observed})
              for i, j in pairs]
    problem = Problem(system, joined, [], [], period, options)
    run = problem.run(np.zeros(0), starts, False)
    names = list(dict.fromkeys(k for s in joined for k in s.observed))
    tau, measured, predicted, states = [], {k: [] for k in names}, {k: [] for k in names}, []
    for k, ((i, j), seg) in enumerate(zip(pairs, joined)):
        ahead = slice(problem.offsets[k] + len(segments[i].tau), problem.offsets[k + 1])
        tau.append(segments[j].tau)
        states.append(run.states[:, ahead])
        for name, c in problem.channel_index[k].items():
            measured[name].append(segments[j].observed[name] - bias.get(name, 0.0))
            predicted[name].append(run.outputs[c, ahead])
    measured = {k: np.concatenate(v) for k, v in measured.items()}
    predicted = {k: np.concatenate(v) for k, v in predicted.items()}
    errors = {k: float(np.sqrt(np.mean((predicted[k] - measured[k]) ** 2)) / (np.std(measured[k]) or 1.0))
              for k in names}
    return Prediction(float(np.mean(list(errors.values()))), np.concatenate(tau), measured, predicted,
                      np.hstack(states), len(pairs), errors,
                      tuple((segments[j].label, len(segments[j].tau)) for _, j in pairs))
