"""SciPy ``solve_ivp`` (adaptive RK45 by default) on the augmented n + n^2 system.

A hand-written numpy right-hand side with the exact Jacobian (g' = 0 or 1),
one ``solve_ivp`` call per forcing period (t_span = [k T, (k+1) T]) and
modified Gram-Schmidt in between: the way one would do the task with SciPy
alone. k(tau) and the forcing are evaluated at every RHS call (the adaptive
steps do not fall on a grid that could be tabulated). The tangent vectors are
the columns of Q, stored one after the other in the augmented state (vector j
at s[n + j n : n + (j+1) n]).
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from bench.peers.common import (DIM, K_HARMONICS, T, ContinuationSweep, PointResult, Stopwatch,
                                check_periods, initial_state, mgs, model_params, shaft_constants)

DEFAULT_ACCURACY = {"rtol": 1e-10, "atol": 1e-12}
_HARM_M = np.array([m for m, _ in K_HARMONICS], dtype=float)
_HARM_C = np.array([c for _, c in K_HARMONICS])


def _rhs_factory(model: str, p: dict[str, float], omega: float):
    """fun(t, s) for solve_ivp with the per-omega constants folded in."""
    inv_w2 = 1.0 / omega**2
    c1 = 2.0 * p["zeta"] / omega
    k_a, B0, B1, Theta, eta = p["k_a"], p["B0"], p["B1"], p["Theta"], p["eta"]
    n = DIM[model]
    J = np.zeros((n, n))  # constant entries set once, the g'-dependent ones per call
    if model == "one_stage":
        J[0, 1], J[1, 1] = 1.0, -c1
    else:
        b1, b2, b3 = shaft_constants(p)
        c3, s1, s2 = 2.0 * p["zeta"] * b3 / omega, p["kS"] * b1 * inv_w2, p["kS"] * b2 * inv_w2
        J[0, 1], J[2, 3] = 1.0, 1.0
        J[1, 1], J[1, 2] = -c1, -s1
        J[3, 1], J[3, 2] = -c3, -s2

    def fun(t: float, s: np.ndarray) -> np.ndarray:
        kw = (1.0 + k_a * (_HARM_C @ np.cos(_HARM_M * t))) * inv_w2
        fw = (B0 + B1 * np.cos(t + Theta)) * inv_w2
        x = s[0]
        if x >= 0.0:
            g, gp = x, 1.0
        elif x <= -eta:
            g, gp = x + eta, 1.0
        else:
            g, gp = 0.0, 0.0
        out = np.empty_like(s)
        if model == "one_stage":
            out[0] = s[1]
            out[1] = -c1 * s[1] + fw - kw * g
            J[1, 0] = -kw * gp
        else:
            out[0] = s[1]
            out[1] = -c1 * s[1] + fw - kw * g - s1 * s[2]
            out[2] = s[3]
            out[3] = -s2 * s[2] - c3 * s[1] - b3 * kw * g
            J[1, 0] = -kw * gp
            J[3, 0] = -b3 * kw * gp
        # Rows of s[n:].reshape(n, n) are the tangent vectors q_j: d q_j = J q_j.
        out[n:] = (s[n:].reshape(n, n) @ J.T).ravel()
        return out

    return fun


class ScipyIVP(ContinuationSweep):
    def __init__(self, model: str, accuracy: dict | None, method: str, params: dict[str, float]):
        t0 = time.perf_counter()
        acc = {**DEFAULT_ACCURACY, **(accuracy or {})}
        if set(acc) - {"rtol", "atol"}:
            raise ValueError(f"solve_ivp is adaptive: accuracy takes 'rtol' and 'atol', got {accuracy}")
        self.model, self.method = model, method
        self.name = f"SciPy {method}"
        self.p = model_params(model, **params)
        self.accuracy = {k: float(v) for k, v in acc.items()}
        self.setup_seconds = time.perf_counter() - t0
        self.setup_note = "none (pure Python)"

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult:
        check_periods(periods, discard)
        n = DIM[self.model]
        s = np.concatenate([initial_state(self.model, y0), np.eye(n).ravel()])
        sumlog = np.zeros(n)
        with Stopwatch() as sw:
            fun = _rhs_factory(self.model, self.p, float(omega))
            for k in range(periods):
                sol = solve_ivp(fun, (k * T, (k + 1) * T), s, method=self.method, **self.accuracy)
                if not sol.success:
                    raise RuntimeError(f"solve_ivp failed at omega={omega}, period {k}: {sol.message}")
                s = sol.y[:, -1].copy()
                Q = s[n:].reshape(n, n).T.copy()  # columns = tangent vectors
                lognorm = mgs(Q)
                s[n:] = Q.T.ravel()
                if k >= discard:
                    sumlog += lognorm
        return PointResult(sumlog / ((periods - discard) * T), s[:n].copy(), sw.seconds)


def make(model: str, accuracy: dict | None = None, method: str = "RK45", **params: float) -> ScipyIVP:
    return ScipyIVP(model, accuracy, method, params)
