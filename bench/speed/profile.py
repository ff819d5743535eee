"""Where the time per point goes, for the targets a run misses: cost per RK4 step and per point.

* For gearsym (the paper's plain RK4, like the C) and the fastest C build of
  each model: the time of a 1-period point and of a 400-period point
  (interleaved, medians), giving the cost per RK4 step (with its tangent
  vectors) and the fixed cost per point (tables, constants, calls, exponents).
* The backlash as CasADi writes it: the one-stage C yardstick compiled with
  ``-DBACKLASH_SELECT``, which replaces its if/else for g and g' by the
  branch-free selects in gearsym's generated step, timed against the
  ordinary build: how much of a gap the selects alone make.
"""
from __future__ import annotations

import statistics
import sys
from collections.abc import Callable

from gearsym import Integration
from bench.peers import c_yardstick, gearsym_tool

STEPS = 200


def _median_seconds(tool, omega, periods, discard, repeats) -> float:
    return statistics.median(tool.spectrum(omega, None, periods, discard).seconds for _ in range(repeats))


def measure(models, c_flags: dict, periods: int = 400, omega: float = 1.5, repeats: int = 7,
            log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    """``c_flags[model]``: the flags of that model's fastest C build in this run."""
    out: dict = {"omega": omega, "periods": periods, "steps_per_period": STEPS, "models": {}}
    for model in models:
        tools = {"gearsym": gearsym_tool.make(model, {"steps": STEPS}, scheme=Integration.paper()),
                 "C": c_yardstick.make(model, {"steps": STEPS}, flags=tuple(c_flags[model]))}
        entry = {}
        for label, tool in tools.items():
            short = _median_seconds(tool, omega, 1, 0, repeats)
            long = _median_seconds(tool, omega, periods, 0, repeats)
            per_step = (long - short) / ((periods - 1) * STEPS)
            entry[label] = {"ns_per_step": per_step * 1e9, "fixed_us_per_point": (short - per_step * STEPS) * 1e6,
                            "ms_per_point": long * 1e3}
        entry["step_ratio"] = entry["gearsym"]["ns_per_step"] / entry["C"]["ns_per_step"]
        out["models"][model] = entry
        log(f"    {model}: gearsym {entry['gearsym']['ns_per_step']:.1f} ns/step, C {entry['C']['ns_per_step']:.1f} "
            f"ns/step; fixed per point {entry['gearsym']['fixed_us_per_point']:.0f} us vs "
            f"{entry['C']['fixed_us_per_point']:.0f} us")
    if "one_stage" in models:
        flags = tuple(c_flags["one_stage"])
        branch = c_yardstick.make("one_stage", {"steps": STEPS}, flags=flags)
        select = c_yardstick.make("one_stage", {"steps": STEPS}, flags=(*flags, "-DBACKLASH_SELECT"))
        times: dict[str, list[float]] = {"branch": [], "select": []}
        for _ in range(repeats):
            times["branch"].append(branch.spectrum(omega, None, periods, periods // 4).seconds)
            times["select"].append(select.spectrum(omega, None, periods, periods // 4).seconds)
        b, s = statistics.median(times["branch"]), statistics.median(times["select"])
        out["backlash_select"] = {"branch_ms": b * 1e3, "select_ms": s * 1e3, "ratio": s / b, "flags": list(flags)}
        log(f"    one_stage C, backlash as selects / as branches: {s / b:.2f}")
    return out
