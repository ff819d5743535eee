"""Self-check: every peer gets the same Lyapunov exponents at one periodic point.

    python -m bench.peers.check              # both models, omega = 1.8, 60 periods (20 discarded)
    python bench/peers/check.py --omega 1.5 --periods 100 --discard 40

Numba and gearsym with the paper's scheme (``Integration.paper()``) run the C
yardstick's scheme, so they must agree with it to rounding (1e-10). JiTCODE and
SciPy are adaptive (rtol 1e-10, atol 1e-12), and gearsym with the crossings
located (its default) is fourth order at the kinks: these are compared with
the C at 3200 steps per period (1e-6), and the adaptive two with each other (1e-8). That reference is itself only about
first-order accurate where the orbit crosses a backlash kink (the tangent
equations' right-hand side jumps there), so its own error, estimated against
12800 steps, is printed too; at omega = 1.2 or 1.5 it exceeds 1e-6. Exit code
1 if a check fails. Takes ~30 s with JiTCODE modules to compile, less after.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from gearsym import Integration  # noqa: E402

from bench.peers import c_yardstick, gearsym_tool, jitcode_lyap, numba_rk4, scipy_ivp  # noqa: E402
from bench.peers.common import DEFAULTS, MODELS, PointResult, sum_rule  # noqa: E402

SAME_SCHEME_TOL = 1e-10
ADAPTIVE_TOL = 1e-6
MUTUAL_TOL = 1e-8  # JiTCODE vs SciPy: the same method at the same tolerances
TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def _acc(acc: dict) -> str:
    return " ".join(f"{k}={v:g}" for k, v in acc.items())


def check_model(model: str, omega: float, periods: int, discard: int) -> bool:
    run = dict(periods=periods, discard=discard)
    rows: list[tuple[str, str, object, PointResult, str, float | None, float | None]] = []

    c200 = c_yardstick.make(model)
    r_c200 = c200.spectrum(omega, **run)
    c3200 = c_yardstick.make(model, {"steps": 3200})
    r_ref = c3200.spectrum(omega, **run)
    r_c12800 = c_yardstick.make(model, {"steps": 12800}).spectrum(omega, **run)
    rows.append((c200.name, _acc(c200.accuracy), c200, r_c200, "", None, None))
    def gearsym(scheme: Integration):  # the peers' parameter values, so that every tool integrates one system
        return gearsym_tool.make(model, scheme=scheme, **DEFAULTS[model])

    tools = [(numba_rk4.make(model), r_c200, "C 200", SAME_SCHEME_TOL),
             (gearsym(Integration.paper()), r_c200, "C 200", SAME_SCHEME_TOL),
             (c3200, None, "reference", None),
             (jitcode_lyap.make(model, TIGHT), r_ref, "C 3200", ADAPTIVE_TOL),
             (scipy_ivp.make(model, TIGHT), r_ref, "C 3200", ADAPTIVE_TOL),
             (gearsym(Integration(locate_crossings=True)), r_ref, "C 3200", ADAPTIVE_TOL)]
    results = {}
    for tool, ref, against, tol in tools:
        r = r_ref if tool is c3200 else tool.spectrum(omega, **run)
        results[tool.name] = r
        diff = None if ref is None else float(np.max(np.abs(r.exponents - ref.exponents)))
        rows.append((tool.name, _acc(tool.accuracy), tool, r, against, diff, tol))

    expected_sum = sum_rule(model, omega)
    print(f"\n{model}, omega = {omega:g}, {periods} periods ({discard} discarded), cold start from the default y0")
    print(f"  {'tool':27s} {'accuracy':22s} {'setup s':>8s} {'setup note':32s} {'point s':>8s}  "
          f"{'lambda_1':>11s} {'sum+2z/w':>9s}  {'max|dlambda|':>12s} {'vs':9s} {'tol':>6s}")
    ok = True
    for name, acc, tool, r, against, diff, tol in rows:
        passed = diff is None or diff <= tol
        ok &= passed
        comp = "" if diff is None else f"{diff:12.2e} {against:9s} {tol:6.0e} {'ok' if passed else 'FAIL'}"
        print(f"  {name:27s} {acc:22s} {tool.setup_seconds:8.3f} {tool.setup_note:32s} {r.seconds:8.4f}  "
              f"{r.exponents[0]:+11.7f} {r.exponents.sum() - expected_sum:+9.1e}  {comp}")
    j, s = results["JiTCODE"], results["SciPy RK45"]
    d = float(np.max(np.abs(j.exponents - s.exponents)))
    ok &= d <= MUTUAL_TOL
    print(f"  JiTCODE vs SciPy RK45 (both Dormand-Prince 5(4), same tolerances): max |dlambda| {d:.2e} "
          f"(tol {MUTUAL_TOL:.0e} {'ok' if d <= MUTUAL_TOL else 'FAIL'}), "
          f"max |dy_end| {np.max(np.abs(j.final_state - s.final_state)):.2e}")
    print(f"  reference's own error (C 3200 vs C 12800 steps): max |dlambda| "
          f"{np.max(np.abs(r_ref.exponents - r_c12800.exponents)):.2e}")
    if not np.isnan(r_c200.final_state).any():
        print(f"  final state, Numba vs C 200: max |dy| "
              f"{np.max(np.abs(results['Numba RK4'].final_state - r_c200.final_state)):.2e}")
    return ok


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--omega", type=float, default=1.8, help="a point periodic in both models (default 1.8)")
    ap.add_argument("--periods", type=int, default=60)
    ap.add_argument("--discard", type=int, default=20)
    ap.add_argument("--model", choices=MODELS, action="append", help="default: both")
    args = ap.parse_args(argv)
    ok = all([check_model(m, args.omega, args.periods, args.discard) for m in args.model or MODELS])
    print("\nall checks passed" if ok else "\nSOME CHECKS FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
