"""``python -m bench.stability``: a 400 x 400 stability chart of the one-stage model, in one run.

* **The monodromies against the hand-written C**: Mathieu's case of the one-stage model (k = 1 + k_a cos tau, no
  backlash, damping or forcing), omega in [0.3, 2.5] x k_a in [0, 0.8], 400 x 400 points, one period of RK4 at
  200 steps each. The C yardstick (``bench/yardstick/monodromy.c``: the tangent matrix's two columns, scalar,
  the cosine tabulated once) in three builds, its own CPU clock around the loop; gearsym's chart in-process
  (``static_chart``, no refinement: the grid's monodromies, static states, multipliers and kinds), on one thread
  and on every core. Interleaved repetitions, medians; CPU and wall time, the verdict on CPU time (other jobs on
  a shared machine do not count into it). The two must agree: the same unstable points (to the ones within
  rounding of |mu| = 1 + 1e-9) and the same sum of the largest moduli.
* **The command end to end**: ``gearsym stability one_stage ... --param omega=0.3:2.4945:0.0055
  --param k_a=0:0.798:0.002`` (400 x 400) in a fresh process, start-up included (the linearisation's library and
  summary cached, as for any user's second run), with the boundaries located (the default) and without.
* **The refinement**: its periods and seconds per boundary point, from the in-process run with it.

Writes ``bench/results/stability.json`` and prints the verdicts.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import gearsym
from gearsym.stability import compile_linearisation, static_chart
from gearsym.stability.monodromies import MonodromyRunner

from bench.machine import REPO, machine_info, user_environment

DEFAULT_OUT = REPO / "bench" / "results" / "stability.json"
YARDSTICK = REPO / "bench" / "yardstick" / "monodromy.c"
C_BUILDS = (("-O3",), ("-O3", "-march=native"), ("-O3", "-march=native", "-mprefer-vector-width=128"))
POINTS, STEPS = 400, 200
OMEGA, KA = (0.3, 2.5), (0.0, 0.8)
MATHIEU = {"k": "1+k_a*cos(tau)", "zeta": "0", "eta": "0", "B0": "0", "B1": "0"}
COMMAND_AXES = ("omega=0.3:2.4945:0.0055", "k_a=0:0.798:0.002")  # 400 x 400 as --param takes them
#: the targets of issue 40
TARGET_WALL, TARGET_RATIO = 3.0, 0.3

_ENV = user_environment("stability")  # (bytecode kept, as for any user)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def build(flags: tuple[str, ...], folder: Path) -> Path:
    binary = folder / ("monodromy" + "".join(f.replace("=", "_").replace("-", "_") for f in flags))
    subprocess.run(["gcc", *flags, "-o", str(binary), str(YARDSTICK), "-lm"], check=True)
    return binary


def run_c(binary: Path) -> dict:
    out = subprocess.run([str(binary), str(OMEGA[0]), str(OMEGA[1]), str(POINTS), str(KA[0]), str(KA[1]), str(POINTS),
                          "0", str(STEPS)], capture_output=True, text=True, check=True).stdout.split()
    values = dict(zip(out[::2], out[1::2]))
    return {"unstable": int(values["unstable"]), "sum_max_modulus": float(values["sum_max_modulus"]),
            "cpu_seconds": float(values["seconds"])}


def command(refine: bool) -> list[str]:
    sets = [a for k, v in MATHIEU.items() for a in ("--set", f"{k}={v}")]
    return [sys.executable, "-m", "gearsym.cli", "stability", "one_stage", *sets, "--param", COMMAND_AXES[0],
            "--param", COMMAND_AXES[1], "--quiet", *([] if refine else ["--no-refine"])]


def timed_command(cmd: list[str]) -> tuple[float, float, str]:
    t, cpu = time.perf_counter(), _children_cpu()
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, env=_ENV)
    if proc.returncode:
        raise RuntimeError(f"{shlex.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    return time.perf_counter() - t, _children_cpu() - cpu, proc.stdout


def measure(repeats: int, log) -> dict:
    grid = {"omega": np.linspace(*OMEGA, POINTS), "k_a": np.linspace(*KA, POINTS)}
    lin = compile_linearisation(gearsym.load("one_stage", **MATHIEU), gearsym.Integration(), verbose=True)
    folder = Path(tempfile.mkdtemp(prefix="bench-stability-"))
    binaries = {" ".join(f): build(f, folder) for f in C_BUILDS}
    static_chart(lin, {"omega": [0.5, 1.0], "k_a": [0.1, 0.2]})  # (the lanes compiled, loaded)
    for refine in (True, False):  # (the command's summaries and bytecode cached)
        timed_command(command(refine))
    c = {b: [] for b in binaries}
    gearsym_runs = {"1 thread": [], "every core": [], "monodromies alone, 1 thread": []}
    gearsym_cpu = {"1 thread": [], "every core": [], "monodromies alone, 1 thread": []}
    runner = MonodromyRunner(lin.model, jobs=1, linear=True)
    names = lin.model.parameter_names
    W, K = np.meshgrid(grid["omega"], grid["k_a"])
    p = np.tile(lin.model.parameter_vector(), (W.size, 1))
    p[:, names.index("omega")], p[:, names.index("k_a")] = W.ravel(), K.ravel()
    results = {}
    for rep in range(repeats):
        for b, binary in binaries.items():
            r = run_c(binary)
            c[b].append(r["cpu_seconds"])
            results["C"] = r
        for name, jobs in (("1 thread", 1), ("every core", 0)):
            t, cpu = time.perf_counter(), time.process_time()
            chart = static_chart(lin, grid, refine=False, execution=gearsym.Execution(jobs=jobs))
            gearsym_runs[name].append(time.perf_counter() - t)
            gearsym_cpu[name].append(time.process_time() - cpu)
            results["gearsym"] = {"unstable": int(np.sum(chart.stable == False)),  # noqa: E712
                                  "sum_max_modulus": float(np.nansum(chart.max_modulus))}
        t, cpu = time.perf_counter(), time.process_time()
        runner.run(p, np.zeros((len(p), lin.model.dimension)))
        gearsym_runs["monodromies alone, 1 thread"].append(time.perf_counter() - t)
        gearsym_cpu["monodromies alone, 1 thread"].append(time.process_time() - cpu)
        log(f"  repetition {rep + 1}/{repeats}: C " + ", ".join(f"{b}: {v[-1]:.3f}" for b, v in c.items())
            + " s CPU; gearsym " + ", ".join(f"{k}: {gearsym_cpu[k][-1]:.3f} s CPU ({gearsym_runs[k][-1]:.3f} s)"
                                               for k in gearsym_runs) + f"; load {os.getloadavg()[0]:.1f}")
    t, cpu = time.perf_counter(), time.process_time()
    refined = static_chart(lin, grid, execution=gearsym.Execution(jobs=0))
    refine_wall, refine_cpu = time.perf_counter() - t, time.process_time() - cpu
    commands = {}
    for refine in (True, False):
        walls, cpus = [], []
        for _ in range(max(2, repeats // 2)):
            wall, cpu, text = timed_command(command(refine))
            walls.append(wall)
            cpus.append(cpu)
        commands["refined" if refine else "grid only"] = {
            "command": shlex.join(["gearsym", *command(refine)[3:]]), "seconds": walls, "cpu_seconds": cpus,
            "output": text.splitlines()[:4]}
        log(f"  command ({'refined' if refine else 'grid only'}): {np.median(walls):.2f} s "
            f"({np.median(cpus):.2f} s CPU)")
    return {"points": POINTS * POINTS, "steps_per_period": STEPS, "c_builds": list(binaries),
            "c_cpu_seconds": c, "gearsym_seconds": gearsym_runs, "gearsym_cpu_seconds": gearsym_cpu,
            "agreement": results, "lanes": 8,
            "refinement": {**refined.timings, "wall_seconds": refine_wall, "cpu_seconds": refine_cpu},
            "commands": commands}


def summary(record: dict) -> list[str]:
    best = min(record["c_builds"], key=lambda b: np.median(record["c_cpu_seconds"][b]))
    c = float(np.median(record["c_cpu_seconds"][best]))
    one = float(np.median(record["gearsym_cpu_seconds"]["1 thread"]))
    alone = float(np.median(record["gearsym_cpu_seconds"]["monodromies alone, 1 thread"]))
    every_wall = float(np.median(record["gearsym_seconds"]["every core"]))
    every_cpu = float(np.median(record["gearsym_cpu_seconds"]["every core"]))
    r = record["refinement"]
    agree = record["agreement"]
    lines = [
        f"machine: {record['machine']['cpu_model']}, {record['machine']['nproc']} cores, load "
        f"{record['machine']['loadavg_at_start']} at the start, {record['load_at_end']} at the end",
        f"C yardstick (best build: gcc {best}): {c:.3f} s CPU for {record['points']} monodromies "
        f"({c / record['points'] * 1e6:.2f} us each)",
        f"gearsym's monodromies alone (the lanes), 1 thread: {alone:.3f} s CPU = {alone / c:.2f} x the C "
        f"(target <= {TARGET_RATIO})",
        f"gearsym chart (monodromies, static states, multipliers, kinds, crossings), 1 thread: {one:.3f} s CPU = "
        f"{one / c:.2f} x the C",
        f"gearsym chart, every core: {every_wall:.3f} s wall ({every_cpu:.3f} s CPU) = {every_wall / c:.2f} x the "
        "C's time",
        f"agreement: unstable points C {agree['C']['unstable']}, gearsym {agree['gearsym']['unstable']}; sum of "
        f"max |mu| C {agree['C']['sum_max_modulus']:.9g}, gearsym {agree['gearsym']['sum_max_modulus']:.9g}",
        f"refinement: {r['boundary_points']} boundary points, {r['periods_per_boundary_point']:.1f} periods and "
        f"{r['refinement_seconds'] / max(1, r['boundary_points']) * 1e3:.3f} ms ({r['cpu_seconds']:.2f} s CPU for "
        "grid and refinement together) per point",
    ]
    for name, run in record["commands"].items():
        wall = float(np.median(run["seconds"]))
        lines.append(f"command ({name}), start-up included: {wall:.2f} s wall, {np.median(run['cpu_seconds']):.2f} s "
                     f"CPU (target {TARGET_WALL} s wall): {run['command']}")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.stability", description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="interleaved repetitions (default 5)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="the record (default bench/results/stability.json)")
    args = ap.parse_args(argv)
    started = time.perf_counter()
    log = lambda s: print(s, file=sys.stderr, flush=True)  # noqa: E731
    record = {"command": "python -m bench.stability " + shlex.join(argv if argv is not None else sys.argv[1:]),
              "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "machine": machine_info(),
              "repeats": args.repeats, **measure(args.repeats, log)}
    record["load_at_end"] = [round(x, 2) for x in os.getloadavg()]
    record["total_seconds"] = time.perf_counter() - started
    record["summary"] = summary(record)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    for line in record["summary"]:
        print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
