"""The worked example of docs/fmu.md: the one-stage model's FMU run by FMPy, both ways, against gearsym's own run.

Run from the repository root (about half a minute):

    python docs/fmu_example.py

It exports ``gearsym fmu one_stage --set "k=1+0.2*cos(tau)"`` into a temporary folder, simulates the FMU in FMPy
by co-simulation (one communication step per RK4 step of the engine, 200 per forcing period) and by model
exchange (CVode, relative tolerance 1e-10), runs gearsym's own phase trajectory at the same step, and writes
docs/figures/fmu-one_stage.csv (every 10th step of 40 forcing periods) and docs/figures/fmu-one_stage.png.
tests/test_fmu.py computes the data again and compares them with the committed file.
"""
from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

import gearsym
from gearsym import Integration
from gearsym.files.atomic import write_atomically

HERE = Path(__file__).resolve().parent
DATA = HERE / "figures" / "fmu-one_stage.csv"
FIGURE = HERE / "figures" / "fmu-one_stage.png"
K = "1+0.2*cos(tau)"
PERIODS, STEPS, EVERY = 40, 200, 10
TOLERANCE = 1e-10  # CVode's relative tolerance


def compute(fmu: Path, backend: str = "auto") -> dict[str, np.ndarray]:
    """tau and x of gearsym's run (on ``backend``), the co-simulation and model exchange, every EVERY-th step."""
    from fmpy import simulate_fmu

    step = 2 * math.pi / STEPS
    stop = PERIODS * STEPS * step
    cs = simulate_fmu(str(fmu), fmi_type="CoSimulation", stop_time=stop, output_interval=step, output=["x"])
    me = simulate_fmu(str(fmu), fmi_type="ModelExchange", stop_time=stop, output_interval=step, output=["x"],
                      relative_tolerance=TOLERANCE, record_events=False)
    ours = gearsym.phase_trajectory(gearsym.load("one_stage", k=K),
                                    options=Integration(periods=PERIODS, discard=0, backend=backend))
    rows = slice(None, PERIODS * STEPS + 1, EVERY)
    return {"tau": ours.time[rows], "x_gearsym": ours["x"][rows], "x_co_simulation": cs["x"][rows],
            "x_model_exchange": me["x"][rows]}


def write_data(data: dict[str, np.ndarray]) -> None:
    lines = [",".join(data)] + [",".join(f"{v:.15g}" for v in row) for row in zip(*data.values())]
    write_atomically(DATA, "\n".join(lines) + "\n")


def draw(data: dict[str, np.ndarray]) -> None:
    from gearsym.figures.save import save_figure
    import matplotlib.pyplot as plt

    tau, ours, cs, me = (data[k] for k in data)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.4), constrained_layout=True)
    last = tau >= tau[-1] - 4 * 2 * math.pi
    top.plot(tau[last], ours[last], "-", color="black", lw=1.4, label="gearsym (phase_trajectory, located RK4)")
    top.plot(tau[last], cs[last], "o", color="tab:blue", ms=3.5, mfc="none", label="FMU, co-simulation (FMPy)")
    top.plot(tau[last], me[last], "--", color="tab:orange", lw=1.2,
             label=f"FMU, model exchange (FMPy, CVode {TOLERANCE:g})")
    top.axhline(0, color="grey", lw=0.6, ls=":")
    top.axhline(-10, color="grey", lw=0.6, ls=":")
    top.set_xlabel(r"$\tau$ (the last 4 of 40 forcing periods)")
    top.set_ylabel("mesh deflection x")
    top.legend(loc="lower left", fontsize=8)
    top.set_title(r"one_stage with k = 1 + 0.2 cos$\tau$: $\omega$=1.5, $\zeta$=0.08, B0=1, B1=4, $\eta$=10 "
                  "(dotted: the backlash kinks x = 0, -η)", fontsize=9)
    floor = 1e-17
    bottom.semilogy(tau, np.abs(cs - ours) + floor, "-", color="tab:blue", lw=1, label="|co-simulation - gearsym|")
    bottom.semilogy(tau, np.abs(me - ours) + floor, "-", color="tab:orange", lw=1, label="|model exchange - gearsym|")
    bottom.set_xlabel(r"$\tau$ (40 forcing periods, 200 RK4 steps each)")
    bottom.set_ylabel("difference in x (+1e-17)")
    bottom.legend(loc="lower right", fontsize=8)
    save_figure(fig, FIGURE, dpi=110)


def main() -> int:
    from gearsym.cli import main as gearsym_main

    with tempfile.TemporaryDirectory() as tmp:
        fmu = Path(tmp) / "one_stage.fmu"
        if gearsym_main(["fmu", "one_stage", "--set", f"k={K}", "--out", str(fmu)]) != 0:
            return 1
        data = compute(fmu)
    write_data(data)
    draw(data)
    print(f"wrote {DATA.relative_to(HERE.parent)} and {FIGURE.relative_to(HERE.parent)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
