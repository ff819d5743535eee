"""The section of ``docs/performance.md`` on periodic orbits, and ``docs/figures/orbits-speed.png``, rendered
from ``bench/results/orbits.json`` (by ``bench/speed/report.py``, which writes the page)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from bench.machine import REPO
from gearsym.figures.save import pyplot, save_figure

RECORD = REPO / "bench" / "results" / "orbits.json"
FIGURE = REPO / "docs" / "figures" / "orbits-speed.png"


def summary(record: dict) -> dict:
    """Medians and the ratios the page reports (a pure function of the measurements)."""
    med = {k: float(np.median(v)) for k, v in record["seconds"].items()}
    return {"median_seconds": med, "curve_over_sweep": med["curve"] / med["sweep"],
            "curve_over_plain_sweep": med["curve"] / med["sweep (paper's scheme)"],
            "met": med["curve"] < med["sweep"]}


def section(record: dict) -> list[str]:
    s = summary(record)
    med, c = s["median_seconds"], record["curve"]
    kinds: dict[str, int] = {}
    for b in c["bifurcations"]:
        kinds[b["type"]] = kinds.get(b["type"], 0) + 1
    m = record["machine"]
    return [
        "## Periodic orbits: the frequency-response curve against the sweep", "",
        f"Measured {record['date']} by `{record['command']}` ({record['total_seconds']:.0f} s; {m['cpu_model']}, "
        f"{m['nproc']} cores, load at start {', '.join(map(str, m['loadavg_at_start'] or []))}): the whole "
        f"period-1 frequency-response curve of {record['model']} on ω ∈ [{record['range'][0]:g}, "
        f"{record['range'][1]:g}] by `gearsym.continue_orbits` (pseudo-arclength through folds, unstable parts "
        f"included, every fold, period doubling and grazing located: {c['points']} points, "
        + ", ".join(f"{n} {k}" for k, n in kinds.items())
        + f") against the brute-force sweep `{record['grid']}` ({record['sweep']['points']} points, 400 periods "
        f"each, 100 discarded, Lyapunov spectrum at every point), both on one thread, on one model compiled with "
        f"the crossings located; medians of {record['repeats']} interleaved repetitions.", "",
        "| run | seconds (median) | × the curve |", "|---|---|---|",
        *[f"| {name} | {t:.3f} | {t / med['curve']:.2f} |" for name, t in med.items()], "",
        f"The curve takes **{s['curve_over_sweep']:.2f}×** the sweep's time "
        f"({'met' if s['met'] else '**missed**'}: the target is the full curve in less time than the sweep), "
        f"{s['curve_over_plain_sweep']:.2f}× the sweep with the paper's plain scheme.", "",
        "![the curve and the sweep's points; the times](figures/orbits-speed.png)", "",
    ]


def figure(record: dict, path: Path = FIGURE) -> Path:
    plt = pyplot()
    c, sw = record["curve"], record["sweep"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [3, 1]})
    a.plot(sw["omega"], sw["amplitude"], ".", color="0.6", ms=3, label=f"sweep ({sw['points']} points)")
    w, amp, stable = np.array(c["values"]), np.array(c["amplitude"]), np.array(c["stable"])
    for ok, style in ((True, "-"), (False, "--")):
        a.plot(w, np.where(stable == ok, amp, np.nan), style, color="k", lw=1,
               label=f"period-1 orbits, {'stable' if ok else 'unstable'} ({int(np.sum(stable == ok))} points)")
    a.set_xlabel(r"$\omega$")
    a.set_ylabel("A (x)")
    a.legend(fontsize=7)
    a.set_title(f"{record['model']}: period-1 curve and the brute-force sweep", fontsize=9)
    med = summary(record)["median_seconds"]
    b.barh(list(med), list(med.values()), color=["k", "0.6", "0.8"])
    b.set_xlabel("seconds (median)")
    b.tick_params(labelsize=7)
    fig.tight_layout()
    return save_figure(fig, path, dpi=100)
