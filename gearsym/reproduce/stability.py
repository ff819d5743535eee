"""Beyond the paper: the stability chart of its model, the one-stage gear pair (Eq. 2) at the paper's values, over
the mesh frequency omega and the stiffness variation k_a (`gearsym stability`): where its static state is
parametrically unstable, and where the two parameter sets of the reproduction (k_a = 0.05 calibrated, 0.2 the
model's default) lie. Cheap (a few thousand monodromy matrices, one period each) and deterministic; the record
keeps numbers that another CPU reproduces to rounding, and the tests compare them with tolerances."""
from __future__ import annotations

import numpy as np

from ..checks import json_safe
from ..stability.chart import StabilityChart, static_chart
from ..stability.kinds import PERIOD_DOUBLING
from ..stability.recipe import CompiledLinearisation
from .plan import SCENARIOS

MODEL = "one_stage"
#: the chart's grid (the quick run's: coarser)
OMEGA, KA = (0.2, 2.6, 0.02), (0.0, 0.6, 0.02)
QUICK_OMEGA, QUICK_KA = (0.2, 2.6, 0.1), (0.0, 0.6, 0.1)
#: the boundaries to this fraction of each axis's range
TOLERANCE = 1e-6


def grid(quick: bool) -> dict[str, np.ndarray]:
    (w0, w1, dw), (k0, k1, dk) = (QUICK_OMEGA, QUICK_KA) if quick else (OMEGA, KA)
    return {"omega": np.round(np.arange(w0, w1 + dw / 2, dw), 10), "k_a": np.round(np.arange(k0, k1 + dk / 2, dk), 10)}


def chart(lin: CompiledLinearisation, quick: bool = False) -> StabilityChart:
    """The chart of ``lin`` (the paper's model linearised about its static state) on the reproduction's grid,
    its boundaries located to :data:`TOLERANCE` of each axis's range."""
    g = grid(quick)
    span = (g["omega"][-1] - g["omega"][0], g["k_a"][-1] - g["k_a"][0])
    return static_chart(lin, g, tolerance=(TOLERANCE * span[0], TOLERANCE * span[1]))


def stability_record(chart: StabilityChart) -> dict:
    """What the report quotes of the chart (its figure is drawn with the others, :mod:`.figures`): the points'
    verdicts, each tongue's lowest located k_a (where it opens) and its omega, and the scenarios' k_a lines,
    stable or not along omega."""
    tongues = []
    for b in chart.boundaries:
        if len(b.points) < 2:
            continue
        k = int(np.argmin(b.points[:, 1]))
        tongues.append({"kind": b.kind, "opens_at_k_a": float(b.points[k, 1]), "omega": float(b.points[k, 0]),
                        "omega_range": [float(b.points[:, 0].min()), float(b.points[:, 0].max())]})
    tongues.sort(key=lambda t: -t["omega"])
    lowest = min((t["opens_at_k_a"] for t in tongues), default=None)
    lines = []
    for s in SCENARIOS:
        ka = s.settings(MODEL).get("k_a", chart.parameters["k_a"])  # (the model's own, where a scenario has none)
        lines.append({"scenario": s.name, "label": s.label, "k_a": ka,
                      "unstable_somewhere": lowest is not None and ka >= lowest})
    principal = next((t for t in tongues if t["kind"] == PERIOD_DOUBLING and 1.5 < t["omega"] < 2.5), None)
    g = dict(zip(chart.names, chart.values))
    return json_safe({"model": MODEL, "parameters": chart.fixed, "grid": {k: [float(v[0]), float(v[-1]),
                      int(len(v))] for k, v in g.items()}, "steps_per_period": chart.steps_per_period,
                      "counts": chart.counts(), "tongues": tongues, "principal": principal, "scenarios": lines,
                      "notes": list(chart.notes), "tolerance": list(chart.tolerance)})


def report_lines(record: dict, figures_dir: str) -> list[str]:
    """The report's section on the chart (nothing for a record without one)."""
    s = record.get("stability")
    if not s:
        return []
    p = s["principal"]
    grid_text = (f"ω from {s['grid']['omega'][0]:g} to {s['grid']['omega'][1]:g} ({s['grid']['omega'][2]} values) × "
                 f"k_a from {s['grid']['k_a'][0]:g} to {s['grid']['k_a'][1]:g} ({s['grid']['k_a'][2]})")
    lines = ["## Beyond the paper: where the static state is parametrically unstable", "",
             f"![Stability chart of the one-stage model]({figures_dir}/stability.png)", "",
             f"*`gearsym stability one_stage --param omega=... --param k_a=...` at the paper's values "
             f"(ζ = 0.08, B0 = 1, B1 = 4, η = 10) over {grid_text}: the Floquet multipliers of the model linearised "
             "about its static state (the mesh in contact on its drive flank), tongues shaded by the kind of "
             "instability, boundaries located to 1e-6 of each axis's range. docs/stability.md says how.*", ""]
    if p:
        lines.append(f"The principal tongue (a multiplier through −1, near ω = 2: the mesh frequency twice the "
                     f"natural frequency) opens at k_a = {p['opens_at_k_a']:.3f} (at ω = {p['omega']:.3f}); with "
                     f"damping ζ = 0.08 a weaker variation leaves the static state stable at every mesh frequency.")
    others = [t for t in s["tongues"] if t != p]
    if others:
        lines.append("Other tongues: " + "; ".join(f"{t['kind']} near ω = {t['omega']:.3f}, from k_a = "
                                                   f"{t['opens_at_k_a']:.3f}" for t in others) + ".")
    lines += ["", "| parameter set | k_a | the static state along ω |", "|---|---|---|"]
    for line in s["scenarios"]:
        verdict = "unstable in a tongue" if line["unstable_somewhere"] else "stable at every ω of the chart"
        lines.append(f"| {line['label']} | {line['k_a']:g} | {verdict} |")
    lines.append("")
    if not any(line["unstable_somewhere"] for line in s["scenarios"]):
        lines += ["At both parameter sets the static state is parametrically stable: the jumps, chaos and impacts "
                  "of Figs. 3–7 come from the forcing B1 and the backlash, not from the stiffness variation alone.",
                  ""]
    return lines
