"""Sweep overhead: the Python around each point of a sweep, against the compiled loops' own time.

A 401-point continuation sweep of the one-stage model (400 periods, 100 discarded, 200 steps per period,
crossings located, one worker, files written) runs with every native call of the compiled library timed:
the overhead is (sweep time - time in the compiled loops) / time in the compiled loops, both from the same
run, so a busy machine slows both alike. The median of ``REPEATS`` runs is the result. Alone:
``python -m bench.speed.overhead [--repeats N]``.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import gearsym
from gearsym.codegen.native import NativeFunction

MODEL = "one_stage"
PERIODS, DISCARD, STEPS, POINTS = 400, 100, 200, 401
REPEATS = 5
TARGET = 0.05


def _timed_native():
    """Wrap NativeFunction.call to sum its time; returns (the total so far as a one-item list, undo)."""
    spent, original = [0.0], NativeFunction.call

    def call(self, args, results):
        t = time.perf_counter()
        try:
            return original(self, args, results)
        finally:
            spent[0] += time.perf_counter() - t

    NativeFunction.call = call
    return spent, lambda: setattr(NativeFunction, "call", original)


def measure(repeats: int = REPEATS, log=lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    options = gearsym.Integration(periods=PERIODS, discard=DISCARD, steps_per_period=STEPS)
    compiled = gearsym.compile_model(gearsym.load(MODEL), options)
    grid = np.round(0.1 + 0.005 * np.arange(POINTS), 10)
    runs = []
    for rep in range(repeats):
        with tempfile.TemporaryDirectory() as tmp:
            spent, undo = _timed_native()
            try:
                t = time.perf_counter()
                gearsym.run_sweep(compiled, {"omega": grid}, out=Path(tmp) / "sweep.csv",
                                  execution=gearsym.Execution(jobs=1))
                total = time.perf_counter() - t
            finally:
                undo()
        runs.append({"seconds": total, "compiled_seconds": spent[0], "overhead": total / spent[0] - 1})
        log(f"  sweep overhead {rep + 1}/{repeats}: {1e3 * total / POINTS:.3f} ms per point, compiled "
            f"{1e3 * spent[0] / POINTS:.3f} ms: {runs[-1]['overhead']:+.1%}")
    return {"model": MODEL, "periods": PERIODS, "discard": DISCARD, "steps_per_period": STEPS, "points": POINTS,
            "target": TARGET, "runs": runs, "median_overhead": statistics.median(r["overhead"] for r in runs),
            "median_ms_per_point": 1e3 * statistics.median(r["seconds"] for r in runs) / POINTS,
            "median_compiled_ms_per_point": 1e3 * statistics.median(r["compiled_seconds"] for r in runs) / POINTS}


def lines(result: dict) -> list[str]:
    return [f"sweep overhead ({result['model']}, {result['points']} points x {result['periods']} periods, "
            f"{result['steps_per_period']} steps, one worker; median of {len(result['runs'])}): "
            f"{result['median_ms_per_point']:.3f} ms per point, {result['median_compiled_ms_per_point']:.3f} ms in the "
            f"compiled loops: {result['median_overhead']:+.1%} (target <= {result['target']:.0%})"]


def main() -> None:
    parser = argparse.ArgumentParser(prog="python -m bench.speed.overhead", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=REPEATS)
    parser.add_argument("--json", action="store_true", help="print the measurements as JSON")
    args = parser.parse_args()
    result = measure(repeats=args.repeats)
    print(json.dumps(result, indent=2) if args.json else "\n".join(lines(result)))


if __name__ == "__main__":
    main()
