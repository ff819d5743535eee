"""Errors, ratios and verdicts: pure functions of the raw measurements (so the tests can recompute them).

Conventions:

* a tool's time for the per-point task is the sum over the omegas of the
  median over repetitions of its time at that point; ratios divide such sums
  measured in the same run; "per point" is that sum over the number of points;
* the C reference is the fastest of the C builds (smallest sum of medians);
* a tool's error is the largest |lambda_i - reference_i| over the sorted
  exponents, over the points whose reference converged (periodic points);
  chaotic points are reported separately (~1e-2 is the floor there);
* like for like: every tool started at the same state, so on the periodic
  points a tool running the C's scheme (gearsym with ``Integration.paper()``,
  Numba) gives the C reference's exponents to rounding; the largest difference
  says which rows are the same computation as the C (only those are timed
  against it fairly) and is a target for gearsym;
* "at equal accuracy": an adaptive tool is taken at the loosest tolerance of
  its ladder whose error is no larger than gearsym's at 200 steps per period
  (so it is at least as accurate; the ladder steps by 100x, so its time is
  an upper bound); if none reaches it, its most accurate run is used and
  marked so.
"""
from __future__ import annotations

import statistics

TARGETS = {
    "gearsym_vs_c": 1.0,  # gearsym time / hand-written C time, at most
    "threads_speedup": 1.8,  # 1 thread / all threads, independent sweep on 2 cores, at least
    "jitcode_ratio": 100.0,  # JiTCODE time / gearsym time at equal accuracy, at least
    "scipy_ratio": 1000.0,  # SciPy time / gearsym time at equal accuracy, at least
    "compile_seconds": 10.0,  # per model, at most
    "same_as_c": 1e-9,  # |gearsym (paper's RK4) exponents - the C's|, same start, periodic points, at most
}
GEARSYM = "gearsym"  # Integration.paper(): the paper's plain RK4, the C's scheme
CROSSINGS = "gearsym (crossings located)"  # Integration(locate_crossings=True): RK4 steps split at the backlash kinks
BASES = (GEARSYM, CROSSINGS)  # the gearsym runs the adaptive tools are matched against, when present
ADAPTIVE = ("JiTCODE", "SciPy RK45")


def point_time(record: dict, stat=statistics.median) -> float:
    return sum(stat(p["seconds"]) for p in record["points"].values())


def errors(record: dict, reference: dict) -> dict:
    """Largest exponent error over converged (periodic) and over chaotic points."""
    periodic, chaotic = [], []
    for key, ref in reference.items():
        got = record["points"][key]["exponents"]
        err = max(abs(a - b) for a, b in zip(got, ref["reference"]))
        (periodic if ref["converged"] else chaotic).append(err)
    return {"periodic": max(periodic) if periodic else None, "chaotic": max(chaotic) if chaotic else None}


def largest_difference(record: dict, other: dict, reference: dict) -> float | None:
    """Largest |lambda_i - other's lambda_i| over the periodic points: 0 to rounding for the same scheme."""
    diffs = [max(abs(a - b) for a, b in zip(record["points"][key]["exponents"], other["points"][key]["exponents"]))
             for key, ref in reference.items() if ref["converged"]]
    return max(diffs) if diffs else None


def sum_rule(record: dict, reference: dict, zeta: float) -> float:
    """Largest |sum of exponents + 2 zeta/omega| (the exact mean trace of the Jacobian) over the points."""
    return max(abs(record["points"][k]["sum"] + 2 * zeta / ref["omega"]) for k, ref in reference.items())


def _c_labels(records: dict) -> list[str]:
    return [label for label in records if label.startswith("C ")]


def _row(record: dict, reference: dict, zeta: float, c_time: float, g_time: float, setting: str) -> dict:
    t = point_time(record)
    return {"setting": setting, "accuracy": record["accuracy"], "seconds": t, "seconds_min": point_time(record, min),
            "per_point": t / len(record["points"]), "vs_c": t / c_time, "vs_gearsym": t / g_time,
            "errors": errors(record, reference), "sum_rule": sum_rule(record, reference, zeta),
            "setup_seconds": record["setup_seconds"], "setup_note": record["setup_note"]}


def summarise_model(raw: dict, zeta: float) -> dict:
    reference, fixed = raw["reference"], raw["fixed"]
    c_ref = min(_c_labels(fixed), key=lambda label: point_time(fixed[label]))
    c_time, g_time = point_time(fixed[c_ref]), point_time(fixed[GEARSYM])
    tools = {label: {**_row(record, reference, zeta, c_time, g_time, "200"),
                     "same_as_c": largest_difference(record, fixed[c_ref], reference)}
             for label, record in fixed.items()}
    precision = {}
    for tool, by_setting in raw.get("precision", {}).items():
        rows = [_row(record, reference, zeta, c_time, g_time, setting) for setting, record in by_setting.items()]
        base = raw.get("precision_base", {}).get(tool)  # the 200-step run of a fixed-step tool
        if base:
            rows.insert(0, dict(tools[base], setting="200"))
        precision[tool] = rows
    equal = {base: _equal_accuracy(precision, tools[base]) for base in BASES if base in tools}
    periodic = [ref["omega"] for ref in reference.values() if ref["converged"]]
    return {"c_reference": c_ref, "gearsym_error": tools[GEARSYM]["errors"]["periodic"], "tools": tools,
            "precision": precision,
            "equal_accuracy": equal, "periodic_omegas": periodic,
            "chaotic_omegas": [ref["omega"] for ref in reference.values() if not ref["converged"]],
            "sweep": summarise_sweep(raw.get("sweep", {}))}


def _equal_accuracy(precision: dict, base: dict) -> dict:
    """Each adaptive tool at the loosest tolerance at least as accurate as ``base``, timed against it."""
    target, out = base["errors"]["periodic"], {}
    for tool in ADAPTIVE:
        rows = precision.get(tool)
        if not rows:
            continue
        good = [r for r in rows if target is None or (r["errors"]["periodic"] or 0.0) <= target]
        pick = max(good, key=lambda r: r["errors"]["periodic"] or 0.0) if good else \
            min(rows, key=lambda r: r["errors"]["periodic"] or 0.0)
        out[tool] = {"setting": pick["setting"], "reached": bool(good), "error": pick["errors"]["periodic"],
                     "per_point": pick["per_point"], "vs_c": pick["vs_c"],
                     "vs_gearsym": pick["seconds"] / base["seconds"], "gearsym_error": target}
    return out


def summarise_sweep(sweep: dict) -> dict:
    if not sweep:
        return {}
    finest = min(r["every"] for r in sweep.values())  # 1 in the real run; coarser only in --quick
    full = {label: r for label, r in sweep.items() if r["every"] == finest}
    c_ref = min(_c_labels(full), key=lambda label: statistics.median(full[label]["seconds"]))
    c_per_point = statistics.median(full[c_ref]["seconds"]) / full[c_ref]["points"]
    g = sweep[GEARSYM]
    g_per_point = statistics.median(g["seconds"]) / g["points"]
    ref_lams = full[c_ref]["exponents"]
    out = {"c_reference": c_ref, "tools": {}}
    for label, r in sweep.items():
        per_point = statistics.median(r["seconds"]) / r["points"]
        agree = None
        if r["every"] == finest:
            diffs = [max(abs(a - b) for a, b in zip(x, y)) for x, y in zip(r["exponents"], ref_lams)]
            agree = {"1e-9": sum(d <= 1e-9 for d in diffs), "1e-2": sum(d <= 1e-2 for d in diffs),
                     "points": len(diffs)}
        out["tools"][label] = {
            "points": r["points"], "every": r["every"], "accuracy": r["accuracy"], "repeats": len(r["seconds"]),
            "seconds_min": min(r["seconds"]), "seconds_median": statistics.median(r["seconds"]),
            "per_point": per_point, "vs_c": per_point / c_per_point, "vs_gearsym": per_point / g_per_point,
            "agree_with_c": agree}
    return out


def summarise_scaling(scaling: dict) -> dict:
    """Per workload and configuration: wall times and the speed-up over the first (one worker); where the
    run recorded them, the CPU time used (``work``: relative to one worker, what more workers cost the
    software; ``busy``: CPU / wall, the cores it kept busy) and the seconds stolen by the hypervisor."""
    out = {}
    for name, w in scaling.get("workloads", {}).items():
        labels = list(w["seconds"])
        one = statistics.median(w["seconds"][labels[0]])
        cpu_one = _median_known(w.get("cpu_seconds", {}).get(labels[0]))
        out[name] = {}
        for label, s in w["seconds"].items():
            entry = {"median": statistics.median(s), "min": min(s), "speedup": one / statistics.median(s),
                     "identical": w["identical"][label]}
            cpu = _median_known(w.get("cpu_seconds", {}).get(label))
            if cpu is not None and cpu_one:
                entry.update(cpu=cpu, work=cpu / cpu_one, busy=statistics.median(
                    c / t for c, t in zip(w["cpu_seconds"][label], s)))
            steal = _median_known(w.get("steal_seconds", {}).get(label))
            if steal is not None:
                entry["steal"] = steal
            out[name][label] = entry
    return out


def _median_known(values) -> float | None:
    known = [v for v in values or () if v is not None]
    return statistics.median(known) if known else None


def verdicts(models: dict, scaling: dict, compile_times: dict, startup: dict | None = None,
             overhead: dict | None = None) -> list[dict]:
    """One line per target of the issues: measured value, target, met or not."""
    rows = []
    if startup:
        slowest = max(startup["models"], key=lambda m: startup["models"][m]["median"])
        value = startup["models"][slowest]["median"]
        rows.append({"what": f"start-up of a cached model, slowest ({slowest}) (s)", "value": value,
                     "target": f"<= {startup['target_seconds']:g}", "met": value <= startup["target_seconds"]})
    if overhead:
        rows.append({"what": f"sweep overhead around the compiled loops, {overhead['model']} (%)",
                     "value": 100 * overhead["median_overhead"], "target": f"<= {100 * overhead['target']:g}",
                     "met": overhead["median_overhead"] <= overhead["target"]})
    for model, s in models.items():
        same = s["tools"][GEARSYM]["same_as_c"]
        if same is not None:
            rows.append({"what": f"gearsym (the paper's RK4) − hand-written C: largest exponent difference from the "
                                 f"same start, periodic points, {model}", "value": same,
                         "target": f"<= {TARGETS['same_as_c']:g}", "met": same <= TARGETS["same_as_c"]})
        ratio = s["tools"][GEARSYM]["vs_c"]
        rows.append({"what": f"gearsym / hand-written C, per point, {model}", "value": ratio,
                     "target": f"<= {TARGETS['gearsym_vs_c']}", "met": ratio <= TARGETS["gearsym_vs_c"]})
        sweep = s["sweep"].get("tools", {}).get(GEARSYM)
        if sweep:
            rows.append({"what": f"gearsym / hand-written C, 191-point sweep, {model}", "value": sweep["vs_c"],
                         "target": f"<= {TARGETS['gearsym_vs_c']}", "met": sweep["vs_c"] <= TARGETS["gearsym_vs_c"]})
        for base, scheme in ((GEARSYM, "the paper's RK4"), (CROSSINGS, "crossings located")):
            for tool, key in zip(ADAPTIVE, ("jitcode_ratio", "scipy_ratio")):
                eq = s["equal_accuracy"].get(base, {}).get(tool)
                if eq:
                    bound = "" if eq["reached"] else " (no tolerance reached it: a lower bound)"
                    rows.append({"what": f"{tool} / gearsym ({scheme}) at equal accuracy, {model}{bound}",
                                 "value": eq["vs_gearsym"], "target": f">= {TARGETS[key]:g}",
                                 "met": eq["vs_gearsym"] >= TARGETS[key]})
    for workload, what in (("independent", "independent sweep"), ("map", "2-D map")):
        ind = scaling.get(workload)
        if ind:
            label = next(k for suffix in ("processes", "threads") for k in ind if k.endswith(suffix))  # the default
            rows.append({"what": f"{what}, {label} vs 1 thread", "value": ind[label]["speedup"],
                         "target": f">= {TARGETS['threads_speedup']}",
                         "met": ind[label]["speedup"] >= TARGETS["threads_speedup"]})
    if compile_times:
        worst = max(max(c["first"].get("compile", 0.0), c.get("crossings", {}).get("compile", 0.0))
                    for c in compile_times.values())
        rows.append({"what": "C compile time, slowest model, either scheme (s)", "value": worst,
                     "target": f"<= {TARGETS['compile_seconds']:g}", "met": worst <= TARGETS["compile_seconds"]})
        again = sum(c["recompiled"] for c in compile_times.values())
        rows.append({"what": "models compiled again when unchanged", "value": again, "target": "0",
                     "met": again == 0})
    return rows


def summarise(raw: dict) -> dict:
    models = {m: summarise_model(r, r["zeta"]) for m, r in raw["models"].items()}
    scaling = summarise_scaling(raw.get("scaling", {}))
    return {"models": models, "scaling": scaling, "verdicts": verdicts(models, scaling, raw.get("compile", {}),
                                                                      raw.get("startup"), raw.get("sweep_overhead"))}
