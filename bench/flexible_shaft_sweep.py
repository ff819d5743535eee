#!/usr/bin/env python3
"""Benchmark: gearsym's Lyapunov-spectrum sweep of the flexible-shaft model
against the hand-written C yardstick (bench/yardstick/flexible_shaft.c).

    python bench/flexible_shaft_sweep.py [--quick] [--repeats R] [--out FILE.json]

The sweep: omega = 0.1 + 0.01 i, i = 0..190 (191 points), 400 forcing periods
per point of which the first 100 are discarded, 200 RK4 steps per period, the
first point starting at (x1, v1, x2, v2) = (-2, -0.5, 0, 0), every further point
from the previous point's final state (continuation), tangent vectors reset to
the identity at every point. Model parameters: gearsym's defaults, passed to
the C program explicitly so that both tools integrate the same system.

Everything happens in one process run, so the ratio compares like with like
on whatever the (shared, noisy) machine is doing at the time:

* the yardstick is built three ways (``-O3``; ``-O3 -march=native``; the
  hand-tuned ``-O3 -march=native -mprefer-vector-width=128``), in GNU C mode
  so that FMA contraction is allowed as in gearsym's build; all are timed and
  the fastest one is the reference;
* repetitions are interleaved (yardstick builds, gearsym, gearsym via
  ``lyapunov_spectrum``, then again, R times) and the minimum and the median
  of each are reported, with ratios gearsym / reference of minima and of
  medians (target <= 1);
* the yardstick's time is the C program's own clock around its sweep loop
  (process start-up and output excluded); gearsym's is ``time.perf_counter``
  around the Python sweep loop (per point: parameter vector, ``prepare``,
  ``tangent_run``, exponents), after ``compile_model``, which is setup;
* correctness is checked on the same runs: per-point exponents in
  Gram-Schmidt order against the yardstick, sum of exponents against the
  exact -2 zeta/omega, and a cold-start single point (no continuation).

See bench/README.md for how to read the output.
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime as _dt
import json
import math
import shlex
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from bench.speed.machine import machine_info  # noqa: E402
from bench.yardstick import runner  # noqa: E402

MODEL = "flexible_shaft"
Y0 = (-2.0, -0.5, 0.0, 0.0)
YARDSTICK_FLAGS = (
    ("-O3",),
    ("-O3", "-march=native"),
    # the best hand-tuned build found on this machine: FMA, but 128-bit vectors for the dense 4x4 product
    ("-O3", "-march=native", "-mprefer-vector-width=128"),
)
PERIODIC = -1e-3  # a point is "clearly periodic" if its largest exponent is below this
COLD_START = ((0.2, 50), (1.0, 50))  # (omega, periods) of the cold-start scheme check


@dataclasses.dataclass(frozen=True)
class Sweep:
    omega_start: float
    omega_stop: float
    omega_step: float
    periods: int
    discard: int
    steps: int

    @property
    def points(self) -> int:  # the C program's own count (tolerance for 189.999..)
        return int(math.floor((self.omega_stop - self.omega_start) / self.omega_step + 1e-9)) + 1

    def omegas(self) -> list[float]:  # the same floating-point expression as the C program
        return [self.omega_start + self.omega_step * i for i in range(self.points)]

    @property
    def steps_total(self) -> int:
        return self.points * self.periods * self.steps


FULL = Sweep(0.1, 2.0, 0.01, 400, 100, 200)
QUICK = Sweep(0.1, 2.0, 0.1, 100, 25, 200)  # every 10th point, 100 periods


# ============================================================================ gearsym
def gearsym_sweep(cm, sweep: Sweep, y0=Y0) -> tuple[float, dict]:
    """The low-level sweep, timed: what a continuation sweep in gearsym does."""
    omegas = sweep.omegas()
    P, D = sweep.periods, sweep.discard
    n = len(omegas)
    lam = np.empty((n, 4))
    amp = np.empty((n, 2))
    starts = np.empty((n, 4))
    y = np.asarray(y0, dtype=float)
    start = time.perf_counter()
    for i, w in enumerate(omegas):
        starts[i] = y
        inp = cm.prepare(cm.parameter_vector(omega=w))
        run = cm.tangent_run(y, P, inp)
        lam[i] = run.log_stretch[:, D:].sum(axis=1) / ((P - D) * inp.period)
        amp[i] = 0.5 * (run.high[:, D:].max(axis=1) - run.low[:, D:].min(axis=1))
        y = run.strobe[:, -1]
    seconds = time.perf_counter() - start
    return seconds, {"omega": np.array(omegas), "exponents": lam, "amplitude": amp, "final_state": y,
                     "start_states": starts}


def gearsym_sweep_highlevel(cm, sweep: Sweep, y0=Y0) -> tuple[float, dict]:
    """The same sweep through ``gearsym.analysis.lyapunov_spectrum`` (sorted exponents, stats)."""
    from gearsym.analysis import lyapunov_spectrum

    omegas = sweep.omegas()
    n = len(omegas)
    lam = np.empty((n, 4))
    amp = np.empty((n, 2))
    y = np.asarray(y0, dtype=float)
    names = cm.state_names
    start = time.perf_counter()
    for i, w in enumerate(omegas):
        res = lyapunov_spectrum(cm, periods=sweep.periods, discard=sweep.discard, y0=y, omega=w)
        lam[i] = res.exponents
        amp[i] = [res.amplitude[k] for k in cm.observed]
        y = np.array([res.final_state[s] for s in names])
    seconds = time.perf_counter() - start
    return seconds, {"omega": np.array(omegas), "exponents": lam, "amplitude": amp, "final_state": y}


class _TimedNative:
    """Wraps a NativeFunction (the compiled backend's direct C call); accumulates the wall time of its calls."""

    def __init__(self, f):
        self.f, self.seconds, self.calls = f, 0.0, 0

    def call(self, args, results):
        t = time.perf_counter()
        self.f.call(args, results)
        self.seconds += time.perf_counter() - t
        self.calls += 1

    def __call__(self, *arrays):
        t = time.perf_counter()
        out = self.f(*arrays)
        self.seconds += time.perf_counter() - t
        self.calls += 1
        return out


def profile_gearsym(cm, sweep: Sweep, yard_point_seconds: np.ndarray) -> dict:
    """Where gearsym's sweep time goes (one instrumented pass, not used for the ratio)."""
    if not cm.native:
        raise RuntimeError("the profile needs the compiled backend (a C compiler)")
    wrapped = {name: _TimedNative(f) for name, f in cm.native.items()}
    tcm = dataclasses.replace(cm, native=wrapped)
    omegas = sweep.omegas()
    P, D = sweep.periods, sweep.discard
    t_param = t_prepare = t_run = t_post = 0.0
    y = np.asarray(Y0, dtype=float)
    start = time.perf_counter()
    for w in omegas:
        t0 = time.perf_counter()
        p = tcm.parameter_vector(omega=w)
        t1 = time.perf_counter()
        inp = tcm.prepare(p)
        t2 = time.perf_counter()
        run = tcm.tangent_run(y, P, inp)
        t3 = time.perf_counter()
        run.log_stretch[:, D:].sum(axis=1) / ((P - D) * inp.period)
        0.5 * (run.high[:, D:].max(axis=1) - run.low[:, D:].min(axis=1))
        y = run.strobe[:, -1]
        t4 = time.perf_counter()
        t_param += t1 - t0
        t_prepare += t2 - t1
        t_run += t3 - t2
        t_post += t4 - t3
    total = time.perf_counter() - start
    calls = {k: (v.seconds, v.calls) for k, v in wrapped.items() if v.calls}
    loop_c = sum(v.seconds for k, v in wrapped.items() if k in ("lyapunov_chunk", "lyapunov_period"))
    n_loop_calls = sum(v.calls for k, v in wrapped.items() if k in ("lyapunov_chunk", "lyapunov_period"))

    # one point: the raw C calls of a 400-period run vs tangent_run around them
    w = 0.2
    inp = cm.prepare(cm.parameter_vector(omega=w))
    chunk = cm.options.chunk_periods
    n_chunks = 400 // chunk
    f_chunk = cm.native["lyapunov_chunk"]
    table, c = np.asfortranarray(inp.table), inp.constants
    yy, Qa, Qb = np.array(Y0, dtype=float), np.asfortranarray(np.eye(4)), np.asfortranarray(np.eye(4))
    strobe, logs = np.empty((4, chunk), order="F"), np.empty((4, chunk), order="F")
    low, high = np.empty((2, chunk), order="F"), np.empty((2, chunk), order="F")
    raw, tr = [], []
    for _ in range(5):
        t = time.perf_counter()
        for _ in range(n_chunks):
            f_chunk.call([yy.ctypes.data, Qa.ctypes.data, table.ctypes.data, c.ctypes.data],
                         [strobe.ctypes.data, Qb.ctypes.data, logs.ctypes.data, low.ctypes.data, high.ctypes.data])
        raw.append(time.perf_counter() - t)
        t = time.perf_counter()
        cm.tangent_run(np.array(Y0), n_chunks * chunk, inp)
        tr.append(time.perf_counter() - t)
    prep = []
    p = cm.parameter_vector(omega=w)
    for _ in range(5):
        t = time.perf_counter()
        for _ in range(20):
            cm.prepare(p)
        prep.append((time.perf_counter() - t) / 20)
    steps400 = n_chunks * chunk * cm.steps_per_period
    return {
        "sweep": {
            "total_seconds": total,
            "parameter_vector_seconds": t_param,
            "prepare_seconds": t_prepare,
            "tangent_run_seconds": t_run,
            "loop_c_calls_seconds": loop_c,
            "loop_c_calls": n_loop_calls,
            "tangent_run_python_seconds": t_run - loop_c,
            "exponents_and_carry_seconds": t_post,
            "calls": {k: {"seconds": s, "calls": n} for k, (s, n) in calls.items()},
        },
        "point": {
            "omega": w,
            "periods": n_chunks * chunk,
            "raw_chunk_calls": n_chunks,
            "raw_chunk_calls_seconds_min": min(raw),
            "tangent_run_seconds_min": min(tr),
            "prepare_seconds_min": min(prep),
            "gearsym_ns_per_step_raw": min(raw) / steps400 * 1e9,
            "yardstick_point_seconds_median": float(np.median(yard_point_seconds)),
            "yardstick_ns_per_step": float(np.median(yard_point_seconds)) / (sweep.periods * sweep.steps) * 1e9,
        },
    }


# ============================================================================ checks
def compare(yard: dict, gs: dict, gs_hl: dict, zeta: float) -> dict:
    om = yard["omega"]
    omega_diff = float(np.max(np.abs(om - gs["omega"]))) if om.shape == gs["omega"].shape else math.inf
    if not omega_diff <= 1e-12:  # an FMA build of the yardstick may round w_start + w_step*i differently
        raise RuntimeError(f"omega grids differ: max |d| = {omega_diff}")
    ly, lg = yard["exponents"], gs["exponents"]
    diff = np.abs(ly - lg).max(axis=1)
    per_y = ly[:, 0] < PERIODIC
    per_both = per_y & (lg[:, 0] < PERIODIC)
    settled = per_both & np.concatenate([[True], per_both[:-1]])  # this and the previous point periodic in both
    exact = -2.0 * zeta / om

    def worst(mask):
        if not mask.any():
            return {"count": 0, "max_abs_diff": None, "at_omega": None}
        i = int(np.flatnonzero(mask)[np.argmax(diff[mask])])
        return {"count": int(mask.sum()), "max_abs_diff": float(diff[i]), "at_omega": float(om[i])}

    big = np.flatnonzero(diff > 1e-9)
    return {
        "omega_grid_max_abs_diff": omega_diff,
        "all_points": worst(np.ones_like(per_y)),
        "periodic_yardstick": worst(per_y),
        "periodic_both": worst(per_both),
        "periodic_both_and_previous": worst(settled),
        "points_over_1e-9": [
            {"omega": float(om[i]), "lambda1_yardstick": float(ly[i, 0]), "lambda1_gearsym": float(lg[i, 0]),
             "max_abs_diff": float(diff[i]), "periodic_yardstick": bool(per_y[i])} for i in big],
        "amplitude_max_abs_diff_settled": (float(np.abs(yard["amplitude"] - gs["amplitude"])[settled].max())
                                           if settled.any() else None),
        "sum_check_max_abs": {
            "yardstick": float(np.max(np.abs(ly.sum(axis=1) - exact))),
            "gearsym": float(np.max(np.abs(lg.sum(axis=1) - exact))),
            "gearsym_lyapunov_spectrum": float(np.max(np.abs(gs_hl["exponents"].sum(axis=1) - exact))),
            "at_omega_gearsym": float(om[np.argmax(np.abs(lg.sum(axis=1) - exact))]),
        },
        "lyapunov_spectrum_vs_lowlevel_sorted_max_abs_diff": float(np.max(np.abs(
            np.sort(lg, axis=1)[:, ::-1] - gs_hl["exponents"]))),
        "per_point_max_abs_diff": diff.tolist(),
    }


def same_start(binary, gs: dict, sweep: Sweep, params: dict, variant: str) -> dict:
    """Every point once more in the yardstick, from the state gearsym started that point from.

    Removes the continuation's memory: both tools integrate the same initial
    value problem at every point, so any difference is the scheme plus
    rounding (amplified only where the point itself is chaotic).
    """
    om, starts, lg = gs["omega"], gs["start_states"], gs["exponents"]
    ly = np.empty_like(lg)
    t = time.perf_counter()
    for i, w in enumerate(om):
        r = runner.run(binary, variant=variant, steps=sweep.steps, periods=sweep.periods, discard=sweep.discard,
                       omega_start=float(w), omega_stop=float(w), omega_step=0.01, y0=tuple(starts[i]), **params)
        ly[i] = r["exponents"][0]
    seconds = time.perf_counter() - t
    diff = np.abs(ly - lg).max(axis=1)
    per = (ly[:, 0] < PERIODIC) & (lg[:, 0] < PERIODIC)
    worst = int(np.argmax(np.where(per, diff, -1.0))) if per.any() else None
    return {
        "seconds": seconds,
        "all_points_max_abs_diff": float(diff.max()),
        "all_points_at_omega": float(om[int(np.argmax(diff))]),
        "periodic_count": int(per.sum()),
        "periodic_max_abs_diff": float(diff[worst]) if worst is not None else None,
        "periodic_at_omega": float(om[worst]) if worst is not None else None,
        "points_over_1e-9": int((diff > 1e-9).sum()),
        "per_point_max_abs_diff": diff.tolist(),
    }


def cold_start(cm, binaries: dict, params: dict, steps: int) -> list[dict]:
    """One point from (-2, -0.5, 0, 0), no continuation, no discard: isolates the scheme."""
    out = []
    for w, periods in COLD_START:
        inp = cm.prepare(cm.parameter_vector(omega=w))
        run = cm.tangent_run(np.array(Y0), periods, inp)
        lg = run.log_stretch.sum(axis=1) / (periods * inp.period)
        ag = 0.5 * (run.high.max(axis=1) - run.low.min(axis=1))
        row = {"omega": w, "periods": periods, "gearsym": lg.tolist()}
        for label, binary in binaries.items():
            r = runner.run(binary, steps=steps, periods=periods, discard=0, omega_start=w, omega_stop=w,
                           omega_step=0.01, y0=Y0, **params)
            row[label] = {"exponents": r["exponents"][0].tolist(),
                          "max_abs_diff": float(np.max(np.abs(r["exponents"][0] - lg))),
                          "max_rel_diff": float(np.max(np.abs(r["exponents"][0] - lg) / np.abs(lg))),
                          "amplitude_max_abs_diff": float(np.max(np.abs(r["amplitude"][0] - ag)))}
        out.append(row)
    return out


# ============================================================================ report
def stats(xs: list[float]) -> dict:
    return {"min": min(xs), "median": statistics.median(xs), "max": max(xs), "all": list(xs)}


def fmt_s(x: float) -> str:
    return f"{x:8.3f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="smoke test: every 10th point, 100 periods (25 discarded)")
    ap.add_argument("--repeats", type=int, default=3, help="interleaved repetitions (default 3)")
    ap.add_argument("--out", type=Path, help="write all numbers to this JSON file")
    ap.add_argument("--cc", default="gcc", help="compiler for the yardstick (default gcc)")
    ap.add_argument("--variant", default="table", choices=("table", "direct"),
                    help="yardstick variant (default table: per-point tables of k(tau) and the forcing)")
    ap.add_argument("--no-profile", action="store_true", help="skip the time breakdown of gearsym's sweep")
    ap.add_argument("--extra-build", action="append", default=[], metavar="FLAGS",
                    help="also build and time the yardstick with these flags (quoted, repeatable), e.g. "
                         "--extra-build '-O3 -march=native -ffp-contract=fast'; it competes for the reference")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be at least 1")
    sweep = QUICK if args.quick else FULL
    started = _dt.datetime.now(_dt.timezone.utc)
    info = machine_info(args.cc)

    # ------------------------------------------------------------------ setup
    setup: dict = {}
    binaries = {}
    for flags in [*YARDSTICK_FLAGS, *(tuple(shlex.split(f)) for f in args.extra_build)]:
        label = "C " + " ".join(flags)
        t = time.perf_counter()
        binaries[label] = runner.build(cc=args.cc, flags=flags)
        setup[f"yardstick build {' '.join(flags)}"] = time.perf_counter() - t
    t = time.perf_counter()
    from gearsym.codegen import compile_model
    from gearsym.codegen.compiler import compile_flags
    cm = compile_model(MODEL, steps_per_period=sweep.steps)
    setup["gearsym compile_model (first call, incl. import)"] = time.perf_counter() - t
    gearsym_timings = dict(cm.timings)
    t = time.perf_counter()
    cm = compile_model(MODEL, steps_per_period=sweep.steps)
    setup["gearsym compile_model (second call)"] = time.perf_counter() - t
    if cm.backend != "compiled":
        print(f"warning: gearsym backend is {cm.backend!r}, not 'compiled'", file=sys.stderr)
    params = {k: float(v) for k, v in cm.system.parameters.items() if k != "omega"}
    if set(params) != set(runner.PARAMS):
        raise SystemExit(f"gearsym's parameters {sorted(params)} and the yardstick's {sorted(runner.PARAMS)} differ")
    zeta = float(cm.system.parameters["zeta"])

    # warm-up (untimed): page in the binaries and the library
    for binary in binaries.values():
        runner.run(binary, variant=args.variant, steps=sweep.steps, periods=2, discard=1,
                   omega_start=0.2, omega_stop=0.2, omega_step=0.01, y0=Y0, **params)
    cm.tangent_run(np.array(Y0), cm.options.chunk_periods + 1, cm.prepare(cm.parameter_vector(omega=0.2)))

    # ------------------------------------------------------------------ timed, interleaved
    times: dict[str, list[float]] = {label: [] for label in binaries}
    wall: dict[str, list[float]] = {label: [] for label in binaries}
    times["gearsym"], times["gearsym lyapunov_spectrum"] = [], []
    results: dict[str, list[dict]] = {k: [] for k in times}
    ykw = dict(variant=args.variant, steps=sweep.steps, periods=sweep.periods, discard=sweep.discard,
               omega_start=sweep.omega_start, omega_stop=sweep.omega_stop, omega_step=sweep.omega_step,
               y0=Y0, **params)
    print(f"running {args.repeats} interleaved repetition(s) of the {'quick' if args.quick else 'full'} sweep "
          f"({sweep.points} points x {sweep.periods} periods) ...", file=sys.stderr, flush=True)
    for rep in range(args.repeats):
        for label, binary in binaries.items():
            t = time.perf_counter()
            r = runner.run(binary, **ykw)
            wall[label].append(time.perf_counter() - t)
            times[label].append(r["total_seconds"])
            results[label].append(r)
        s, r = gearsym_sweep(cm, sweep)
        times["gearsym"].append(s)
        results["gearsym"].append(r)
        s, r = gearsym_sweep_highlevel(cm, sweep)
        times["gearsym lyapunov_spectrum"].append(s)
        results["gearsym lyapunov_spectrum"].append(r)
        print(f"  rep {rep + 1}: " + ", ".join(f"{k} {v[-1]:.3f} s" for k, v in times.items()),
              file=sys.stderr, flush=True)

    yard_labels = list(binaries)
    tstats = {k: stats(v) for k, v in times.items()}
    ref = min(yard_labels, key=lambda k: (tstats[k]["min"], tstats[k]["median"]))

    def ratios(key: str, against: str) -> dict:
        return {
            "min_over_min": tstats[key]["min"] / tstats[against]["min"],
            "median_over_median": tstats[key]["median"] / tstats[against]["median"],
            "paired_median": statistics.median(a / b for a, b in zip(times[key], times[against])),
        }

    ratio = {g: {y: ratios(g, y) for y in yard_labels} for g in ("gearsym", "gearsym lyapunov_spectrum")}

    # ------------------------------------------------------------------ checks
    yard0 = results[ref][0]
    check = compare(yard0, results["gearsym"][0], results["gearsym lyapunov_spectrum"][0], zeta)
    deterministic = {
        k: all(np.array_equal(r["exponents"], v[0]["exponents"]) for r in v) for k, v in results.items()}
    builds_identical = all(np.array_equal(results[yard_labels[0]][0]["exponents"], results[k][0]["exponents"])
                           for k in yard_labels)
    cold = cold_start(cm, binaries, params, sweep.steps)
    same = same_start(binaries[ref], results["gearsym"][0], sweep, params, args.variant)
    profile = None if args.no_profile else profile_gearsym(cm, sweep, yard0["point_seconds"])

    # ------------------------------------------------------------------ print
    W = max(42, *(len(f"{g} vs {y}") for g in ratio for y in yard_labels),
            *(len(f"  ({k} subprocess wall)") for k in yard_labels)) + 2
    line = "-" * 92
    print(line)
    print(f"flexible-shaft Lyapunov sweep: {sweep.points} points, omega {sweep.omega_start:g}..{sweep.omega_stop:g} "
          f"step {sweep.omega_step:g}, {sweep.periods} periods ({sweep.discard} discarded), "
          f"{sweep.steps} RK4 steps/period{'  [QUICK]' if args.quick else ''}")
    print(f"machine: {info['cpu_model']}, nproc {info['nproc']}, {info['platform']}")
    print(f"         {info['cc_version']}; casadi {info['casadi']}; numpy {info['numpy']}; python {info['python']}; "
          f"load avg at start {', '.join(f'{x:.2f}' for x in info['loadavg_at_start'] or [])}")
    print(f"yardstick variant: --{args.variant}; gearsym backend: {cm.backend} "
          f"({cm.library.name if cm.library else '-'}, cflags {' '.join(compile_flags())})")
    print()
    print("setup (not in the timings):")
    for k, v in setup.items():
        print(f"  {k:62s} {v:8.3f} s")
    if gearsym_timings:
        comp = gearsym_timings.get("compile")
        print("  gearsym timings: " + ", ".join(f"{k} {v:.3f} s" for k, v in gearsym_timings.items())
              + ("" if comp else "   (library from the cache: no first-time compile in this run)"))
    print()
    print(f"sweep time, seconds, {args.repeats} interleaved repetition(s)")
    print(f"  {'':{W}s} {'min':>8s} {'median':>8s} {'max':>8s}   {'per point':>9s} {'per step':>9s}")
    for k in times:
        st = tstats[k]
        name = (k + " (C clock)") if k in binaries else k
        mark = "  <- reference" if k == ref else ""
        print(f"  {name:{W}s} {fmt_s(st['min'])} {fmt_s(st['median'])} {fmt_s(st['max'])}   "
              f"{st['min'] / sweep.points * 1e3:7.2f}ms {st['min'] / sweep.steps_total * 1e9:7.1f}ns{mark}")
    for k in yard_labels:
        print(f"  {'  (' + k + ' subprocess wall)':{W}s} {fmt_s(min(wall[k]))} {fmt_s(statistics.median(wall[k]))}")
    print()
    print(f"RATIO gearsym / yardstick (reference = faster build: {ref})   target <= 1.0")
    print(f"  {'':{W}s} {'min/min':>8s} {'med/med':>8s} {'paired':>8s}")
    for g in ratio:
        for y in yard_labels:
            r = ratio[g][y]
            tag = f"{g} vs {y}"
            star = "  <-" if y == ref else ""
            print(f"  {tag:{W}s} {r['min_over_min']:8.3f} {r['median_over_median']:8.3f} {r['paired_median']:8.3f}{star}")
    print()
    print("correctness (first repetition; exponents in Gram-Schmidt order, vs the reference build)")
    print("  runs deterministic across repetitions: "
          + ", ".join(f"{k}: {'yes' if v else 'NO'}" for k, v in deterministic.items()))
    print(f"  yardstick builds bit-identical to each other: {'yes' if builds_identical else 'no'}"
          + ("" if builds_identical else "  (expected: builds with FMA round differently)"))

    def wline(title, w):
        if w["count"] == 0:
            return f"  {title:58s}   (no such points)"
        return f"  {title:58s} {w['max_abs_diff']:9.2e}  at omega={w['at_omega']:.2f}  ({w['count']} points)"

    if check["omega_grid_max_abs_diff"]:
        print(f"  note: the reference build's omega grid differs from Python's by up to "
              f"{check['omega_grid_max_abs_diff']:.1e} (FMA in w_start + w_step*i)")
    print(wline("max |dlambda|, all points", check["all_points"]))
    print(wline(f"max |dlambda|, yardstick lambda1 < {PERIODIC:g}", check["periodic_yardstick"]))
    print(wline(f"max |dlambda|, lambda1 < {PERIODIC:g} in both", check["periodic_both"]))
    print(wline(f"max |dlambda|, lambda1 < {PERIODIC:g} in both, here and at previous",
                check["periodic_both_and_previous"]))
    big = check["points_over_1e-9"]
    if big:
        print(f"  points with |dlambda| > 1e-9: {len(big)}; omega (lambda1 yardstick/gearsym):")
        chunks = [f"{b['omega']:.2f}({b['lambda1_yardstick']:+.4f}/{b['lambda1_gearsym']:+.4f})" for b in big]
        for i in range(0, len(chunks), 4):
            print("    " + "  ".join(chunks[i:i + 4]))
    sc = check["sum_check_max_abs"]
    print(f"  max |sum(lambda) + 2 zeta/omega|: yardstick {sc['yardstick']:.2e}, gearsym {sc['gearsym']:.2e}, "
          f"lyapunov_spectrum {sc['gearsym_lyapunov_spectrum']:.2e} (largest at omega={sc['at_omega_gearsym']:.2f})")
    print(f"  lyapunov_spectrum vs low-level loop (sorted): max |d| "
          f"{check['lyapunov_spectrum_vs_lowlevel_sorted_max_abs_diff']:.2e}")
    cold_max = max(row[k]["max_abs_diff"] for row in cold for k in yard_labels)
    check["scheme_matches"] = bool(cold_max < 1e-12 and (same["periodic_max_abs_diff"] or 0.0) < 1e-9)
    for row in cold:
        diffs = ", ".join(f"{k} {row[k]['max_abs_diff']:.1e} (rel {row[k]['max_rel_diff']:.1e})" for k in yard_labels)
        print(f"  cold start omega={row['omega']:g}, {row['periods']} periods, max |dlambda|: {diffs}")
    print(f"  same start (each point re-run in the yardstick from gearsym's start state, {same['seconds']:.1f} s):")
    if same["periodic_count"]:
        print(f"    max |dlambda| over the {same['periodic_count']} points periodic in both: "
              f"{same['periodic_max_abs_diff']:.2e} at omega={same['periodic_at_omega']:.2f};  ", end="")
    print(f"all points: {same['all_points_max_abs_diff']:.2e} at omega={same['all_points_at_omega']:.2f}; "
          f"{same['points_over_1e-9']} points over 1e-9")
    if check["scheme_matches"]:
        print("  verdict: same scheme (cold start and same-start periodic points agree to rounding); the larger sweep"
              " differences\n           come from the continuation through chaotic windows, which amplifies last-bit"
              " differences of the carried state")
    else:
        print("  verdict: MISMATCH beyond rounding: check the scheme (cold-start or same-start periodic points differ)")
    if profile:
        sw, pt = profile["sweep"], profile["point"]
        print()
        print("where gearsym's time goes (one extra instrumented sweep; wrappers add ~1 us per call)")
        tot = sw["total_seconds"]

        def pl(title, s):
            print(f"  {title:62s} {s:8.3f} s {100 * s / tot:5.1f} %")

        pl("whole sweep", tot)
        pl("  parameter_vector", sw["parameter_vector_seconds"])
        pl("  prepare (constants + tables: two C calls)", sw["prepare_seconds"])
        pl(f"  tangent_run: the compiled loops ({sw['loop_c_calls']} C calls)", sw["loop_c_calls_seconds"])
        pl("  tangent_run: Python around them", sw["tangent_run_python_seconds"])
        pl("  exponents, amplitude, carry", sw["exponents_and_carry_seconds"])
        calls = ", ".join(f"{k} x{v['calls']}" for k, v in sw["calls"].items())
        print(f"  calls: {calls}")
        print(f"  one point (omega={pt['omega']}, {pt['periods']} periods), best of 5:")
        print(f"    {pt['raw_chunk_calls']} raw lyapunov_chunk calls {pt['raw_chunk_calls_seconds_min'] * 1e3:7.3f} ms"
              f"   tangent_run {pt['tangent_run_seconds_min'] * 1e3:7.3f} ms"
              f"   prepare {pt['prepare_seconds_min'] * 1e6:6.1f} us")
        print(f"    per RK4 step (state + 4x4 tangent): gearsym raw {pt['gearsym_ns_per_step_raw']:.1f} ns, "
              f"yardstick {pt['yardstick_ns_per_step']:.1f} ns (median point of the sweep)")
    print(line)

    # ------------------------------------------------------------------ json
    if args.out:
        def arr(a):
            return np.asarray(a).tolist()

        doc = {
            "benchmark": "flexible_shaft_sweep",
            "timestamp": started.isoformat(),
            "finished": _dt.datetime.now(_dt.timezone.utc).isoformat(),
            "command": " ".join(shlex.quote(a) for a in [sys.executable, *sys.argv]),
            "machine": info,
            "sweep": {**dataclasses.asdict(sweep), "points": sweep.points, "y0": Y0, "quick": args.quick,
                      "parameters": params, "yardstick_variant": args.variant,
                      "yardstick_command": runner.command(binaries[ref], **ykw)},
            "repeats": args.repeats,
            "setup_seconds": setup,
            "gearsym": {"timings": gearsym_timings, "library": str(cm.library), "backend": cm.backend,
                    "cflags": list(compile_flags()),
                        "hash": cm.hash, "options": dataclasses.asdict(cm.options)},
            "yardstick_binaries": {k: str(v) for k, v in binaries.items()},
            "reference": ref,
            "times_seconds": {k: tstats[k] for k in times},
            "yardstick_subprocess_wall_seconds": {k: stats(v) for k, v in wall.items()},
            "ratio": ratio,
            "ratio_vs_reference": {g: ratio[g][ref] for g in ratio},
            "correctness": {**check, "deterministic": deterministic, "yardstick_builds_identical": builds_identical,
                            "cold_start": cold, "same_start": same, "periodic_threshold": PERIODIC},
            "profile": profile,
            "per_point": {
                "omega": arr(yard0["omega"]),
                "yardstick_exponents": arr(yard0["exponents"]),
                "gearsym_exponents": arr(results["gearsym"][0]["exponents"]),
                "yardstick_amplitude": arr(yard0["amplitude"]),
                "gearsym_amplitude": arr(results["gearsym"][0]["amplitude"]),
                "yardstick_point_seconds": arr(yard0["point_seconds"]),
            },
        }
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(doc, indent=1) + "\n")
        print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
