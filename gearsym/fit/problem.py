"""The least-squares problem of a multiple-shooting fit: every window's scaled residuals and their exact Jacobian, by
the unknowns u = [theta, bias, S[:, 0], S[:, 1], ...] (parameters, channel offsets, each window's start state)."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from ..codegen.windows import Windows
from ..errors import GearsymError
from ..options import Integration
from ..system import FirstOrderSystem
from .integrated import from_rate
from .jacobian import Jacobian
from .observed import ObservedWindows, observed_windows
from .segment import Segment, substeps_for


#: runs a problem keeps (:meth:`Problem.run_at`): Levenberg-Marquardt ends at an accepted step, after which at most a
#: few refused trials are run
RECENT = 4


class Problem:
    """Scaled residuals of every window and their exact Jacobian, by u = [theta, bias, S[:, 0], S[:, 1], ...].

    ``slots``: tooth-by-tooth forms as the compiled model has them (:class:`gearsym.fit.tooth_forms.Slots`): the
    per-tooth parameters among ``fit`` reach each window through its slots (its first tooth set from its start time,
    each slot the parameter of its tooth), and each slot's derivative column adds to its tooth's."""

    def __init__(self, system: FirstOrderSystem, segments: Sequence[Segment], fit: list[str], bias: list[str],
                 period: float, options: Integration, slots: Sequence = ()):
        self.system, self.segments, self.fit, self.period = system, list(segments), fit, period
        self._integrated = None
        self._recent: list = []  # the last RECENT runs of __call__: (u, run), newest first
        self.names = tuple(system.parameters)
        per_tooth = {name: (sl, k) for sl in slots for k, name in enumerate(sl.teeth_names)}
        unknown = [p for p in fit if p not in self.names and p not in per_tooth]
        if unknown:
            raise GearsymError(f"cannot fit {', '.join(unknown)}: not parameters of {system.name}")
        self.direct = np.array([i for i, p in enumerate(fit) if p in self.names], dtype=int)  # positions in theta
        self.index = np.array([self.names.index(fit[i]) for i in self.direct], dtype=int)
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
        self.engine: Windows | ObservedWindows = observed_windows(system, [e for _, e in keys], options.backend)
        self.scale = {}
        for name in dict.fromkeys(self.channel_names):
            values = np.concatenate([s.observed[name] for s in segments if name in s.observed])
            self.scale[name] = float(np.std(values)) or 1.0
        self.samples = np.array([len(s.tau) for s in segments], dtype=np.int64)
        self.t0 = np.array([float(s.tau[0]) for s in segments])
        self.dt = _sample_steps(segments)
        self.substeps = np.array([substeps_for(dt, period, options) for dt in self.dt], dtype=np.int64)
        self.base = np.array([[s.parameters[n] for n in self.names] for s in segments], dtype=float).T
        # per slot (across the forms' gears): its parameter's row, and per window the position in theta of its tooth's
        self.slot_rows, slot_positions = [], []
        for sl in slots:
            firsts = np.array([sl.first_tooth(t) for t in self.t0])
            self.base[self.names.index(sl.first), :] = firsts
            for j, name in enumerate(sl.slots):
                self.slot_rows.append(self.names.index(name))
                position = [fit.index(sl.teeth_names[k]) if sl.teeth_names[k] in fit else -1
                            for k in (firsts + j - 1) % sl.teeth]
                slot_positions.append(position)
        self.slot_rows = np.array(self.slot_rows, dtype=int)
        self.slot_positions = np.array(slot_positions, dtype=int).reshape(len(self.slot_rows), len(segments))
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
        P[self.index, :] = theta[self.direct, None]
        if self.slot_rows.size:
            padded = np.append(theta, 0.0)  # (position -1: a tooth not fitted, its slot at 0)
            P[self.slot_rows, :] = padded[self.slot_positions]
        return P

    @property
    def columns(self) -> np.ndarray:
        """The parameters whose derivative columns a run computes: the fitted ones, then the slots."""
        return np.concatenate([self.index, self.slot_rows]).astype(int)

    def run(self, theta: np.ndarray, S: np.ndarray, tangent: bool):
        return self.engine.run(S, self.t0, self.dt, self.samples, self.substeps, self.parameters(theta), tangent,
                               columns=self.columns)

    def _parameter_columns(self, D: np.ndarray) -> np.ndarray:
        """The residuals' derivatives by theta from the run's columns (fitted parameters, then slots)."""
        direct = len(self.index)
        out = np.zeros((D.shape[0], self.m))
        out[:, self.direct] = D[:, :direct]
        rows = np.arange(D.shape[0])
        for j in range(len(self.slot_rows)):
            position = self.slot_positions[j][self.window]
            fitted = position >= 0
            np.add.at(out, (rows[fitted], position[fitted]), D[fitted, direct + j])
        return out

    def run_at(self, u: np.ndarray):
        """The run without the tangent at the unknowns ``u``: one of the last runs :meth:`__call__` made, if it made
        one at exactly ``u`` (its states and outputs are the same bits with or without the tangent), else a new one."""
        for at, run in self._recent:
            if np.array_equal(at, u):
                return run
        theta, _, S = self.split(u)
        return self.run(theta, S, False)

    def __call__(self, u: np.ndarray, jacobian: bool = True):
        theta, b, S = self.split(u)
        run = self.run(theta, S, jacobian)
        self._recent = [(np.array(u, dtype=float), run), *self._recent[:RECENT - 1]]
        offset = np.where(self.bias_of >= 0, b[np.maximum(self.bias_of, 0)] if b.size else 0.0, 0.0)
        r = (run.outputs[self.rows] + offset) * self.weight - self.data
        if not jacobian:
            return r, None
        D = run.derivatives[self.rows[0], :, self.rows[1]] * self.weight[:, None]  # (residuals, n + fitted)
        offsets = np.stack([np.where(self.bias_of == j, self.weight, 0.0) for j in range(len(self.bias))], axis=1) \
            if self.bias else np.zeros((r.size, 0))
        return r, Jacobian(np.hstack([self._parameter_columns(D[:, self.n:]), offsets]), D[:, :self.n], self.window,
                           self.row_offsets)


def _sample_steps(segments: Sequence[Segment]) -> np.ndarray:
    """Each window's median step between samples: the windows of one length at once (one median call per length,
    not per window, which was most of a problem's set-up: the same numbers)."""
    lengths = np.array([len(s.tau) for s in segments], dtype=np.int64)
    out = np.empty(len(segments))
    for length in np.unique(lengths):
        which = np.nonzero(lengths == length)[0]
        if length < 2:  # (no step: what the median of none is)
            out[which] = [float(np.median(np.diff(segments[k].tau))) for k in which]
        else:
            out[which] = np.median(np.diff(np.array([segments[k].tau for k in which], dtype=float), axis=1), axis=1)
    return out
