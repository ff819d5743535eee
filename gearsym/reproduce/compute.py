"""Running the plan: sweeps into resumable files under ``DATA/``, attractors and portraits in memory.

The sweep files double as a cache: a second ``gearsym reproduce`` finds them
complete (same model code, parameters and options, as their records say) and
only redraws; an interrupted one resumes where it stopped.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

from ..analysis import LyapunovSpectrum, Trajectory, lyapunov_spectrum, phase_trajectory
from ..analysis.attractors import AttractorSet, find_attractors
from ..codegen import compile_model
from ..sweep import SweepResult, run_sweep
from .plan import Plan


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


def compute(plan: Plan, data_dir: str | Path, *, jobs: int = 0, progress: bool = True) -> Computed:
    data_dir = Path(data_dir)
    sweeps = {}
    for job in plan.sweeps:
        _say(progress, f"sweep {job.name}: {job.model} {' '.join(job.params)}"
             + "".join(f" {k}={v}" for k, v in job.settings.items()))
        sweeps[job.name] = run_sweep(job.model, job.params, mode="continuation", direction=job.direction,
                                     periods=plan.periods, discard=plan.discard, jobs=jobs,
                                     out=data_dir / f"{job.name}.csv", poincare=job.poincare, progress=progress,
                                     **job.settings)
    attractors = {}
    for job in plan.attractors:
        _say(progress, f"attractors: {job.model} at omega={job.omega:g}, {job.ics} random initial states")
        attractors[(job.model, job.omega)] = find_attractors(
            job.model, ics=job.ics, seed=job.seed, periods=plan.attractor_periods, discard=plan.attractor_discard,
            **plan.scenario.settings(job.model), omega=job.omega)
    portraits = []
    fixed = plan.scenario.settings(plan.portrait_model)
    compiled = compile_model(plan.portrait_model, **fixed) if plan.portraits else None
    for job in plan.portraits:
        values = {"omega": plan.portrait_omega, **job.settings}
        spectrum = lyapunov_spectrum(compiled, periods=plan.periods, discard=plan.discard, **values)
        shown = min(plan.portrait_window, plan.periods - plan.discard)  # the end of the same run
        trajectory = phase_trajectory(compiled, periods=shown, discard=plan.periods - shown, **values)
        portraits.append(Portrait(job.letter, values, job.x, job.y, spectrum, trajectory))
    return Computed(plan, sweeps, attractors, tuple(portraits))


def _say(enabled: bool, message: str) -> None:
    if enabled:
        print(f"gearsym: {message}", file=sys.stderr, flush=True)
