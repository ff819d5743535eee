"""Held-out error: how well a fitted model predicts one forcing period ahead.

For each pair of consecutive held-out windows (k, k+1) of a record, the state at
the start of window k is estimated from window k's samples alone (parameters
fixed at the fit), the model is run on through window k+1, and its samples
there are compared with the measurement. The error is the normalised RMS:
per measured coordinate, RMS(prediction - measurement) / std(measurement),
averaged over the coordinates. None of the held-out samples enters the
parameter fit, so an effect that only fits noise does not lower it.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .shooting import Segment, fit_windows, simulate_segment


@dataclass(frozen=True)
class Prediction:
    """The held-out error and what it is made of (for the residual figures)."""

    error: float  # normalised RMS over all predicted samples, averaged over coordinates
    tau: np.ndarray  # the predicted samples' times
    measured: dict[str, np.ndarray]
    predicted: dict[str, np.ndarray]
    states: np.ndarray  # (n, samples): the model's states along the prediction
    pairs: int

    @property
    def residual(self) -> dict[str, np.ndarray]:
        return {k: self.measured[k] - self.predicted[k] for k in self.measured}


def pairs_of(segments: Sequence[Segment], keys: Sequence[tuple]) -> list[tuple[int, int]]:
    """Indices (k, k+1) of consecutive windows of one record with equal sample counts.
    ``keys``: per segment (record id, window index)."""
    out = []
    for i, (a, b) in enumerate(zip(keys, keys[1:])):
        if a[0] == b[0] and b[1] == a[1] + 1 and len(segments[i].tau) == len(segments[i + 1].tau):
            out.append((i, i + 1))
    return out


def predict_ahead(system: FirstOrderSystem, segments: Sequence[Segment], keys: Sequence[tuple],
                  estimates: Mapping[str, float], period: float = 2 * np.pi,
                  options: Integration = Integration()) -> Prediction:
    """One-forcing-period-ahead prediction of every held-out pair (see the module docstring)."""
    pairs = pairs_of(segments, keys)
    if not pairs:
        raise ValueError("the held-out part has no two consecutive whole forcing periods of one record")
    firsts = [segments[i] for i, _ in pairs]
    fixed = [Segment(s.tau, s.observed, {**s.parameters, **estimates}, s.label) for s in firsts]
    starts = fit_windows(system, fixed, [], period=period, options=options).starts
    names = sorted({k for s in segments for k in s.observed})
    tau, measured, predicted, states = [], {k: [] for k in names}, {k: [] for k in names}, []
    state_names = [s.name for s in system.states]
    for (i, j), seg, start in zip(pairs, fixed, starts.T):
        samples = len(seg.tau)
        Y = simulate_segment(system, seg, start, None, period, samples=2 * samples, options=options)[:, samples:]
        nxt = segments[j]
        tau.append(nxt.tau)
        states.append(Y)
        for k in names:
            measured[k].append(nxt.observed[k])
            predicted[k].append(Y[state_names.index(k)])
    measured = {k: np.concatenate(v) for k, v in measured.items()}
    predicted = {k: np.concatenate(v) for k, v in predicted.items()}
    errors = [np.sqrt(np.mean((predicted[k] - measured[k]) ** 2)) / (np.std(measured[k]) or 1.0) for k in names]
    return Prediction(float(np.mean(errors)), np.concatenate(tau), measured, predicted, np.hstack(states), len(pairs))
