"""The channels a fit observes, read from one compiled window library per model.

A channel that is a state, a state's rate or a sum of numbers times them (x; x_dot; an accelerometer's x_ddot where
x' = v is a state, in the model's time or scaled to seconds: 62500 x_ddot) is taken from the windows of every state
and every rate that is no state (:func:`observable`), of which a run computes only those it asks for. So data of a
displacement and of an accelerometer, in tau or in seconds, share one library, compiled once, of a model (before, a
library each: the one-stage model's of every candidate 4 s of gcc each). Any other channel (a declared combination
with a parameter or the time in it) has a library of its own channels, as before. A channel that is one of those
channels is read as it is: the same bits as from a library of its own.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from ..codegen.windows import Windows, WindowRun, compile_windows
from ..data.channels import channel_expression
from ..system import FirstOrderSystem

#: a channel as the windows' channels it sums: (index in the library's channels, factor), ...
Terms = tuple[tuple[int, float], ...]


def observable(system: FirstOrderSystem) -> list[sp.Expr]:
    """The channels of a model's shared window library: every state, then every rate that is no state."""
    states = list(system.states)
    return states + list(dict.fromkeys(f for f in system.rhs if f not in states))


def terms_of(channel: sp.Expr, system: FirstOrderSystem, channels: Sequence[sp.Expr]) -> Terms | None:
    """``channel`` (states and derivative placeholders) as a sum of numbers times ``channels``, or None."""
    out = []
    for name, factor in channel.as_coefficients_dict().items():
        if not isinstance(name, sp.Symbol) or not factor.is_Number:
            return None
        resolved = channel_expression(name, system)
        if resolved not in channels:
            return None
        out.append((list(channels).index(resolved), float(factor)))
    return tuple(out) or None


class ObservedWindows:
    """Window runs of a model's channels taken from its shared library (see the module docstring): :meth:`run` as
    :meth:`Windows.run`, the outputs' rows the channels given."""

    def __init__(self, windows: Windows, terms: Sequence[Terms]):
        self.windows, self.terms = windows, tuple(terms)
        self.needed = sorted({k for t in self.terms for k, _ in t})
        self._row = {k: i for i, k in enumerate(self.needed)}

    def run(self, starts, t0, dt, samples, substeps, parameters, tangent: bool = True,
            columns: Sequence[int] | None = None) -> WindowRun:
        run = self.windows.run(starts, t0, dt, samples, substeps, parameters, tangent, columns, self.needed)
        outputs = np.stack([self._sum(run.outputs, t) for t in self.terms])
        derivatives = np.stack([self._sum(run.derivatives, t) for t in self.terms]) if tangent else None
        return WindowRun(run.states, outputs, derivatives)

    def _sum(self, rows: np.ndarray, terms: Terms) -> np.ndarray:
        total = None
        for k, factor in terms:  # (a factor 1 is no multiplication: a channel of the library is read as it is)
            part = rows[self._row[k]] if factor == 1 else factor * rows[self._row[k]]
            total = part if total is None else total + part
        return total


def observed_windows(system: FirstOrderSystem, channels: Sequence[sp.Expr],
                     backend: str = "auto") -> Windows | ObservedWindows:
    """The window integrator of ``system`` observed through ``channels`` (states and derivative placeholders): from
    the model's shared library where every channel is a sum of its channels, else from a library of its own."""
    shared = observable(system)
    terms = [terms_of(c, system, shared) for c in channels]
    if channels and all(t is not None for t in terms):
        return ObservedWindows(compile_windows(system, shared, backend), terms)
    return compile_windows(system, [channel_expression(c, system) for c in channels], backend)
