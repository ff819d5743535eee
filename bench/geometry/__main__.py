"""``python -m bench.geometry``: the time of one mesh-stiffness curve, spur and helical (issue 27).

Two pairs, each timed as a user meets it: ``mesh_stiffness(pair)`` with the default options (720 phases,
24 Gauss–Legendre nodes per piece of the profile, the exact mean) on gears built afresh, so the fillet's integrals
are not cached; the best and the median of ``--repeats`` runs, after one warm-up (imports, numpy's first calls).

* spur: the NASA gear-noise rig pair (28/28, m = 3.175 mm, 20 deg, b = 6.35 mm), target < 0.5 s;
* helical: ISO/TR 6336-30's Example 1 (17/103, m_n = 8 mm, beta = 15.8 deg, b = 100 mm) with 20 slices, target < 2 s.

Writes bench/results/geometry.json (or ``--out``) with the machine, the load at the start and the times.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

from bench.machine import machine_info
from gearsym.files.atomic import write_atomically
from gearsym.geometry import GearGeometry, GearPair, mesh_stiffness, StiffnessOptions

REPO = Path(__file__).resolve().parents[2]
DEFAULT_OUT = REPO / "bench" / "results" / "geometry.json"
TARGETS = {"spur": 0.5, "helical": 2.0}


def pairs():
    deg = math.pi / 180
    yield "spur", "NASA rig 28/28, m 3.175 mm, 20 deg, b 6.35 mm", lambda: GearPair(
        GearGeometry(28, 3.175e-3, 20 * deg, 6.35e-3), GearGeometry(28, 3.175e-3, 20 * deg, 6.35e-3))
    rack = dict(dedendum_coefficient=1.4, fillet_coefficient=0.39)
    yield "helical", "ISO/TR 6336-30 Ex. 1: 17/103, m_n 8 mm, beta 15.8 deg, b 100 mm, 20 slices", lambda: GearPair(
        GearGeometry(17, 8e-3, 20 * deg, 0.1, 0.145, 15.8 * deg, **rack),
        GearGeometry(103, 8e-3, 20 * deg, 0.1, 0.0, -15.8 * deg, **rack), 0.5)


def time_case(build, repeats: int) -> dict:
    options = StiffnessOptions(slices=20)
    times = []
    for i in range(repeats + 1):
        pair = build()  # fresh gears: nothing cached from the run before
        start = time.perf_counter()
        result = mesh_stiffness(pair, options)
        elapsed = time.perf_counter() - start
        if i:  # the first run warms up
            times.append(elapsed)
    return {"best_s": min(times), "median_s": statistics.median(times), "repeats": repeats,
            "mean_N_per_m": result.mean, "slices": result.slices, "phase_points": options.phase_points}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.geometry", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO))
    record = {"command": "python -m bench.geometry", "date": _dt.datetime.now().isoformat(timespec="seconds"),
              "loadavg_at_start": os.getloadavg()[0], "machine": machine_info(), "cases": {}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the solid bodies' note on Sainsot's range; docs/geometry.md)
        for name, what, build in pairs():
            case = {"pair": what, **time_case(build, args.repeats), "target_s": TARGETS[name]}
            case["met"] = case["median_s"] < TARGETS[name]
            record["cases"][name] = case
            print(f"{name:8} {what}: best {case['best_s'] * 1e3:.1f} ms, median {case['median_s'] * 1e3:.1f} ms "
                  f"(target < {TARGETS[name]:g} s: {'met' if case['met'] else 'NOT met'})")
    write_atomically(args.out, json.dumps(record, indent=2) + "\n")
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
