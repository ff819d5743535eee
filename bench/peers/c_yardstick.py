"""The hand-written C yardstick (bench/yardstick/*.c) behind the common Tool interface.

Fixed-step RK4 with tabulated time coefficients; each call runs the C program
once (a sweep is one process, with the continuation done in C). ``seconds``
are the program's own CLOCK_MONOTONIC per point: process start-up, argument
parsing and output are not included.
"""
from __future__ import annotations

import platform
import time

import numpy as np

from bench.peers.common import PointResult, check_periods, fixed_step_accuracy, initial_state, model_params
from bench.yardstick import runner

# The fastest build found for both models (bench/README.md): on AVX-512 CPUs
# plain -march=native vectorises the dense 4x4 tangent product 512 bits wide
# and is slower than -O3; preferring 128-bit vectors fixes that (x86 only flag).
DEFAULT_FLAGS: tuple[str, ...] = ("-O3", "-march=native") + (
    ("-mprefer-vector-width=128",) if platform.machine().lower() in ("x86_64", "amd64") else ())


class CYardstick:
    name = "C yardstick"

    def __init__(self, model: str, accuracy: dict | None, flags: tuple[str, ...], cc: str,
                 variant: str, params: dict[str, float]):
        t0 = time.perf_counter()
        self.model = model
        self.params = model_params(model, **params)
        self.accuracy = fixed_step_accuracy(accuracy, "the C yardstick")
        self.flags, self.variant = tuple(flags), variant
        cached = runner.binary_path(cc, self.flags, model=model).exists()
        self.binary = runner.build(cc, self.flags, model=model)
        self.setup_seconds = time.perf_counter() - t0
        self.setup_note = "cached binary" if cached else "first compile (gcc)"

    def _run(self, start: float, stop: float, step: float, y0, periods: int, discard: int) -> dict:
        check_periods(periods, discard)
        return runner.run(self.binary, variant=self.variant, steps=self.accuracy["steps"],
                          periods=periods, discard=discard, omega_start=start, omega_stop=stop,
                          omega_step=step, y0=tuple(initial_state(self.model, y0)), **self.params)

    def _results(self, r: dict) -> list[PointResult]:
        n = len(r["omega"])
        final = r["final_state"]
        if final is None or len(final) != n:
            raise RuntimeError(f"{self.binary.name} printed no final state per point (# y_end= lines)")
        return [PointResult(r["exponents"][i].copy(), final[i].copy(), float(r["point_seconds"][i]))
                for i in range(n)]

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult:
        return self._results(self._run(omega, omega, 1.0, y0, periods, discard))[0]

    def sweep(self, omegas, y0=None, periods: int = 400, discard: int = 100) -> list[PointResult]:
        """One C process for the whole sweep: omegas must be evenly spaced and increasing
        (the program forms omega_start + i * omega_step itself)."""
        w = np.asarray(omegas, dtype=float)
        if w.size == 1:
            return [self.spectrum(float(w[0]), y0, periods, discard)]
        step = (w[-1] - w[0]) / (w.size - 1)
        if not step > 0 or not np.allclose(np.diff(w), step, rtol=1e-9, atol=0.0):
            raise ValueError("the C yardstick sweeps an evenly spaced increasing omega grid only")
        res = self._results(self._run(w[0], w[-1], step, y0, periods, discard))
        if len(res) != w.size:
            raise RuntimeError(f"C program ran {len(res)} points, expected {w.size}")
        return res


def make(model: str, accuracy: dict | None = None, flags=DEFAULT_FLAGS, cc: str = "gcc",
         variant: str = "table", **params: float) -> CYardstick:
    return CYardstick(model, accuracy, flags, cc, variant, params)
