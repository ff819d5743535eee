"""``gearsym reproduce``: the paper's Figs. 3, 4, 6 and 7, its claims checked, and a parameter study.

Pipeline: :mod:`.plan` (what to run) -> :mod:`.compute` (sweeps, attractors,
portraits, periodic branches) -> :mod:`.claims` (each claim measured and judged) and
:mod:`.jumps` (what each jump is, from the branches) ->
:mod:`.figures` (PNGs) and :mod:`.report` (``docs/reproduction.md``).
"""
from __future__ import annotations

import time
from pathlib import Path

from ..checks import json_safe
from ..loading import load
from ..stability.linearised import compile_linearisation
from ..options import Execution
from .basins import basins_record
from .claims import evaluate
from .compute import Computed, compute
from .figures import draw_all, draw_stability
from .plan import NOT_IN_PAPER, SCENARIOS, Plan, Scenario, paper_plan
from .report import render, write
from .stability import MODEL as STABILITY_MODEL, chart as stability_chart, stability_record

__all__ = ["SCENARIOS", "Computed", "Plan", "Scenario", "compute", "evaluate", "paper_plan", "record_of", "render",
           "reproduce"]


def scenario_record(c: Computed) -> dict:
    """One scenario's part of the record: its values for what the paper leaves open, and the claims."""
    values = {}
    for job in c.plan.sweeps:
        if not job.name.startswith("study"):
            params = c.sweeps[job.name].record["parameters"]
            values.setdefault(job.model, {k: params[k] for k in NOT_IN_PAPER if k in params})
    s = c.plan.scenario
    record = {"name": s.name, "label": s.label, "values": values, **evaluate(c)}
    if c.jumps:
        record["orbits"] = c.jumps
    if c.basins or c.fractions:
        record["basins"] = basins_record(c)
    return record


def record_of(computed: list[Computed]) -> dict:
    """The JSON record behind the report: run options, then each scenario's values, claims and study."""
    first = next(iter(computed[0].sweeps.values())).record
    run = {"periods": first["periods"], "discard": first["discard"], "steps_per_period": first["steps_per_period"]}
    return json_safe({"run": run, "scenarios": [scenario_record(c) for c in computed]})


def reproduce(out: str | Path = "docs/figures", doc: str | Path | None = None, *,
              quick: bool = False, execution: Execution | None = None, data: str | Path | None = None) -> dict:
    """Compute everything, draw the figures into ``out``, write ``out/claims.json`` and ``doc``
    (default: ``reproduction.md`` beside ``out``, i.e. docs/reproduction.md for docs/figures). A record, report or
    figure already there that the new one equals to within rounding is left as it is (another machine rounds
    otherwise: the committed files stay unchanged).

    Sweep data go to ``data`` (default ``out/data``), which is also the cache a
    rerun reads and the place an interrupted run resumes from. ``execution``: threads or workers, and what is
    done said as it goes. Returns the record.
    """
    execution = execution or Execution()
    out = Path(out)
    data = Path(data) if data else out / "data"
    start = time.perf_counter()
    computed = []
    for i, scenario in enumerate(SCENARIOS):  # the first is the main one, with the parameter study
        plan = paper_plan(quick, scenario, study=i == 0)
        computed.append(compute(plan, data / scenario.name, execution=execution))
        draw_all(computed[-1], out, "" if i == 0 else f"-{scenario.name}")
    record = record_of(computed)
    chart = stability_chart(compile_linearisation(load(STABILITY_MODEL)), quick)
    draw_stability(chart, out)
    record["stability"] = stability_record(chart)
    record = write(record, out / "claims.json", Path(doc) if doc else out.parent / "reproduction.md")
    for s in record["scenarios"]:
        verdicts = [c["verdict"] for c in s["claims"]]
        execution.say(f"{s['label']}: " + ", ".join(f"{verdicts.count(v)} {v}" for v in dict.fromkeys(verdicts)))
    execution.say(f"reproduced in {time.perf_counter() - start:.0f} s")
    return record
