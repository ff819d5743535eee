"""``python -m bench.basins``: the lanes against the best hand-written scalar C, and basin maps end to end, in one run.

* **Per trajectory, one core**: one_stage at omega = 1.5, the paper's plain RK4 (the C's scheme), 400 periods of
  which 100 discarded, from the 441 starts of a 21 x 21 grid over [-5, 5]^2. The C yardstick
  (``bench/yardstick/one_stage.c``: state and tangent vectors, Gram-Schmidt every period) in its three builds,
  one process per start, its own clock per point; gearsym's scalar loop (``tangent_run``) on a sample of the starts;
  gearsym's lanes with tangent vectors (the C's job) and without (what a basin map runs), and both with the
  crossings located. Interleaved repetitions, medians; wall and CPU time (the C's process less its start-up; the
  lanes' thread), the verdicts on CPU time, which other jobs on a shared machine do not count into it.
* **The 441-start map**: ``gearsym basins one_stage --grid x=-5:5:0.5 --grid v=-5:5:0.5 --plain --jobs 1`` in a
  fresh process (start-up included: the library, the lanes and Python's bytecode cached, as for any user) against
  the best C build's time for the same 441 starts (the sum of its per-point clocks, and of its processes' CPU less
  their start-ups).
* **A 200 x 200 map**: the same command on 200 x 200 starts, on 2 cores and on 1.

Writes ``bench/results/basins.json``; ``python -m bench.speed.report`` renders its section of
``docs/performance.md``.
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
import time
from pathlib import Path

import numpy as np

import gearsym
from gearsym import Integration
from gearsym.codegen.lane_runs import LaneRunner

from bench.basins.report import summary
from bench.machine import REPO, machine_info, user_environment
from bench.yardstick import runner

DEFAULT_OUT = REPO / "bench" / "results" / "basins.json"
MODEL, OMEGA, PERIODS, DISCARD = "one_stage", 1.5, 400, 100
C_BUILDS = (("-O3",), ("-O3", "-march=native"), ("-O3", "-march=native", "-mprefer-vector-width=128"))
MAP_441 = ("x=-5:5:0.5", "v=-5:5:0.5")
MAP_200 = ("x=-5:4.95:0.05", "v=-5:4.95:0.05")
#: the C and the scalar loop are timed on every SAMPLE-th start (their time per point does not depend on it)
SAMPLE = 21


def _grid() -> np.ndarray:
    xs = np.linspace(-5, 5, 21)
    return np.array([(x, v) for v in xs for x in xs])


def _command(grid, jobs: int) -> list[str]:
    return [sys.executable, "-m", "gearsym.cli", "basins", MODEL, "--set", f"omega={OMEGA}", "--grid", grid[0], "--grid",
            grid[1], "--plain", "--periods", str(PERIODS), "--discard", str(DISCARD), "--jobs", str(jobs),
            "--format", "json", "--quiet"]


def _children_cpu() -> float:
    """CPU seconds (user + system) of this process's finished children so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


_ENV = user_environment("basins")  # (bytecode kept, as for any user)


def _timed_command(cmd: list[str]) -> tuple[float, float, dict]:
    """Wall seconds, CPU seconds (the process and its threads, start-up included) and the result of a command."""
    t, cpu = time.perf_counter(), _children_cpu()
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, env=_ENV)
    seconds, cpu = time.perf_counter() - t, _children_cpu() - cpu
    if proc.returncode != 0:
        raise RuntimeError(f"{shlex.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    data = json.loads(proc.stdout)
    return seconds, cpu, {"attractors": [{k: a[k] for k in ("fraction", "stderr", "period", "regime", "amplitude")}
                                    for a in data["attractors"]],
                     "undetermined": data["undetermined"], "diverged": data["diverged"], "lanes": data["lanes"]}


def _c_points(binary, starts, periods: int = PERIODS, discard: int = DISCARD) -> tuple[list[float], list[float]]:
    """The C program's own (wall) seconds for each start, one process each, and the CPU seconds of each process
    (its start-up included)."""
    wall, cpu = [], []
    for y0 in starts:
        before = _children_cpu()
        r = runner.run(binary, periods=periods, discard=discard, omega_start=OMEGA, omega_stop=OMEGA, omega_step=1.0,
                       y0=tuple(map(float, y0)), model=MODEL)
        cpu.append(_children_cpu() - before)
        wall.append(float(r["point_seconds"][0]))
    return wall, cpu


def measure(repeats: int, log=lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    starts = _grid()
    sample = starts[::SAMPLE]
    binaries = {" ".join(f): runner.build(flags=f, model=MODEL) for f in C_BUILDS}
    paper = Integration.paper(periods=PERIODS, discard=DISCARD)
    plain = gearsym.compile_model(gearsym.load(MODEL), paper)
    located = gearsym.compile_model(gearsym.load(MODEL), Integration(periods=PERIODS, discard=DISCARD))
    inputs = {id(m): m.prepare(m.parameter_vector(omega=OMEGA)) for m in (plain, located)}
    lanes = {id(m): LaneRunner(m, DISCARD, PERIODS - DISCARD, verbose=True) for m in (plain, located)}

    def lanes_run(model, tangent):
        return lambda: lanes[id(model)].orbits(starts, inputs[id(model)], tangent=tangent)

    def scalar_run():
        for y0 in sample:
            plain.tangent_run(y0, PERIODS, inputs[id(plain)])

    gearsym_jobs = {  # name -> (call, trajectories it runs)
        "gearsym scalar loop, tangent": (scalar_run, len(sample)),
        "gearsym lanes, tangent": (lanes_run(plain, True), len(starts)),
        "gearsym lanes, state only": (lanes_run(plain, False), len(starts)),
        "gearsym lanes, tangent, crossings located": (lanes_run(located, True), len(starts)),
        "gearsym lanes, state only, crossings located": (lanes_run(located, False), len(starts)),
    }
    for call, _ in gearsym_jobs.values():  # warm-up
        call()
    # the C's start-up and one period, per process: taken off its CPU time per start (its own clock excludes it)
    c_startup = {b: float(np.median(_c_points(binary, sample, periods=1, discard=0)[1])) for b, binary in
                 binaries.items()}
    names = [*(f"C {b}" for b in binaries), *gearsym_jobs]
    per_trajectory = {name: [] for name in names}
    per_trajectory_cpu = {name: [] for name in names}
    for rep in range(repeats):
        for build, binary in binaries.items():
            wall, cpu = _c_points(binary, sample)
            per_trajectory[f"C {build}"].append(float(np.median(wall)))
            per_trajectory_cpu[f"C {build}"].append(float(np.median(cpu)) - c_startup[build])
        for name, (call, count) in gearsym_jobs.items():
            t, cpu = time.perf_counter(), time.thread_time()
            call()
            per_trajectory[name].append((time.perf_counter() - t) / count)
            per_trajectory_cpu[name].append((time.thread_time() - cpu) / count)
        log(f"  repetition {rep + 1}/{repeats}: " + ", ".join(f"{k} {v[-1] * 1e3:.3f} ms" for k, v in
                                                                per_trajectory_cpu.items()) + " (CPU)")
    best = min(binaries, key=lambda b: np.median(per_trajectory_cpu[f"C {b}"]))
    subprocess.run(_command(MAP_441, 1), capture_output=True, cwd=REPO, env=_ENV)  # the lanes and bytecode cached
    map_441 = {"c_seconds": [], "c_cpu_seconds": [], "gearsym_seconds": [], "gearsym_cpu_seconds": []}
    for rep in range(max(2, repeats // 2)):
        wall, cpu = _c_points(binaries[best], starts)
        map_441["c_seconds"].append(float(np.sum(wall)))
        map_441["c_cpu_seconds"].append(float(np.sum(cpu)) - len(starts) * c_startup[best])
        seconds, cpu_seconds, result = _timed_command(_command(MAP_441, 1))
        map_441["gearsym_seconds"].append(seconds)
        map_441["gearsym_cpu_seconds"].append(cpu_seconds)
        map_441["result"] = result
        log(f"  441-start map {rep + 1}: C {map_441['c_seconds'][-1]:.3f} s ({map_441['c_cpu_seconds'][-1]:.3f} s "
            f"CPU), gearsym basins {seconds:.3f} s ({cpu_seconds:.3f} s CPU)")
    sweep_map = _sweep_map(repeats, log)
    map_200 = {}
    for jobs in (2, 1):
        seconds, cpu_seconds, result = _timed_command(_command(MAP_200, jobs))
        map_200[str(jobs)] = {"seconds": seconds, "cpu_seconds": cpu_seconds, "result": result}
        log(f"  200 x 200 map on {jobs} core(s): {seconds:.1f} s ({cpu_seconds:.1f} s CPU)")
    return {"model": MODEL, "omega": OMEGA, "periods": PERIODS, "discard": DISCARD, "starts": len(starts),
            "sample": len(sample), "c_builds": list(binaries), "best_c_build": best,
            "lanes": lanes[id(plain)].width, "per_trajectory_seconds": per_trajectory,
            "per_trajectory_cpu_seconds": per_trajectory_cpu, "c_startup_cpu_seconds": c_startup,
            "map_441": {**map_441, "command": shlex.join(["gearsym", *_command(MAP_441, 1)[3:]])},
            "map_200": {**map_200, "command": shlex.join(["gearsym", *_command(MAP_200, 2)[3:]])},
            "sweep_map": sweep_map}


#: the 2-D map of python -m bench.speed's scaling stage: flexible_shaft, independent points, the paper's scheme
SWEEP_MODEL, SWEEP_AXES = "flexible_shaft", ["omega=0.1:2.0:0.02", "kS=0,0.05,0.1,1.0"]


def _sweep_map(repeats: int, log) -> dict:
    """The 2-D map through run_sweep on 1 and 2 workers, with and without the lanes (interleaved), its rows
    compared between the two."""
    model = gearsym.compile_model(gearsym.load(SWEEP_MODEL), Integration.paper(periods=PERIODS, discard=DISCARD))
    configs = {f"{jobs} {'process' if jobs == 1 else 'processes'}{', lanes' if lanes else ''}": (jobs, lanes)
               for lanes in (False, True) for jobs in (1, 2)}
    seconds = {name: [] for name in configs}
    rows = {}
    for rep in range(repeats + 1):  # (the first: a warm-up, not counted)
        for name, (jobs, lanes) in configs.items():
            t = time.perf_counter()
            result = gearsym.run_sweep(model, SWEEP_AXES, mode="independent", execution=gearsym.Execution(jobs=jobs, lanes=lanes))
            if rep:
                seconds[name].append(time.perf_counter() - t)
            rows[name] = [float(x) for x in result["lambda_1"]]
        if rep:
            log(f"  2-D map {rep}/{repeats}: " + ", ".join(f"{k} {v[-1]:.2f} s" for k, v in seconds.items()))
    scalar, wide = rows["1 process"], rows["1 process, lanes"]
    return {"model": SWEEP_MODEL, "axes": SWEEP_AXES, "points": len(scalar), "seconds": seconds,
            "largest_difference": max(abs(a - b) for a, b in zip(scalar, wide)),
            "identical": scalar == wide}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.basins", description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="interleaved repetitions (default 5)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="the record (default bench/results/basins.json)")
    args = ap.parse_args(argv)
    os.environ.setdefault("PYTHONHASHSEED", "0")
    started = time.perf_counter()
    record = {"command": "python -m bench.basins " + shlex.join(argv if argv is not None else sys.argv[1:]),
              "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "machine": machine_info(),
              "repeats": args.repeats, **measure(args.repeats)}
    record["total_seconds"] = time.perf_counter() - started
    record["summary"] = summary(record)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    for line in summary(record)["lines"]:
        print(line, file=sys.stderr)
    print("render the page with: python -m bench.speed.report", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
