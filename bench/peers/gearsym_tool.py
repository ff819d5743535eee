"""gearsym itself behind the peers' interface: the compiled model, built once, reused for every point.

The scheme is always named by the caller (``scheme=``, a :class:`gearsym.Integration`), because gearsym's
default locates the backlash crossings and the hand-written C, Numba and the paper do not:

* ``Integration.paper()``: the paper's plain RK4, the same numbers as the C yardstick to rounding (like for
  like in every timing against it);
* ``Integration(locate_crossings=True)``: RK4 steps that cross a backlash kink are split there, which
  restores fourth order for the exponents (the plain scheme is first order at the kinks).

``accuracy={"steps": N}`` sets the scheme's steps per period. Two ways through gearsym are offered, because
they differ in what the call does:

* ``path="loop"`` (default): the low-level calls a sweep makes, ``prepare`` and
  ``tangent_run_into`` on the prebuilt :class:`~gearsym.codegen.CompiledModel` (into a
  :class:`~gearsym.codegen.TangentRuns` of one run, made once per number of periods like the model:
  its native calls are planned once), the exponents summed from the per-period logarithms in
  Gram-Schmidt order;
* ``path="lyapunov_spectrum"``: the high-level analysis on the same prebuilt
  model (sorted exponents, batch-means errors, history, amplitudes, regime),
  which is what ``gearsym sweep`` calls for every point.
"""
from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

import gearsym
from gearsym import Integration
from gearsym.codegen import TangentRuns

from .common import ContinuationSweep, PointResult, fixed_step_accuracy, initial_state

PATHS = ("loop", "lyapunov_spectrum")


class GearsymTool(ContinuationSweep):  # sweep: the shared continuation over spectrum()
    def __init__(self, model: str, accuracy: dict | None, *, scheme: Integration, path: str = "loop",
                 **params: float):
        if path not in PATHS:
            raise ValueError(f"path must be one of {PATHS}, not {path!r}")
        self.model, self.path, self.accuracy = model, path, fixed_step_accuracy(accuracy, "gearsym")
        self.name = "gearsym" if path == "loop" else "gearsym (lyapunov_spectrum)"
        if scheme.locate_crossings:
            self.name = "gearsym (crossings located)"
        self.scheme = replace(scheme, steps_per_period=self.accuracy["steps"], backend="compiled")
        start = time.perf_counter()
        self.compiled = gearsym.compile_model(gearsym.load(model), self.scheme)
        self.setup_seconds = time.perf_counter() - start
        self.setup_note = "compiled now" if "compile" in self.compiled.timings else "library from the cache"
        self.params = dict(params)
        self.runs: dict[int, TangentRuns] = {}  # periods -> the records of one run
        self.compiled.parameter_vector(self.params)  # unknown names fail here, before any timing
        warm = self.compiled.prepare(self.compiled.parameter_vector(self.params, omega=1.0))
        self.compiled.tangent_run(initial_state(model, None), 2, warm)  # page in the library

    def spectrum(self, omega: float, y0: Sequence[float] | None = None, periods: int = 400,
                 discard: int = 100) -> PointResult:
        y = initial_state(self.model, y0)
        runs = (self.runs.get(periods) or self._records(periods)) if self.path == "loop" else None
        start = time.perf_counter()
        if self.path == "loop":
            cm = self.compiled
            inputs = cm.prepare(cm.parameter_vector(self.params, omega=omega))
            cm.tangent_run_into(runs, 0, y, inputs)
            strobe, log_stretch = runs.slot(0)[:2]  # (n, periods) views, as tangent_run returns them
            exponents = log_stretch[:, discard:].sum(axis=1) / ((periods - discard) * inputs.period)
            final = strobe[:, -1].copy()
        else:
            res = gearsym.lyapunov_spectrum(self.compiled, options=self.scheme.run(periods, discard), y0=y,
                                            **self.params, omega=omega)
            exponents = np.asarray(res.exponents)  # sorted: the analysis does not keep Gram-Schmidt order
            final = np.array([res.final_state[s] for s in self.compiled.state_names])
        return PointResult(exponents, final, time.perf_counter() - start)

    def _records(self, periods: int) -> TangentRuns:
        """Room for one run of ``periods`` periods, made once (a user's loop over points makes it once)."""
        cm = self.compiled
        runs = self.runs[periods] = TangentRuns(cm.dimension, len(cm.observed), periods, 1)
        return runs


def make(model: str, accuracy: dict | None = None, *, scheme: Integration, **params: float) -> GearsymTool:
    """``scheme``: ``Integration.paper()`` (like the C) or ``Integration(locate_crossings=True)``; required."""
    return GearsymTool(model, accuracy, scheme=scheme, **params)
