"""Gears on bearings (issue 39): the 3-planet translational planetary set (Lin & Parker, 18 degrees of freedom),
measured in one run:

* declaration -> compiled library, from an empty cache, in a fresh process (``gearsym.load`` + ``compile_model``);
* the cached start-up: ``gearsym lyap planetary_translational --periods 10 --discard 0`` in fresh processes once
  the cache holds the model (median of REPEATS);
* time per RK4 step with the full tangent map: gearsym's compiled Lyapunov run against the hand-written C
  (``planetary_translational.c``: the same equations in the physical coordinates, before the reduction, its
  tangent product using the Jacobian's block structure), same steps per period, same periods, one after the
  other in this process; both give the exponents per unit tau, compared as a check that they integrate the same
  equations (the C has one more zero exponent pair: the rigid rotation it integrates);
* a periodic orbit with its Floquet multipliers (``gearsym.periodic_orbit``: transient, Newton, monodromy);
* for both models on bearings (``spur_pair_bearings`` and the planetary set), with the default integration (the
  step chosen from the fastest mode, crossings located): the library from an empty cache in a fresh process (the
  committed C compiled: load + gcc), and the Lyapunov spectrum's time per mesh period against SciPy's
  ``solve_ivp`` (DOP853, rtol = atol = 1e-8) of the same equations: the model's right-hand side and exact Jacobian
  (its CasADi functions, in-process) with the variational equations, re-orthonormalised each period; both from
  the same state on the attractor; the check that they integrate the same: the state after SciPy's periods and
  the largest exponents over them, gearsym run over the same periods from the same state.

    python -m bench.bearings            # writes bench/results/bearings.json
    python -m bench.bearings --quick    # fewer periods and repeats; writes nothing unless --out
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.machine import REPO, user_environment

MODEL = "planetary_translational"
MODELS = ("spur_pair_bearings", "planetary_translational")
#: mesh periods of the spectrum timed in gearsym, and in SciPy (far slower: a few)
SPECTRUM_PERIODS, SCIPY_PERIODS = 40, 10
HERE = Path(__file__).parent
STEPS, PERIODS, REPEATS = 256, 20, 5
VARIATION = 0.2  # every mesh's stiffness: its mean times 1 + VARIATION cos(phi), phi its mesh phase
TARGETS = {"compile_seconds": 60.0, "startup_seconds": 0.4, "step_ratio": 1.5, "orbit_seconds": 2.0}

_COMPILE = """
import json, sys, time
t = time.perf_counter()
import gearsym
system = gearsym.load(sys.argv[1])
loaded = time.perf_counter() - t
cm = gearsym.compile_model(system, gearsym.Integration(steps_per_period=int(sys.argv[2]), locate_crossings=False,
                                                       backend="compiled"))
print(json.dumps({"load_seconds": loaded, "timings": cm.timings, "total_seconds": time.perf_counter() - t}))
"""


def compile_time(cache: str) -> dict:
    env = {**os.environ, "GEARSYM_CACHE": cache}
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _COMPILE, MODEL, str(STEPS)], capture_output=True, text=True,
                          env=env, cwd=REPO)
    if proc.returncode:
        raise RuntimeError(proc.stderr[-2000:])
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_seconds"] = time.perf_counter() - t
    return out


def startup(cache: str, repeats: int) -> dict:
    env = {**user_environment("bearings"), "GEARSYM_CACHE": cache, "PYTHONPATH": str(REPO)}  # (bytecode kept)
    argv = [sys.executable, "-m", "gearsym.cli", "lyap", MODEL, "--periods", "10", "--discard", "0"]
    subprocess.run(argv, capture_output=True, env=env, cwd=REPO, check=True)  # fills the summaries
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        subprocess.run(argv, capture_output=True, env=env, cwd=REPO, check=True)
        times.append(time.perf_counter() - t)
    return {"command": " ".join(argv[2:]), "seconds": times, "median": statistics.median(times)}


def c_input(scaling, steps: int, periods: int) -> str:
    """The numbers of the hand-written C: the model's own rows, masses, stiffnesses, frame terms and torques in SI,
    time in tau = omega_f t (see planetary_translational.c)."""
    import sympy as sp

    from gearsym.model.translations import CARRIER_SPEED
    from gearsym.model.symbols import parameter_symbol, t

    rd = scaling.model.reduction.resolved
    si = dict(scaling.si_values)
    at = {parameter_symbol(k): v for k, v in si.items()}
    w = scaling.values["omega"] * scaling.omega_n_si
    n = len(rd.dofs)

    def num(e):
        return float(sp.sympify(rd.with_geometry(e)).xreplace(at))

    minv = [1 / num(d.inertia) for d in rd.dofs]
    kb, cb = np.zeros((n, n)), np.zeros((n, n))
    meshes = []
    for rc in rd.couplings:
        row = np.array([num(e) for e in rc.row])
        if rc.kind == "mesh":
            meshes.append((row, num(rc.stiffness), num(rc.damping), float(rc.planet_phase)))
        else:
            kb += num(rc.stiffness) * np.outer(row, row)
            cb += num(rc.damping) * np.outer(row, row)
    g, ko = np.zeros((n, n)), np.zeros((n, n))
    speed = float(rd.carrier_speed_ratio()) * w if rd.frame_turns else 0.0
    for i, force in enumerate(rd.frame_forces):
        force = force.xreplace({sp.Symbol(CARRIER_SPEED, real=True): speed}).xreplace(at)
        for j, d in enumerate(rd.dofs):
            g[i, j] = -float(sp.diff(force, sp.diff(d.angle, t))) if force != 0 else 0.0
            ko[i, j] = float(sp.diff(force, d.angle)) if force != 0 else 0.0
    f0, f1 = np.zeros(n), np.zeros(n)
    theta = 0.0
    for f in rd.forcing:
        value = num(f.amplitude)
        if f.order == 0:
            f0[f.body.index] += value
        else:
            f1[f.body.index] += value
            theta = num(f.phase)
    ka = VARIATION
    lines = [f"{n} {len(meshes)} {steps} {periods} {number(si['eta'])} {number(ka)} {number(theta)}"]
    lines.append(" ".join(number(x) for x in minv))
    for m in (kb / w**2, cb / w, g / w, ko / w**2):
        lines.append(" ".join(number(float(x)) for x in m.ravel()))
    lines.append(" ".join(number(float(x)) for row, *_ in meshes for x in row))
    lines.append(" ".join(number(k / w**2) for _, k, _, _ in meshes))
    lines.append(" ".join(number(c / w) for _, _, c, _ in meshes))
    lines.append(" ".join(number(p) for *_, p in meshes))
    lines.append(" ".join(number(x / w**2) for x in f0))
    lines.append(" ".join(number(x / w**2) for x in f1))
    lines.append(" ".join("0.0" for _ in range(2 * n)))
    return "\n".join(lines) + "\n"


def number(x) -> str:
    """A number as the C reads it (NumPy 2's repr of its floats is np.float64(...), which it does not)."""
    return repr(float(x))


def per_step(cache: str, steps: int, periods: int) -> dict:
    os.environ["GEARSYM_CACHE"] = cache
    import gearsym

    nd = gearsym.reduce(gearsym.load_model(MODEL))
    groups = {gr.name for gr in nd.groups if gr.role == "stiffness"}
    formulas = {}
    for f in nd.functions:  # (the C's stiffness: one harmonic; the model's relative stiffness K kept)
        k = sorted(s.name for s in f.expression.free_symbols if s.name in groups)
        formulas[f.name] = (f"{k[0]}*" if k else "") + f"(1+{VARIATION}*cos(phi))"
    scaling = gearsym.scaling(MODEL, **formulas)
    options = gearsym.Integration(steps_per_period=steps, periods=periods, discard=0, locate_crossings=False,
                                  backend="compiled")
    cm = gearsym.compile_model(scaling.system(), options)
    gearsym.lyapunov_spectrum(cm, options=options)  # (warm: pages, caches)
    t = time.perf_counter()
    spectrum = gearsym.lyapunov_spectrum(cm, options=options)
    gearsym_step = (time.perf_counter() - t) / (steps * periods)
    binary = Path(tempfile.mkdtemp()) / "planetary_translational"
    subprocess.run([shutil.which("gcc") or "cc", "-O3", "-std=gnu99", "-o", str(binary), str(HERE / f"{MODEL}.c"),
                    "-lm"], check=True, capture_output=True, text=True)
    data = binary.with_suffix(".txt")
    data.write_text(c_input(scaling, steps, periods))
    proc = subprocess.run([str(binary), str(data)], capture_output=True, text=True, check=True)
    lines = dict(line.split(" ", 1) for line in proc.stdout.strip().splitlines())
    c_step = float(lines["seconds_per_step"])
    c_exponents = sorted((float(x) for x in lines["exponents"].split()), reverse=True)
    t = time.perf_counter()
    orbit = gearsym.periodic_orbit(cm, options=gearsym.Integration(steps_per_period=steps, periods=60, discard=40,
                                                                   locate_crossings=False, backend="compiled"))
    orbit_seconds = time.perf_counter() - t
    return {"steps_per_period": steps, "periods": periods, "states": len(cm.state_names),
            "gearsym_seconds_per_step": gearsym_step, "c_seconds_per_step": c_step,
            "ratio": gearsym_step / c_step,
            "gearsym_exponents_top": [float(x) for x in spectrum.exponents[:4]],
            "c_exponents_top": c_exponents[:4],
            "orbit": {"seconds": orbit_seconds, "stable": bool(orbit.stable), "iterations": orbit.iterations,
                      "largest_multiplier": float(np.max(np.abs(orbit.multipliers)))}}


_DEFAULT_COMPILE = """
import json, sys, time
t = time.perf_counter()
import gearsym
system = gearsym.load(sys.argv[1])
loaded = time.perf_counter() - t
cm = gearsym.compile_model(system, gearsym.Integration(backend="compiled"))
print(json.dumps({"load_seconds": loaded, "timings": cm.timings, "total_seconds": time.perf_counter() - t,
                  "integration": cm.integration.choice, "states": cm.dimension}))
"""


def default_compile(model: str, cache: str) -> dict:
    """The model with the default integration, from an empty cache in a fresh process: its committed C compiled."""
    env = {**os.environ, "GEARSYM_CACHE": cache}
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _DEFAULT_COMPILE, model], capture_output=True, text=True, env=env,
                          cwd=REPO)
    if proc.returncode:
        raise RuntimeError(proc.stderr[-2000:])
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_seconds"] = time.perf_counter() - t
    c = REPO / "generated" / model / f"{model}.c"
    out["c_kib"] = round(c.stat().st_size / 1024) if c.is_file() else None
    return out


def spectrum_against_scipy(model: str, cache: str, periods: int, scipy_periods: int) -> dict:
    """gearsym's spectrum per mesh period (compiled, default integration) against SciPy's solve_ivp of the same
    equations with their variational equations, from the same state on the attractor."""
    from scipy.integrate import solve_ivp

    os.environ["GEARSYM_CACHE"] = cache
    import gearsym

    cm = gearsym.compile_model(gearsym.load(model), gearsym.Integration(backend="compiled"))
    settle = gearsym.lyapunov_spectrum(cm, options=cm.integration.run(periods=20, discard=0))  # (warm; a start)
    y0 = np.array(list(settle.final_state.values()))
    options = cm.integration.run(periods=periods, discard=0)
    t = time.perf_counter()
    spectrum = gearsym.lyapunov_spectrum(cm, options=options, y0=dict(settle.final_state))
    gearsym_period = (time.perf_counter() - t) / periods
    p, n, T = cm.parameter_vector(), cm.dimension, cm.prepare().period

    def variational(time_, z):
        y, Q = z[:n], z[n:].reshape(n, n)
        return np.concatenate([cm.rhs(time_, y, p), (cm.jacobian(time_, y, p) @ Q).ravel()])

    y, Q, logs, evaluations = y0, np.eye(n), np.zeros(n), 0
    t = time.perf_counter()
    for k in range(scipy_periods):  # (the spectrum's start is at t = 0 of the forcing: whole periods on)
        sol = solve_ivp(variational, (k * T, (k + 1) * T), np.concatenate([y, Q.ravel()]), method="DOP853",
                        rtol=1e-8, atol=1e-8)
        evaluations += sol.nfev
        y, Q = sol.y[:n, -1], sol.y[n:, -1].reshape(n, n)
        Q, R = np.linalg.qr(Q)
        signs = np.sign(np.diag(R))
        Q, logs = Q * signs, logs + np.log(np.abs(np.diag(R)))
    scipy_period = (time.perf_counter() - t) / scipy_periods
    # the check: gearsym over the same periods from the same state (its exponents from the same Gram-Schmidt)
    same = gearsym.lyapunov_spectrum(cm, options=cm.integration.run(periods=scipy_periods, discard=0),
                                     y0=dict(settle.final_state))
    y_gearsym = np.array(list(same.final_state.values()))
    return {"states": n, "integration": cm.integration.choice, "gearsym_periods": periods,
            "scipy_periods": scipy_periods, "gearsym_seconds_per_period": gearsym_period,
            "scipy_seconds_per_period": scipy_period, "scipy_over_gearsym": scipy_period / gearsym_period,
            "scipy_rhs_evaluations_per_period": evaluations / scipy_periods,
            "gearsym_largest_exponents": [float(x) for x in spectrum.exponents[:3]],
            "check_over_the_scipy_periods": {
                "state_difference_relative": float(np.max(np.abs(y_gearsym - y)) / np.max(np.abs(y))),
                "gearsym_largest_exponents": [float(x) for x in same.exponents[:3]],
                "scipy_largest_exponents": sorted((float(x) for x in logs / (scipy_periods * T)), reverse=True)[:3]}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.bearings", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    periods, repeats = (4, 2) if args.quick else (PERIODS, REPEATS)
    out = {"model": MODEL, "targets": TARGETS, "load_at_start": os.getloadavg()[0], "cpus": os.cpu_count()}
    with tempfile.TemporaryDirectory() as cache:
        out["compile"] = compile_time(cache)
        print(f"declaration -> compiled library: {out['compile']['process_seconds']:.1f} s", file=sys.stderr)
        out["startup"] = startup(cache, repeats)
        print(f"cached start-up: {out['startup']['median']:.3f} s", file=sys.stderr)
        try:
            out["step"] = per_step(cache, STEPS, periods)
        except subprocess.CalledProcessError as exc:  # (recorded as failed; the other stages still run)
            out["step"] = {"error": f"{' '.join(map(str, exc.cmd))}: exit {exc.returncode}: {exc.stderr}"}
            print(f"per RK4 step: failed: {out['step']['error']}", file=sys.stderr)
        else:
            print(f"per RK4 step with the tangent map: gearsym {out['step']['gearsym_seconds_per_step'] * 1e6:.2f} "
                  f"us, hand-written C {out['step']['c_seconds_per_step'] * 1e6:.2f} us (x{out['step']['ratio']:.2f}); "
                  f"periodic orbit {out['step']['orbit']['seconds']:.2f} s", file=sys.stderr)
    spectrum_periods, scipy_periods = (8, 1) if args.quick else (SPECTRUM_PERIODS, SCIPY_PERIODS)
    out["models"] = {}
    for model in MODELS:
        with tempfile.TemporaryDirectory() as cache:
            row = {"compile": default_compile(model, cache)}
            print(f"{model}: library from an empty cache {row['compile']['process_seconds']:.1f} s "
                  f"(gcc {row['compile']['timings'].get('compile', 0):.1f} s)", file=sys.stderr)
            row["spectrum"] = spectrum_against_scipy(model, cache, spectrum_periods, scipy_periods)
            s = row["spectrum"]
            print(f"{model}: spectrum per mesh period gearsym {s['gearsym_seconds_per_period'] * 1e3:.3f} ms, SciPy "
                  f"DOP853 {s['scipy_seconds_per_period'] * 1e3:.1f} ms (x{s['scipy_over_gearsym']:.0f})",
                  file=sys.stderr)
            out["models"][model] = row
    out["load_at_end"] = os.getloadavg()[0]
    target = args.out or (None if args.quick else REPO / "bench" / "results" / "bearings.json")
    if target:
        Path(target).write_text(json.dumps(out, indent=2) + "\n")
        print(f"wrote {target}", file=sys.stderr)
    else:
        print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
