"""``python -m bench.orbits``: the period-1 frequency-response curve of one_stage on omega in [0.1, 2.0], unstable
parts and located bifurcations included, against the 191-point brute-force sweep (400 periods per point), in
one run.

Both on one compiled model (crossings located, 200 steps per period: the orbits' scheme) and on one thread;
the sweep is also timed with the paper's plain scheme (the reproduction's). Repetitions are interleaved
(curve, sweep, plain sweep, then again) and the median of each is compared. Writes
``bench/results/orbits.json``; ``python -m bench.speed.report`` then renders ``docs/performance.md`` (its
section on the orbits comes from this record) and ``docs/figures/orbits-speed.png``.
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
from gearsym import Execution, Integration, continue_orbits

from bench.orbits.report import summary
from bench.machine import REPO, machine_info

DEFAULT_OUT = REPO / "bench" / "results" / "orbits.json"
MODEL, START, STOP, GRID = "one_stage", 0.1, 2.0, "omega=0.1:2.0:0.01"


def _timed(call) -> tuple[float, object]:
    t = time.perf_counter()
    result = call()
    return time.perf_counter() - t, result


def measure(repeats: int, log=lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    located = gearsym.compile_model(gearsym.load(MODEL), Integration())
    plain = gearsym.compile_model(gearsym.load(MODEL), Integration.paper())
    jobs = {
        "curve": lambda: continue_orbits(located, "omega", START, STOP, switch_depth=0),
        "sweep": lambda: gearsym.run_sweep(located, [GRID], execution=Execution(1)),
        "sweep (paper's scheme)": lambda: gearsym.run_sweep(plain, [GRID], execution=Execution(1)),
    }
    for call in jobs.values():  # warm-up: libraries loaded, caches filled
        call()
    seconds = {name: [] for name in jobs}
    results = {}
    for rep in range(repeats):
        for name, call in jobs.items():
            t, results[name] = _timed(call)
            seconds[name].append(t)
        log(f"  repetition {rep + 1}/{repeats}: " + ", ".join(f"{k} {v[-1]:.3f} s" for k, v in seconds.items()))
    curve, sweep = results["curve"], results["sweep"]
    branch = curve.branches[0]
    return {
        "model": MODEL, "range": [START, STOP], "grid": GRID, "seconds": seconds,
        "curve": {"points": len(branch), "values": branch.values.tolist(), "amplitude": branch.amplitude[:, 0].tolist(),
                  "stable": branch.stable.tolist(), "end": branch.end,
                  "bifurcations": [{"type": b.kind, "omega": b.value} for b in curve.bifurcations]},
        "sweep": {"points": len(sweep), "omega": sweep["omega"].tolist(), "amplitude": sweep["A_x"].tolist(),
                  "regime": sweep["regime"].tolist()},
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.orbits", description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="interleaved repetitions (default 5)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="the record (default bench/results/orbits.json)")
    args = ap.parse_args(argv)
    started = time.perf_counter()
    record = {"command": "python -m bench.orbits " + shlex.join(argv if argv is not None else sys.argv[1:]),
              "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "machine": machine_info(),
              "repeats": args.repeats, **measure(args.repeats)}
    record["total_seconds"] = time.perf_counter() - started
    record["summary"] = summary(record)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    s = record["summary"]
    print(f"curve {s['median_seconds']['curve']:.3f} s, sweep {s['median_seconds']['sweep']:.3f} s: "
          f"{s['curve_over_sweep']:.2f}x ({'MET' if s['met'] else 'MISSED'}: the curve in less time than the sweep)",
          file=sys.stderr)
    print("render the page with: python -m bench.speed.report", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
