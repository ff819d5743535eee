"""gearsym itself behind the peers' interface: the compiled model, built once, reused for every point.

Two ways through gearsym are offered, because they differ in what the call does:

* ``path="loop"`` (default): the low-level call a sweep makes, ``prepare`` and
  ``tangent_run`` on the prebuilt :class:`~gearsym.codegen.CompiledModel`, the
  exponents summed from the per-period logarithms in Gram-Schmidt order;
* ``path="lyapunov_spectrum"``: the high-level analysis on the same prebuilt
  model (sorted exponents, batch-means errors, history, amplitudes, regime),
  which is what ``gearsym sweep`` calls for every point.

``crossings=True`` compiles the model with ``locate_crossings``: RK4 steps that
cross a backlash kink are split there, which restores fourth order for the
exponents (the plain scheme is first order at the kinks).
"""
from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from .common import ContinuationSweep, PointResult, initial_state

PATHS = ("loop", "lyapunov_spectrum")


class GearsymTool(ContinuationSweep):  # sweep: the shared continuation over spectrum()
    def __init__(self, model: str, accuracy: dict | None = None, path: str = "loop", crossings: bool = False,
                 **params: float):
        from gearsym.codegen import compile_model

        if path not in PATHS:
            raise ValueError(f"path must be one of {PATHS}, not {path!r}")
        accuracy = dict(accuracy or {"steps": 200})
        if set(accuracy) != {"steps"}:
            raise ValueError(f"gearsym integrates with fixed steps: accuracy must be {{'steps': N}}, got {accuracy}")
        self.model, self.path, self.accuracy = model, path, accuracy
        self.name = "gearsym" if path == "loop" else "gearsym (lyapunov_spectrum)"
        if crossings:
            self.name = "gearsym (crossings located)"
        start = time.perf_counter()
        extra = {"locate_crossings": True} if crossings else {}  # opt-in: RK4 steps split at the backlash kinks
        self.compiled = compile_model(model, steps_per_period=int(accuracy["steps"]), backend="compiled", **extra)
        self.setup_seconds = time.perf_counter() - start
        self.setup_note = "compiled now" if "compile" in self.compiled.timings else "library from the cache"
        self.params = dict(params)
        self.compiled.parameter_vector(self.params)  # unknown names fail here, before any timing
        warm = self.compiled.prepare(self.compiled.parameter_vector(self.params, omega=1.0))
        self.compiled.tangent_run(initial_state(model, None), 2, warm)  # page in the library

    def spectrum(self, omega: float, y0: Sequence[float] | None = None, periods: int = 400,
                 discard: int = 100) -> PointResult:
        y = initial_state(self.model, y0)
        start = time.perf_counter()
        if self.path == "loop":
            cm = self.compiled
            inputs = cm.prepare(cm.parameter_vector(self.params, omega=omega))
            run = cm.tangent_run(y, periods, inputs)
            exponents = run.log_stretch[:, discard:].sum(axis=1) / ((periods - discard) * inputs.period)
            final = run.strobe[:, -1].copy()
        else:
            from gearsym.analysis import lyapunov_spectrum

            res = lyapunov_spectrum(self.compiled, periods=periods, discard=discard, y0=y, **self.params,
                                    omega=omega)
            exponents = np.asarray(res.exponents)  # sorted: the analysis does not keep Gram-Schmidt order
            final = np.array([res.final_state[s] for s in self.compiled.state_names])
        return PointResult(exponents, final, time.perf_counter() - start)


def make(model: str, accuracy: dict | None = None, crossings: bool = False, **params: float) -> GearsymTool:
    return GearsymTool(model, accuracy, crossings=crossings, **params)
