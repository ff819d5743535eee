"""Running the plan: sweeps into resumable files under ``DATA/``, attractors and portraits in memory.

The sweep files double as a cache: a second ``gearsym reproduce`` finds them
complete (same model code, parameters and options, as their records say) and
only redraws; an interrupted one resumes where it stopped.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..analysis.lyapunov import LyapunovSpectrum, lyapunov_spectrum
from ..analysis.poincare import Trajectory, phase_trajectory
from ..analysis.attractors import DEFAULT_BOX, AttractorSet, find_attractors
from ..analysis.basins import BasinMap, basin_map, method
from ..codegen.build import compile_model
from ..options import Execution, Integration
from ..periodic import Continuation, continue_orbits
from ..periodic.orbit import sweep_start
from ..loading import load
from ..files.atomic import write_atomically
from ..sweep import SweepResult, parse_axis, run_sweep
from ..sweep.basin_continuation import BasinContinuation, continue_basins
from .jumps import jump_records
from .plan import ORBITS, Plan


@dataclass(frozen=True)
class Portrait:
    letter: str
    settings: dict
    x: str
    y: str
    spectrum: LyapunovSpectrum
    trajectory: Trajectory


@dataclass(frozen=True)
class Computed:
    plan: Plan
    sweeps: dict[str, SweepResult]
    attractors: dict[tuple[str, float], AttractorSet]
    portraits: tuple[Portrait, ...]
    orbits: dict[str, Continuation] = field(default_factory=dict)  # by the name of the sweep they follow
    jumps: dict[str, dict] = field(default_factory=dict)  # what each of that sweep's jumps is (jumps.py)
    local: dict[str, list] = field(default_factory=dict)  # orbits of other periods continued across its jumps
    basins: dict[tuple[str, float], BasinMap] = field(default_factory=dict)  # Fig. 4 as basin maps
    fractions: dict[str, BasinContinuation] = field(default_factory=dict)  # basin fractions across Fig. 3's jumps


def compute(plan: Plan, data_dir: str | Path, *, execution: Execution | None = None) -> Computed:
    """Every run of ``plan`` with the paper's scheme (plain RK4 at 200 steps per period), named explicitly
    so that the reproduction stays like for like whatever the engine's default. ``execution``: threads or
    workers, and a line of progress per run (the sweeps' bars too)."""
    execution = execution or Execution()
    say = execution.say
    data_dir = Path(data_dir)
    scheme = Integration.paper(periods=plan.periods, discard=plan.discard)
    compiled = {name: compile_model(load(name), scheme)
                for name in dict.fromkeys([j.model for j in plan.sweeps] + [j.model for j in plan.attractors]
                                          + [j.model for j in (*plan.basins, *plan.fractions)]
                                          + ([plan.portrait_model] if plan.portraits else []))}
    sweeps = {}
    for job in plan.sweeps:
        say(f"sweep {job.name}: {job.model} {' '.join(job.params)}"
            + "".join(f" {k}={v}" for k, v in job.settings.items()))
        sweeps[job.name] = run_sweep(compiled[job.model], job.params, mode="continuation", direction=job.direction,
                                     execution=execution, out=data_dir / f"{job.name}.csv", poincare=job.poincare,
                                     overwrite="stale",  # (the data are a cache: a changed model starts again)
                                     **job.settings)
    attractors = {}
    transient = scheme.run(plan.attractor_discard + plan.attractor_periods, plan.attractor_discard)
    for job in plan.attractors:
        say(f"attractors: {job.model} at omega={job.omega:g}, {job.ics} random initial states")
        attractors[(job.model, job.omega)] = find_attractors(
            compiled[job.model], options=transient, ics=job.ics, seed=job.seed,
            **plan.scenario.settings(job.model), omega=job.omega)
    portraits = []
    fixed = plan.scenario.settings(plan.portrait_model)
    shown = min(plan.portrait_window, plan.periods - plan.discard)
    for job in plan.portraits:
        values = {"omega": plan.portrait_omega, **fixed, **job.settings}
        model = compiled[plan.portrait_model]
        spectrum = lyapunov_spectrum(model, **values)
        trajectory = phase_trajectory(model, options=scheme.run(discard=plan.periods - shown), **values)  # its end
        portraits.append(Portrait(job.letter, {"omega": plan.portrait_omega, **job.settings}, job.x, job.y,
                                  spectrum, trajectory))
    orbits = _orbits(plan, sweeps, say)
    jumps, local = jump_records(plan, sweeps, orbits)
    maps, fractions = _basins(plan, compiled, transient, data_dir, execution)
    return Computed(plan, sweeps, attractors, tuple(portraits), orbits, jumps, local, maps, fractions)


def box_grid(points: int) -> dict[str, np.ndarray]:
    """The grid over Fig. 4's box of random starts, ``points`` per state."""
    return {s: np.linspace(*DEFAULT_BOX, points) for s in ("x", "v")}


def _basins(plan: Plan, compiled: dict, options: Integration, data_dir: Path, execution: Execution):
    """Fig. 4's basin maps (kept in ``data_dir/basins`` as JSON: a rerun reads them) and the basin fractions
    across Fig. 3's jumps (a resumable continuation there)."""
    say, maps = execution.say, {}
    for job in plan.basins:
        say(f"basins: {job.model} at omega={job.omega:g}, {job.points} x {job.points} starts")
        values = {**plan.scenario.settings(job.model), "omega": job.omega}
        maps[(job.model, job.omega)] = _cached_map(compiled[job.model], box_grid(job.points), options, values,
                                                   data_dir / "basins" / f"map-{job.model}-{job.omega:g}.json", execution)
    fractions = {}
    for job in plan.fractions:
        axis = parse_axis(job.omegas)
        say(f"basin fractions: {job.model} {job.omegas}, {job.points} x {job.points} starts each")
        fractions[job.model] = continue_basins(
            compiled[job.model], box_grid(job.points), "omega", axis.values, options=options,
            out=data_dir / "basins" / f"fractions-{job.model}.csv", overwrite="stale",
            execution=replace(execution, progress=False),
            **plan.scenario.settings(job.model))
    return maps, fractions


def _cached_map(model, grid: dict, options: Integration, values: dict, path: Path,
                execution: Execution) -> BasinMap:
    """The basin map, from ``path`` if it holds this one (same code, grid, run and values), else computed there."""
    record = json.loads(json.dumps({"model_hash": model.hash, "grid": {k: v.tolist() for k, v in grid.items()},
                                    "periods": options.periods, "discard": options.discard, "values": values,
                                    "method": method()}))
    try:
        data = json.loads(path.read_text())
        if data["record"] == record:
            return BasinMap.from_dict(data["map"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    found = basin_map(model, grid, options=options, execution=replace(execution, progress=False), **values)
    write_atomically(path, json.dumps({"record": record, "map": found.as_dict(labels=True)}) + "\n")
    return found




def _orbits(plan: Plan, sweeps: dict[str, SweepResult], say) -> dict[str, Continuation]:
    """The periodic branches over each orbit job's range, started from its sweep's state there."""
    out = {}
    for job in plan.orbits:
        sweep_job = plan.sweep(job.sweep)
        say(f"periodic orbits: {sweep_job.model} omega={job.start:g}..{job.stop:g}"
            + "".join(f" {k}={v}" for k, v in sweep_job.settings.items()))
        model = compile_model(load(sweep_job.model), ORBITS)
        start = sweep_start(sweeps[job.sweep], model, "omega", job.start, sweep_job.settings)
        out[job.sweep] = continue_orbits(model, "omega", job.start, job.stop, y0=start,
                                         switch_depth=job.switch_depth, **sweep_job.settings)
    return out


