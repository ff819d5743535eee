"""Every core, and beyond: the same sweep on 1 thread, on all threads, and on a local Dask cluster.

Workloads (flexible-shaft model, 400 periods, 100 discarded):

* ``independent``: the 191 omegas, every point from the initial state;
* ``map``: a 2-D map omega = 0.1:2.0:0.02 x kS in {0, 0.05, 0.1, 1.0}, independent points;
* ``lines``: the same map as four continuation lines (one task per kS).

Each runs through :func:`gearsym.run_sweep` on a model compiled once with the scheme given (the paper's
plain RK4 in ``python -m bench.speed``), on 1 thread, every core as threads and every core as forked
processes (the default),
interleaved over repetitions; the results of every configuration are compared
with the single-thread run bit for bit (repr of every number in every row).
The Dask cluster is started after those timings (its idle processes would share the cores with the
two-worker runs only), once, outside its own timings; its start-up is reported.

Beside the wall time, each run records the CPU time it used (this process and its joined workers: what the
software asked of the machine; not known for a Dask cluster's processes) and the time the hypervisor
took from this machine's CPUs meanwhile (*steal*, from ``/proc/stat`` where the kernel reports it). Work
per point that grows with more workers is the software's; a wall time that does not fall as its CPU time
says is the machine's.
"""
from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import replace

import gearsym
from gearsym import Execution
from gearsym.sweep.distributed import connect

WORKLOADS = {
    "independent": ({"omega": "0.1:2.0:0.01"}, "independent"),
    "map": ({"omega": "0.1:2.0:0.02", "kS": "0,0.05,0.1,1.0"}, "independent"),
    "lines": ({"omega": "0.1:2.0:0.02", "kS": "0,0.05,0.1,1.0"}, "continuation"),
}


def _rows(result) -> list[tuple]:
    names = list(result.columns)
    return [tuple(repr(result.columns[n][i].item()) for n in names) for i in range(len(result))]


def measure(model: str, scheme, repeats: int, dask: bool = True, workloads=None,
            log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    """``scheme``: the :class:`gearsym.Integration` of every sweep (periods, discard, steps, crossings)."""
    compiled = gearsym.compile_model(gearsym.load(model), replace(scheme, backend="compiled"))
    cores = os.cpu_count() or 1
    configs: dict[str, Execution] = {"1 thread": Execution(jobs=1),
                                   f"{cores} threads": Execution(jobs=cores, parallel="threads"),
                                   f"{cores} processes": Execution(jobs=cores, parallel="processes")}  # the default
    out: dict = {"cores": cores, "periods": scheme.periods, "discard": scheme.discard,
                 "locate_crossings": scheme.locate_crossings, "workloads": {}}
    names = list(workloads or WORKLOADS)
    baselines = {}
    for name in names:  # this machine's configurations first, with no cluster up: its idle processes
        # would share the cores with the two-worker runs and not with the one-worker run
        out["workloads"][name], baselines[name] = _time_configs(compiled, scheme, name, configs, repeats, None, log)
    if dask:
        try:
            t = time.perf_counter()
            with connect("local", cores) as client:  # the cluster `gearsym sweep --dask` starts
                client.wait_for_workers(cores)
                out["dask_startup_seconds"] = time.perf_counter() - t
                label = f"Dask LocalCluster, {cores} workers"
                for name in names:
                    entry, _ = _time_configs(compiled, scheme, name, {label: Execution(scheduler=client)}, repeats,
                                             baselines[name], log)
                    for key in ("seconds", "cpu_seconds", "steal_seconds", "identical"):
                        out["workloads"][name][key][label] = entry[key][label]
        except Exception as exc:  # the extra is optional: report why it is missing, keep the thread numbers
            out["dask"] = str(exc)
    return out


def _time_configs(compiled, scheme, name: str, configs: dict, repeats: int, baseline, log) -> tuple[dict, list]:
    """Workload ``name`` on each of ``configs``, interleaved over ``repeats`` repetitions after a warm-up
    (which also ships the library to a cluster's workers); every result compared with ``baseline`` (default:
    the first run's rows), bit for bit."""
    axes, mode = WORKLOADS[name]
    spec = [f"{k}={v}" for k, v in axes.items()]
    entry = {"axes": axes, "mode": mode, "seconds": {c: [] for c in configs}, "cpu_seconds": {c: [] for c in configs},
             "steal_seconds": {c: [] for c in configs}, "identical": {}}
    for rep in range(repeats + 1):
        for label, workers in configs.items():
            before, t = _cpu_and_steal(), time.perf_counter()
            res = gearsym.run_sweep(compiled, spec, options=scheme, mode=mode, execution=workers)
            seconds = time.perf_counter() - t
            after = _cpu_and_steal()
            cpu = after[0] - before[0]
            steal = None if None in (before[1], after[1]) else after[1] - before[1]
            rows = _rows(res)
            if baseline is None:
                baseline = rows
            entry["points"] = len(rows)
            entry["identical"][label] = entry["identical"].get(label, True) and rows == baseline
            if rep:
                entry["seconds"][label].append(seconds)
                entry["cpu_seconds"][label].append(None if workers.scheduler is not None else cpu)
                entry["steal_seconds"][label].append(steal)
        if rep:
            log(f"    {name} repetition {rep}/{repeats}: " + ", ".join(
                f"{label} {entry['seconds'][label][-1]:.3f} s" for label in configs))
    return entry, baseline


def _cpu_and_steal() -> tuple[float, float | None]:
    """CPU seconds of this process and its finished children, and the machine's stolen seconds so far
    (None where ``/proc/stat`` does not say)."""
    times = os.times()
    cpu = times.user + times.system + times.children_user + times.children_system
    try:
        fields = open("/proc/stat").readline().split()  # cpu user nice system idle iowait irq softirq steal
        steal = int(fields[8]) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        steal = None
    return cpu, steal
