"""``python -m bench.stiff``: the two-stage gearbox (10 states, models/two_stage_gearbox.py) at 1500 rpm, one run
(issue 38): its Lyapunov spectrum and ``explain --fit zeta`` on 12,200 samples, in gearsym against SciPy's Radau and
a hand-tuned RK4 at its stability limit.

* **lyap**, over 4 periods of the box (244 mesh periods of its first stage; the engine runs whole periods of 61 mesh
  periods, the nearest to the issue's 200 above it), from the model's start, compile time apart (each library
  compiled before it is timed):

  - gearsym, ``integrator="auto"``: RK4 at the steps that resolve the fastest mode (400 per mesh period);
  - gearsym, the stiff RODAS4 at 200 steps per mesh period;
  - a hand-tuned RK4 at its stability limit (h |lambda_max| = 2.5: 50 steps per mesh period), gearsym's own C loop
    (``integrator="rk4"``): what a user who tuned the step by hand runs; its fast exponents are reported as not
    resolved, never as values;
  - SciPy's Radau (rtol 1e-8, atol 1e-10) on the state and its 10 tangent vectors with the exact Jacobian (the
    compiled model's own rhs and Jacobian, called from Python), QR every mesh period, over 10 mesh periods: its
    seconds per mesh period, times 244 for the same run.

  Exponents per second beside each, and against the linearised modes' decay rates (the Jacobian averaged over a
  mesh period at the run's final state).
* **explain --fit zeta** on 12,200 samples (61 mesh periods at 200 samples per mesh period, 1 % noise, after 100
  periods of transient): the whole library, in a fresh process with an empty compile cache (compiling the
  candidates' windows is part of the time, as for a user's first run), and again with the cache warm; wall and CPU
  seconds. Beside it, one evaluation of the model over the record's 46 training windows (each from its start
  state, its samples 2 steps apart): gearsym's compiled windows with their derivatives by the start states and
  zeta, a hand-tuned RK4 in NumPy at its stability limit (states only), and SciPy Radau (states only).

Writes bench/results/stiff.json with the load average at the start (the machine is shared: CPU seconds are the
fairer measure).
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
DEFAULT_OUT = REPO / "bench" / "results" / "stiff.json"
PERIODS = 4  # of 61 mesh periods each
RADAU_MESH_PERIODS = 10

_SIMULATE = ["gearsym", "simulate", "two_stage_gearbox", "--samples-per-period", "200", "--periods", "101",
             "--discard", "100", "--noise", "0.01", "--seed", "1"]

_CHILD = r"""
import json, os, sys, time
args = json.loads(sys.argv[1])
start, cpu = time.perf_counter(), time.process_time()
import gearsym
from gearsym import explain, load_measurements
system = gearsym.load("two_stage_gearbox")
data = load_measurements([args["data"]], system, time_scale=None)
ex = explain(system, data, ["zeta"])
children = os.times()
print(json.dumps({"seconds": time.perf_counter() - start, "cpu_seconds": time.process_time() - cpu
                  + children.children_user + children.children_system, "effects": list(ex.effects),
                  "error_before": ex.base.error, "error_after": ex.final.error, "candidates_tried": len(ex.tried),
                  "zeta": ex.final.fit.estimates.get("zeta")}))
"""


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def timed(run):
    start, cpu = time.perf_counter(), time.process_time()
    out = run()
    return out, time.perf_counter() - start, time.process_time() - cpu


def lyap_rows(system, scaling) -> tuple[list[dict], dict]:
    import gearsym
    from gearsym import Integration
    from gearsym.analysis.resolution import linearised_eigenvalues

    per_second = system.parameters["omega"] * scaling.point_units().omega_n
    rows = []
    cases = (("gearsym auto (RK4, resolved)", Integration(periods=PERIODS, discard=1)),
             ("gearsym stiff (RODAS4, 200 per mesh period)", Integration(periods=PERIODS, discard=1,
                                                                         integrator="stiff")),
             ("hand-tuned RK4 at its stability limit (50 per mesh period)",
              Integration(periods=PERIODS, discard=1, integrator="rk4", steps_per_period=50)))
    reference = None
    for name, options in cases:
        log(f"lyap: {name}: compiling")
        model, compile_seconds, _ = timed(lambda: gearsym.compile_model(system, options))
        log(f"lyap: {name}: running")
        result, seconds, cpu = timed(lambda: gearsym.lyapunov_spectrum(model))
        resolved = list(result.resolution.resolved) if result.resolution else [True] * len(result.exponents)
        rows.append({"tool": name, "steps_per_mesh_period": model.steps_per_cycle,
                     "choice": model.integration.choice, "compile_seconds": compile_seconds, "seconds": seconds,
                     "cpu_seconds": cpu, "mesh_periods": PERIODS * model.cycles,
                     "seconds_per_mesh_period": seconds / (PERIODS * model.cycles),
                     "exponents_per_second": [float(v * per_second) if ok else None
                                              for v, ok in zip(result.exponents, resolved)],
                     "sum_per_second": float(result.sum * per_second)})
        if reference is None:
            reference = (model, result)
    model, result = reference
    mu = linearised_eigenvalues(model, np.array(list(result.final_state.values())), model.parameter_vector(),
                                result.period / model.cycles)
    linear = {"decay_rates_per_second": sorted((float(m.real * per_second) for m in mu), reverse=True)}
    rows.append(radau_row(model, result, per_second))
    return rows, linear


def radau_row(model, result, per_second: float) -> dict:
    """SciPy Radau on the state and its tangent vectors, QR every mesh period, over RADAU_MESH_PERIODS."""
    from scipy.integrate import solve_ivp

    rhs, jacobian = model.functions["rhs"], model.functions["jacobian"]
    p = model.parameter_vector()
    n = model.dimension
    cycle = model.system.cycle_at()

    def f(t, z):
        y, Q = z[:n], z[n:].reshape(n, n)
        J = np.array(jacobian(t, y, p))
        return np.concatenate([np.array(rhs(t, y, p)).ravel(), (J @ Q).ravel()])

    def jac(t, z):
        J = np.array(jacobian(t, z[:n], p))
        return _augmented(J, n)

    y, Q, logs = np.array(list(result.final_state.values())), np.eye(n), np.zeros(n)
    log("lyap: SciPy Radau")
    start, cpu = time.perf_counter(), time.process_time()
    steps = 0
    for k in range(RADAU_MESH_PERIODS):
        sol = solve_ivp(f, (k * cycle, (k + 1) * cycle), np.concatenate([y, Q.ravel()]), method="Radau",
                        rtol=1e-8, atol=1e-10, jac=jac)
        steps += sol.t.size - 1
        y, M = sol.y[:n, -1], sol.y[n:, -1].reshape(n, n)
        Q, R = np.linalg.qr(M)
        logs += np.log(np.abs(np.diag(R)))
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    rates = np.sort(logs / (RADAU_MESH_PERIODS * cycle) * per_second)[::-1]
    return {"tool": "SciPy Radau (rtol 1e-8, exact Jacobian, QR every mesh period)", "mesh_periods": RADAU_MESH_PERIODS,
            "seconds": seconds, "cpu_seconds": cpu, "seconds_per_mesh_period": seconds / RADAU_MESH_PERIODS,
            "steps_per_mesh_period": steps / RADAU_MESH_PERIODS,
            "exponents_per_second": [float(v) for v in rates],
            "note": f"over {RADAU_MESH_PERIODS} mesh periods from gearsym's final state (too short for the slow pair)"}


def _augmented(J: np.ndarray, n: int) -> np.ndarray:
    """The Jacobian of (y, Q) -> (f, J Q), without the Hessian's terms (J does not depend on y within one side of
    the backlash): block-diagonal J."""
    return np.kron(np.eye(n + 1), J)


def explain_rows(tmp: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(REPO), "GEARSYM_CACHE": str(tmp / "cache")}
    data = tmp / "box.csv"
    log("explain: simulating the record (12,200 samples)")
    subprocess.run([*_SIMULATE, "--out", str(data)], check=True, capture_output=True, env=env)
    out = {}
    for what in ("cold", "warm"):
        log(f"explain: {what}")
        done = subprocess.run([sys.executable, "-c", _CHILD, json.dumps({"data": str(data)})], env=env, cwd=REPO,
                              capture_output=True, text=True)
        if done.returncode:
            raise RuntimeError(done.stderr[-2000:])
        out[what] = json.loads(done.stdout.strip().splitlines()[-1])
    out["samples"] = sum(1 for _ in data.open()) - 1
    return out


def evaluation_rows(system) -> list[dict]:
    """One evaluation of the model over 46 windows of 200 samples (2 steps apart): gearsym's windows with the
    derivatives by start states and zeta, a NumPy RK4 at the stability limit, SciPy Radau."""
    from scipy.integrate import solve_ivp

    import gearsym
    from gearsym import Integration
    from gearsym.codegen.windows import compile_windows

    windows, samples = 46, 200
    cycle = system.cycle_at()
    dt = cycle / samples
    model = gearsym.compile_model(system, Integration(periods=2, discard=1))
    run = gearsym.phase_trajectory(model, options=model.integration.run(periods=2, discard=1))
    stride = model.steps_per_cycle // samples
    starts = run.states[:, ::stride][:, ::samples][:, :windows]
    t0 = [k * cycle for k in range(windows)]
    p = np.array([[system.parameters[name] for name in system.parameters]] * windows).T
    engine = compile_windows(system, [], "auto")
    rows = []
    for tangent in (True, False):
        _, seconds, cpu = timed(lambda: engine.run(starts, t0, [dt] * windows, [samples] * windows, [2] * windows, p,
                                                   tangent=tangent))
        rows.append({"tool": f"gearsym windows ({'with' if tangent else 'without'} derivatives, RK4 400 per mesh "
                             "period)", "seconds": seconds, "cpu_seconds": cpu})
    rhs = model.functions["rhs"]
    pv = model.parameter_vector()

    def f(t, y):
        return np.array(rhs(t, y, pv)).ravel()

    def numpy_rk4():
        h = cycle / 50
        for k in range(windows):
            y = starts[:, k].copy()
            for i in range(50):  # (one mesh period a window)
                t = t0[k] + i * h
                k1 = f(t, y); k2 = f(t + h / 2, y + h / 2 * k1); k3 = f(t + h / 2, y + h / 2 * k2)
                k4 = f(t + h, y + h * k3)
                y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    _, seconds, cpu = timed(numpy_rk4)
    rows.append({"tool": "hand-tuned RK4 in NumPy at its stability limit (50 per mesh period, states only)",
                 "seconds": seconds, "cpu_seconds": cpu})
    jacobian = model.functions["jacobian"]

    def radau():
        for k in range(windows):
            solve_ivp(f, (t0[k], t0[k] + cycle), starts[:, k], method="Radau", rtol=1e-8, atol=1e-10,
                      t_eval=t0[k] + dt * np.arange(samples), jac=lambda t, y: np.array(jacobian(t, y, pv)))
    _, seconds, cpu = timed(radau)
    rows.append({"tool": "SciPy Radau (rtol 1e-8, exact Jacobian, states only)", "seconds": seconds,
                 "cpu_seconds": cpu})
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.stiff", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    parser.add_argument("--skip-explain", action="store_true", help="the lyap rows only")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO))
    import gearsym

    results = {"command": "python -m bench.stiff",
               "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "commit": subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True,
                                        text=True).stdout.strip(),
               "cores": os.cpu_count(), "loadavg_at_start": list(os.getloadavg())}
    scaling = gearsym.scaling("two_stage_gearbox")
    system = scaling.system()
    results["lyap"], results["linearised"] = lyap_rows(system, scaling)
    results["evaluation"] = evaluation_rows(system)
    if not args.skip_explain:
        with tempfile.TemporaryDirectory(prefix="gearsym-bench-stiff-") as tmp:
            results["explain"] = explain_rows(Path(tmp))
    results["loadavg_at_end"] = list(os.getloadavg())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1) + "\n")
    log(f"wrote {args.out}")
    for row in results["lyap"]:
        log(f"{row['tool']}: {row['seconds_per_mesh_period'] * 1e3:.3g} ms per mesh period")
    return 0


if __name__ == "__main__":
    sys.exit(main())
