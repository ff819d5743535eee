"""``python -m bench.speed``: gearsym against the hand-written C, Numba, JiTCODE and SciPy, in one run.

See ``bench/README.md`` for what is measured and how to read it; the page
``docs/performance.md`` is rendered from the JSON this writes
(``python -m bench.speed.report``).
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import shlex
import sys
import time
from pathlib import Path

import gearsym
from gearsym import available_models, Integration
from . import compile_time, overhead, points, profile, reference, scaling, startup, sweep
from bench.peers import c_yardstick, gearsym_tool, jitcode_lyap, numba_rk4, scipy_ivp
from bench.machine import machine_info, REPO
from .report import write_report
from .summary import CROSSINGS, summarise, summarise_model

if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

MODELS = ("one_stage", "flexible_shaft")
OMEGAS = (0.9, 1.2, 1.5, 1.8)
C_FLAGS = (("-O3",), ("-O3", "-march=native"), ("-O3", "-march=native", "-mprefer-vector-width=128"))
PRECISION_STEPS = (800, 3200)  # besides 200, timed with the rest
CROSSING_STEPS = (100, 400)  # fourth order: coarser steps already reach the adaptive tools' accuracy
PRECISION_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-11)
DEFAULT_OUT = REPO / "bench" / "results" / "speed.json"


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _model_values(model: str) -> tuple[dict, list[float], float]:
    """The model's own defaults (every tool gets them explicitly), its initial state and zeta."""
    system = gearsym.load(model)
    params = {k: float(v) for k, v in system.parameters.items() if k != "omega"}
    return params, [float(v) for v in system.initial_vector], params["zeta"]


def run_model(model: str, args, log=log) -> dict:
    params, y0, zeta = _model_values(model)
    P, D, steps = args.periods, args.discard, 200
    omegas = OMEGAS[:2] if args.quick else OMEGAS
    log(f"== {model}: {len(omegas)} points x {P} periods ({D} discarded)")

    def tol(t: float) -> dict:
        return {"rtol": t, "atol": t}

    # every gearsym row names its scheme: the paper's plain RK4 (like for like with the C and Numba), or located
    makers = {
        "gearsym": lambda acc: gearsym_tool.make(model, acc, scheme=Integration.paper(), **params),
        CROSSINGS: lambda acc: gearsym_tool.make(model, acc, scheme=Integration(locate_crossings=True), **params),
        "C": lambda acc: c_yardstick.make(model, acc, **params),  # the fastest build (see c_yardstick)
        "Numba RK4": lambda acc: numba_rk4.make(model, acc, **params),
        "JiTCODE": lambda acc: jitcode_lyap.make(model, acc, **params),
        "SciPy RK45": lambda acc: scipy_ivp.make(model, acc, **params),
    }
    fixed = {"gearsym": makers["gearsym"]({"steps": steps}),
             "gearsym (lyapunov_spectrum)": gearsym_tool.GearsymTool(
                 model, {"steps": steps}, scheme=Integration.paper(), path="lyapunov_spectrum", **params)}
    for flags in C_FLAGS:
        fixed["C " + " ".join(flags)] = c_yardstick.make(model, {"steps": steps}, flags=flags, **params)
    fixed["Numba RK4"] = makers["Numba RK4"]({"steps": steps})
    fixed[CROSSINGS] = makers[CROSSINGS]({"steps": steps})
    for label, tool in fixed.items():
        log(f"  setup {label}: {tool.setup_seconds:.2f} s ({tool.setup_note})")

    t = time.perf_counter()
    ref_steps = reference.STEPS[:3] if args.quick else reference.STEPS
    ref_tols = (1e-8, 1e-9, 1e-10) if args.quick else reference.TOLERANCES
    ref = reference.converged_reference(lambda s: makers["C"]({"steps": s}), lambda t: makers["JiTCODE"](tol(t)),
                                        lambda t: makers["SciPy RK45"](tol(t)), omegas, y0, P, D, ref_steps, ref_tols)
    log(f"  reference (C at {ref_steps[0]}..{ref_steps[-1]} steps/period, JiTCODE at "
        f"{', '.join(f'{x:g}' for x in ref_tols)}, SciPy check): {time.perf_counter() - t:.1f} s; converged at "
        + (", ".join(f"{r['omega']:g}" for r in ref.values() if r["converged"]) or "no point"))

    log(f"  per point at {steps} steps/period, {args.repeats} interleaved repetitions")
    raw = {"zeta": zeta, "parameters": params, "initial_state": y0, "omegas": list(omegas), "reference": ref,
           "fixed": points.time_interleaved(fixed, omegas, y0, P, D, args.repeats, log)}

    # work against precision: the fixed-step tools at finer steps, the adaptive ones along a tolerance ladder
    raw["precision_base"] = {"gearsym": "gearsym", "C": "C " + " ".join(c_yardstick.DEFAULT_FLAGS),
                             "Numba RK4": "Numba RK4", CROSSINGS: CROSSINGS}
    raw["precision"] = {}
    ladders = {"steps": PRECISION_STEPS[:1] if args.quick else PRECISION_STEPS,
               "crossings": CROSSING_STEPS[:1] if args.quick else CROSSING_STEPS,
               "tol": PRECISION_TOLERANCES[1:3] if args.quick else PRECISION_TOLERANCES}
    for name, make in makers.items():
        adaptive = name in ("JiTCODE", "SciPy RK45")
        steps_ladder = ladders["crossings"] if name == CROSSINGS else ladders["steps"]
        settings = [(f"{x:.0e}", tol(x)) for x in ladders["tol"]] if adaptive else \
            [(str(x), {"steps": x}) for x in steps_ladder]
        raw["precision"][name] = {}
        for key, acc in settings:
            t = time.perf_counter()
            tool = make(acc)
            raw["precision"][name][key] = points.time_once(tool, omegas, y0, P, D)
            log(f"  {name} at {key}: {time.perf_counter() - t:.1f} s (setup {tool.setup_seconds:.2f} s)")

    if not args.no_sweep:
        every = 10 if args.quick else 1
        log(f"  191-point continuation sweep{' (every 10th point)' if args.quick else ''}, "
            f"{args.repeats} interleaved repetitions of the fixed-step tools")
        raw["sweep"] = sweep.time_sweeps(fixed, y0, P, D, args.repeats, every=every, log=log)
        equal = summarise_model(raw, zeta)["equal_accuracy"]["gearsym"]  # like for like with the sweep's gearsym
        for name in ("JiTCODE", "SciPy RK45"):
            tool_every = max(every, args.scipy_every) if name == "SciPy RK45" else every
            t = time.perf_counter()
            tool = makers[name](tol(float(equal[name]["setting"])))
            raw["sweep"][name] = sweep.time_sweep_once(tool, y0, P, D, tool_every)
            log(f"  sweep {name} at {equal[name]['setting']}, every {tool_every}: {time.perf_counter() - t:.1f} s")
    return raw


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.speed", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke test: 2 omegas, 40 periods, short ladders")
    ap.add_argument("--repeats", type=int, default=5, help="interleaved repetitions of the fast tools (default 5)")
    ap.add_argument("--models", default=",".join(MODELS), help=f"comma-separated (default {','.join(MODELS)})")
    ap.add_argument("--scipy-every", type=int, default=10, metavar="K",
                    help="SciPy's sweep visits every K-th omega (default 10: all 191 would take an hour)")
    ap.add_argument("--no-sweep", action="store_true", help="skip the 191-point sweeps")
    ap.add_argument("--no-profile", action="store_true", help="skip the per-step profile")
    ap.add_argument("--no-scaling", action="store_true", help="skip the threads/Dask scaling runs")
    ap.add_argument("--no-compile", action="store_true", help="skip the compile-time runs")
    ap.add_argument("--no-startup", action="store_true",
                    help="skip the start-up and sweep-overhead runs (alone: python -m bench.speed.startup, .overhead)")
    ap.add_argument("--no-dask", action="store_true", help="scaling without the Dask LocalCluster")
    ap.add_argument("--out", type=Path, help=f"JSON to write (default {DEFAULT_OUT.relative_to(REPO)}; "
                                             "--quick writes nothing unless given)")
    ap.add_argument("--report", action="store_true", help="also render docs/performance.md from the JSON")
    args = ap.parse_args(argv)
    args.periods, args.discard = (40, 10) if args.quick else (400, 100)
    if args.quick:
        args.repeats = min(args.repeats, 2)
    out = args.out or (None if args.quick else DEFAULT_OUT)

    started = time.perf_counter()
    raw = {"command": "python -m bench.speed " + shlex.join(argv if argv is not None else sys.argv[1:]),
           "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "machine": machine_info(), "quick": args.quick,
           "settings": {"periods": args.periods, "discard": args.discard, "steps_per_period": 200,
                        "repeats": args.repeats, "scipy_every": args.scipy_every}, "models": {}}
    for model in args.models.split(","):
        raw["models"][model] = run_model(model, args)
    if not args.no_profile:
        log("== profile: cost per step and per point, gearsym and the fastest C build; the backlash as selects")
        fastest = {m: summarise_model(r, r["zeta"])["c_reference"][2:].split() for m, r in raw["models"].items()}
        raw["profile"] = profile.measure(list(raw["models"]), fastest, args.periods,
                                         repeats=3 if args.quick else 7, log=log)
    if not args.no_scaling:
        log("== scaling: flexible_shaft sweeps on 1 thread, every core, and a local Dask cluster")
        scheme = Integration.paper(periods=args.periods, discard=args.discard)
        raw["scaling"] = scaling.measure("flexible_shaft", scheme, args.repeats, dask=not args.no_dask,
                                         workloads=["independent"] if args.quick else None, log=log)
    if not args.no_compile:
        log("== compile time per model, empty cache, then again")
        raw["compile"] = compile_time.measure(available_models())
    if not args.no_startup:
        log("== start-up of a cached model, and the Python around each sweep point")
        raw["startup"] = startup.measure(log=log)
        raw["sweep_overhead"] = overhead.measure(log=log)
    raw["seconds"] = time.perf_counter() - started
    raw["summary"] = summarise(raw)
    for v in raw["summary"]["verdicts"]:
        log(f"  {'MET ' if v['met'] else 'MISS'} {v['what']}: {v['value']:.4g} (target {v['target']})")
    if out:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(raw, indent=1) + "\n")
        log(f"wrote {out} ({raw['seconds']:.0f} s)")
        if args.report:
            for path in write_report(out):
                log(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
