"""The converged answer each tool is measured against, reached two independent ways.

The gear models are piecewise linear: the backlash slope g'(x) jumps where x
crosses 0 or -eta, so the tangent equations have a discontinuous right-hand
side and fixed-step RK4 is only first-order accurate for the exponents (its
error jumps about with the step, as crossings move inside the steps). Hence:

* **step halving**: the hand-written C at 200, 400, ..., 25 600 steps per
  period; the changes shrink about 2x per halving, so the sequence converges,
  slowly (its finest value is good to ~1e-6);
* **tolerance tightening**: JiTCODE's Dormand-Prince at rtol = atol = 1e-10,
  1e-11, 1e-12, whose error control resolves each crossing; its tightest run
  is the reference, and SciPy's RK45 at 1e-10 (independent code) checks it.

A point is ``converged`` when the two tightest JiTCODE runs agree to 1e-8 and
SciPy agrees with them to 1e-7. On a chaotic orbit the finite-time exponent
depends on every rounding and nothing converges (changes ~1e-2): such points
are compared with the ~0.01 tolerance that separates any two correct methods.
"""
from __future__ import annotations

import numpy as np

STEPS = (200, 400, 800, 1600, 3200, 6400, 12800, 25600)
TOLERANCES = (1e-10, 1e-11, 1e-12)
SCIPY_CHECK = 1e-10
AGREE_TIGHT, AGREE_SCIPY = 1e-8, 1e-7


def _sorted(res) -> np.ndarray:
    return np.sort(np.asarray(res.exponents, dtype=float))[::-1]


def _ladder(tools, omega, y0, periods, discard) -> tuple[list[list[float]], list[float]]:
    runs = [_sorted(t.spectrum(omega, y0, periods, discard)) for t in tools]
    return [r.tolist() for r in runs], [float(np.max(np.abs(b - a))) for a, b in zip(runs, runs[1:])]


def converged_reference(make_c, make_jitcode, make_scipy, omegas, y0, periods: int, discard: int,
                        steps=STEPS, tolerances=TOLERANCES) -> dict:
    """``make_c(steps)``, ``make_jitcode(tol)``, ``make_scipy(tol)`` build the tools."""
    c_tools = [make_c(s) for s in steps]
    jit_tools = [make_jitcode(t) for t in tolerances]
    scipy_tool = make_scipy(SCIPY_CHECK)
    out = {}
    for omega in omegas:
        c_runs, c_changes = _ladder(c_tools, omega, y0, periods, discard)
        j_runs, j_changes = _ladder(jit_tools, omega, y0, periods, discard)
        ref = np.array(j_runs[-1])
        scipy = _sorted(scipy_tool.spectrum(omega, y0, periods, discard))
        scipy_diff = float(np.max(np.abs(scipy - ref)))
        out[repr(float(omega))] = {
            "omega": float(omega), "reference": ref.tolist(),
            "steps": list(steps), "step_halving": c_runs, "step_changes": c_changes,
            "step_finest_difference": float(np.max(np.abs(np.array(c_runs[-1]) - ref))),
            "tolerances": list(tolerances), "tightening": j_runs, "tolerance_changes": j_changes,
            "scipy": scipy.tolist(), "scipy_difference": scipy_diff,
            "converged": j_changes[-1] < AGREE_TIGHT and scipy_diff < AGREE_SCIPY,
        }
    return out
