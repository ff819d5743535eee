"""Numba ``@njit`` fixed-step RK4 with tangent equations and MGS: the scheme of
bench/yardstick/flexible_shaft.c (stage times j*h/2, tau = 0 at every period
start, time coefficients tabulated per omega point), written the natural Numba
way: scalar loops over small arrays, the Jacobian's action written out.

fastmath is off, so results match the C yardstick to rounding (~1e-12 or
better on periodic points; the C build may fuse multiply-adds, LLVM here does
not). ``cache=False``: every process pays the JIT compile, and make() triggers
it with a tiny run, so setup_seconds is the honest first-use cost of Numba.
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from bench.peers.common import (ContinuationSweep, PointResult, Stopwatch, check_periods, fixed_step_accuracy,
                                initial_state, model_params, shaft_constants)

TWO_PI = 2.0 * math.pi


@njit(cache=False)
def _time_tables(N, inv_w2, k_a, B0, B1, Theta):
    """k(tau)/omega^2 and forcing/omega^2 at the 2N+1 half-step times of a period."""
    hh = 0.5 * (TWO_PI / N)
    kw = np.empty(2 * N + 1)
    fw = np.empty(2 * N + 1)
    for j in range(2 * N + 1):
        tau = j * hh
        kw[j] = (1.0 + k_a * (1.18003861468 * math.cos(tau)
                              - 0.336894506314 * math.cos(2.0 * tau)
                              - 0.195632837787 * math.cos(3.0 * tau)
                              + 0.192724343884 * math.cos(4.0 * tau)
                              - 0.0605674179821 * math.cos(6.0 * tau)
                              + 0.0148837545288 * math.cos(7.0 * tau))) * inv_w2
        fw[j] = (B0 + B1 * math.cos(tau + Theta)) * inv_w2
    return kw, fw


@njit(cache=False)
def _backlash(x, eta):
    """g(x) and g'(x); at x = -eta both branches give g = 0."""
    if x >= 0.0:
        return x, 1.0
    if x <= -eta:
        return x + eta, 1.0
    return 0.0, 0.0


@njit(cache=False)
def _rhs_one_stage(s, kw, fw, c, ds):
    """s = (x, v, Q column-major); c = (c1, eta)."""
    c1, eta = c[0], c[1]
    g, gp = _backlash(s[0], eta)
    ds[0] = s[1]
    ds[1] = -c1 * s[1] + fw - kw * g
    j10 = -kw * gp
    for col in range(2):
        o = 2 + 2 * col
        ds[o] = s[o + 1]
        ds[o + 1] = j10 * s[o] - c1 * s[o + 1]


@njit(cache=False)
def _rhs_flexible(s, kw, fw, c, ds):
    """s = (x1, v1, x2, v2, Q column-major); c = (c1, c3, s1, s2, b3, eta)."""
    c1, c3, s1, s2, b3, eta = c[0], c[1], c[2], c[3], c[4], c[5]
    g, gp = _backlash(s[0], eta)
    ds[0] = s[1]
    ds[1] = -c1 * s[1] + fw - kw * g - s1 * s[2]
    ds[2] = s[3]
    ds[3] = -s2 * s[2] - c3 * s[1] - b3 * kw * g
    j10 = -kw * gp
    j30 = -b3 * kw * gp
    for col in range(4):
        o = 4 + 4 * col
        ds[o] = s[o + 1]
        ds[o + 1] = j10 * s[o] - c1 * s[o + 1] - s1 * s[o + 2]
        ds[o + 2] = s[o + 3]
        ds[o + 3] = j30 * s[o] - c3 * s[o + 1] - s2 * s[o + 2]


@njit(cache=False)
def _mgs(s, n, lognorm):
    """Modified Gram-Schmidt on the column-major n x n Q stored at s[n:]."""
    for j in range(n):
        oj = n + n * j
        for i in range(j):
            oi = n + n * i
            r = 0.0
            for k in range(n):
                r += s[oi + k] * s[oj + k]
            for k in range(n):
                s[oj + k] -= r * s[oi + k]
        nrm = 0.0
        for k in range(n):
            nrm += s[oj + k] * s[oj + k]
        nrm = math.sqrt(nrm)
        for k in range(n):
            s[oj + k] /= nrm
        lognorm[j] = math.log(nrm)


def _make_point(rhs, n):
    """The per-point loop for one model: n (a closure constant, so the loops over
    the augmented state have a compile-time trip count, as NS in the C)."""
    ns = n + n * n

    @njit(cache=False)
    def point(y, kw, fw, c, N, P, D):
        s = np.zeros(ns)
        s[:n] = y
        for k in range(n):
            s[n + n * k + k] = 1.0  # Q = identity
        k1, k2, k3, k4, t = np.empty(ns), np.empty(ns), np.empty(ns), np.empty(ns), np.empty(ns)
        lognorm = np.empty(n)
        sumlog = np.zeros(n)
        h = TWO_PI / N
        hh, h6 = 0.5 * h, h / 6.0
        for per in range(P):
            for i in range(N):
                rhs(s, kw[2 * i], fw[2 * i], c, k1)
                for m in range(ns):
                    t[m] = s[m] + hh * k1[m]
                rhs(t, kw[2 * i + 1], fw[2 * i + 1], c, k2)
                for m in range(ns):
                    t[m] = s[m] + hh * k2[m]
                rhs(t, kw[2 * i + 1], fw[2 * i + 1], c, k3)
                for m in range(ns):
                    t[m] = s[m] + h * k3[m]
                rhs(t, kw[2 * i + 2], fw[2 * i + 2], c, k4)
                for m in range(ns):
                    s[m] += h6 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m])
            _mgs(s, n, lognorm)
            if per >= D:
                sumlog += lognorm
        return sumlog / ((P - D) * TWO_PI), s[:n].copy()

    return point


_POINT = {"one_stage": _make_point(_rhs_one_stage, 2), "flexible_shaft": _make_point(_rhs_flexible, 4)}


class NumbaRK4(ContinuationSweep):
    name = "Numba RK4"

    def __init__(self, model: str, accuracy: dict | None, params: dict[str, float]):
        t0 = time.perf_counter()
        self.model = model
        self.p = model_params(model, **params)
        self.accuracy = fixed_step_accuracy(accuracy, "Numba RK4")
        self._point = _POINT[model]
        jitted = bool(self._point.signatures)
        self._run(1.0, initial_state(model, None), 2, 2, 1)  # triggers the JIT compile
        self.setup_seconds = time.perf_counter() - t0
        self.setup_note = "already JIT-compiled in this process" if jitted else "JIT compile (numba, cache=False)"

    def _run(self, omega: float, y: np.ndarray, N: int, P: int, D: int):
        p = self.p
        inv_w2 = 1.0 / (omega * omega)
        kw, fw = _time_tables(N, inv_w2, p["k_a"], p["B0"], p["B1"], p["Theta"])
        if self.model == "one_stage":
            c = np.array([2.0 * p["zeta"] / omega, p["eta"]])
        else:
            b1, b2, b3 = shaft_constants(p)
            c = np.array([2.0 * p["zeta"] / omega, 2.0 * p["zeta"] * b3 / omega,
                          p["kS"] * b1 * inv_w2, p["kS"] * b2 * inv_w2, b3, p["eta"]])
        return self._point(y, kw, fw, c, N, P, D)

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult:
        check_periods(periods, discard)
        y = initial_state(self.model, y0)
        with Stopwatch() as sw:  # tables + per-omega constants + the loop, like the C's run_point
            exps, y_end = self._run(float(omega), y, self.accuracy["steps"], periods, discard)
        return PointResult(exps, y_end, sw.seconds)


def make(model: str, accuracy: dict | None = None, **params: float) -> NumbaRK4:
    return NumbaRK4(model, accuracy, params)
