"""The section of ``docs/performance.md`` on the lanes and basin maps, rendered from ``bench/results/basins.json``
(by ``bench/speed/report.py``, which writes the page)."""
from __future__ import annotations

import numpy as np

from bench.machine import REPO

RECORD = REPO / "bench" / "results" / "basins.json"
#: the issue's targets: per trajectory against the best scalar C, and the 441-start map against the C's same starts
TARGETS = {"per_trajectory": 0.4, "map_441": 0.5}


def _medians(d: dict) -> dict:
    return {k: float(np.median(v)) for k, v in d.items()}


def summary(record: dict) -> dict:
    """Medians, ratios and verdicts (a pure function of the measurements). The verdicts are on CPU time: on a
    machine shared with other jobs a wall clock measures the other jobs too (both are reported)."""
    best = f"C {record['best_c_build']}"
    wall, cpu = _medians(record["per_trajectory_seconds"]), _medians(record["per_trajectory_cpu_seconds"])
    m441 = record["map_441"]
    c441, g441 = float(np.median(m441["c_cpu_seconds"])), float(np.median(m441["gearsym_cpu_seconds"]))
    c441w, g441w = float(np.median(m441["c_seconds"])), float(np.median(m441["gearsym_seconds"]))
    m200 = record["map_200"]
    sm = record["sweep_map"]
    smed = _medians(sm["seconds"])
    out = {"per_trajectory_ms": {k: 1e3 * v for k, v in wall.items()},
           "per_trajectory_cpu_ms": {k: 1e3 * v for k, v in cpu.items()},
           "per_trajectory_over_c": {k: v / cpu[best] for k, v in cpu.items()},
           "per_trajectory_over_c_wall": {k: v / wall[best] for k, v in wall.items()},
           "lanes_over_c": cpu["gearsym lanes, tangent"] / cpu[best],
           "lanes_over_c_wall": wall["gearsym lanes, tangent"] / wall[best],
           "lanes_over_scalar": cpu["gearsym lanes, tangent"] / cpu["gearsym scalar loop, tangent"],
           "map_441": {"c_cpu_seconds": c441, "gearsym_cpu_seconds": g441, "ratio": g441 / c441,
                       "c_seconds": c441w, "gearsym_seconds": g441w, "ratio_wall": g441w / c441w},
           "map_200": {jobs: m200[jobs]["seconds"] for jobs in ("1", "2")},
           "map_200_cpu": {jobs: m200[jobs]["cpu_seconds"] for jobs in ("1", "2")},
           "two_cores": m200["1"]["seconds"] / m200["2"]["seconds"],
           "sweep_map": {"median_seconds": smed, "lanes_over_scalar_2": smed["2 processes, lanes"] / smed["2 processes"],
                         "two_cores_lanes": smed["1 process, lanes"] / smed["2 processes, lanes"]}}
    out["met"] = {"per_trajectory": out["lanes_over_c"] <= TARGETS["per_trajectory"],
                  "map_441": out["map_441"]["ratio"] <= TARGETS["map_441"]}
    out["lines"] = [
        f"per trajectory: lanes (tangent) {out['lanes_over_c']:.2f}x the best C ({record['best_c_build']}) in CPU time "
        f"({out['lanes_over_c_wall']:.2f}x wall), {'met' if out['met']['per_trajectory'] else 'MISSED'} "
        f"(<= {TARGETS['per_trajectory']})",
        f"441-start map: gearsym basins {g441:.2f} s CPU (start-up included), C {c441:.2f} s CPU: "
        f"{out['map_441']['ratio']:.2f}x ({out['map_441']['ratio_wall']:.2f}x wall) "
        f"{'met' if out['met']['map_441'] else 'MISSED'} (<= {TARGETS['map_441']})",
        f"200 x 200 map: {m200['2']['seconds']:.1f} s on 2 cores, {m200['1']['seconds']:.1f} s on 1 "
        f"({out['two_cores']:.2f}x)",
        f"2-D map ({sm['model']}, {sm['points']} independent points) on 2 cores: "
        f"{smed['2 processes, lanes']:.2f} s with lanes, {smed['2 processes']:.2f} s without "
        f"({out['sweep_map']['lanes_over_scalar_2']:.2f}x)"]
    return out


def _result_text(result: dict) -> str:
    parts = [f"{100 * a['fraction']:.1f} % " + (f"period {a['period']}" if a["period"] else a["regime"])
             for a in result["attractors"]]
    parts += [f"{100 * result[k]['fraction']:.1f} % {k}" for k in ("undetermined", "diverged") if result[k]["starts"]]
    return ", ".join(parts)


def section(record: dict) -> list[str]:
    s = summary(record)
    m = record["machine"]
    sm = record["sweep_map"]
    smed = s["sweep_map"]["median_seconds"]
    rows = [f"| {name} | {s['per_trajectory_cpu_ms'][name]:.3f} | {s['per_trajectory_over_c'][name]:.2f}× | "
            f"{s['per_trajectory_ms'][name]:.3f} | {s['per_trajectory_over_c_wall'][name]:.2f}× |"
            for name in s["per_trajectory_ms"]]
    mark = {True: "yes", False: "**no**"}
    return [
        "## Many trajectories at once: the lanes and basin maps", "",
        f"Measured {record['date']} by `{record['command']}` ({record['total_seconds']:.0f} s; {m['cpu_model']}, "
        f"{m['nproc']} cores, {', '.join(m['cpu_simd'])}; load at start "
        f"{', '.join(map(str, m['loadavg_at_start'] or []))}). {record['model']} at ω = {record['omega']:g}, "
        f"{record['periods']} periods of which {record['discard']} discarded, 200 RK4 steps per period, the paper's "
        f"plain RK4 unless said, from the {record['starts']} starts of a 21 × 21 grid over [-5, 5]²; the lanes hold "
        f"{record['lanes']} trajectories per call. The C yardstick runs one process per start; its wall time is its "
        f"own clock, its CPU time that of the process less the start-up (a run of one period, "
        f"{1e3 * record['c_startup_cpu_seconds'][record['best_c_build']]:.2f} ms); it and the scalar loop are timed "
        f"on one start in {record['starts'] // record['sample']}. Medians of {record['repeats']} interleaved "
        "repetitions, one core. The machine was shared with other jobs, so the verdicts are on CPU time (a wall "
        "clock counts the other jobs too); both are given.", "",
        "| per trajectory | CPU ms | × the best C | wall ms | × the best C (wall) |", "|---|---|---|---|---|", *rows,
        "",
        "| target | measured (CPU) | wall | goal | met |", "|---|---|---|---|---|",
        f"| lanes (tangent, the C's job) / the best scalar C, per trajectory | {s['lanes_over_c']:.2f} | "
        f"{s['lanes_over_c_wall']:.2f} | ≤ {TARGETS['per_trajectory']} | {mark[s['met']['per_trajectory']]} |",
        f"| `gearsym basins` of the 441 starts (start-up included) / the best C on the same starts | "
        f"{s['map_441']['ratio']:.2f} | {s['map_441']['ratio_wall']:.2f} | ≤ {TARGETS['map_441']} | "
        f"{mark[s['met']['map_441']]} |", "",
        f"The 441-start map, `{record['map_441']['command']}`: {s['map_441']['gearsym_cpu_seconds']:.2f} s of CPU "
        f"({s['map_441']['gearsym_seconds']:.2f} s wall) in a fresh process (Python's start-up with its bytecode cached "
        "as for any user, loading the cached library and lanes, 441 runs in the lanes without tangent vectors, the "
        f"classification, one tangent run per attractor) against {s['map_441']['c_cpu_seconds']:.2f} s of CPU ({s['map_441']['c_seconds']:.2f} s by its "
        f"clock) of the C for the same starts (their Lyapunov spectra, the C's job); it finds "
        f"{_result_text(record['map_441']['result'])}.", "",
        f"A 200 × 200 map, `{record['map_200']['command']}`: **{s['map_200']['2']:.1f} s on 2 cores** "
        f"({s['map_200_cpu']['2']:.1f} s of CPU), {s['map_200']['1']:.1f} s on 1 ({s['map_200_cpu']['1']:.1f} s of "
        f"CPU; {s['two_cores']:.2f}× by the wall clock); it finds {_result_text(record['map_200']['2']['result'])}. "
        f"The other jobs on the machine left the 2-core run {s['map_200_cpu']['2'] / s['map_200']['2']:.2f} cores "
        "(its CPU over its wall time): what 2 cores give is measured only on an idle machine.",
        "",
        f"The 2-D map of the scaling stage above ({sm['model']}, `{' '.join(sm['axes'])}`, {sm['points']} independent "
        f"points, the paper's scheme, {record['periods']} periods) through `run_sweep(..., execution=Execution(lanes=True))` (`gearsym "
        f"sweep --lanes`: each lane with its point's tables and constants), medians of "
        f"{len(next(iter(sm['seconds'].values())))} interleaved repetitions (wall):", "",
        "| workers | seconds |", "|---|---|", *[f"| {k} | {v:.2f} |" for k, v in smed.items()], "",
        f"On 2 cores the lanes take **{s['sweep_map']['lanes_over_scalar_2']:.2f}×** the scalar loops' time (2 cores "
        f"{s['sweep_map']['two_cores_lanes']:.2f}× one with the lanes); the largest λ₁ difference from the scalar "
        f"sweep is {sm['largest_difference']:.1e} ({'the same bits' if sm['identical'] else 'rounding'}).", "",
    ]
