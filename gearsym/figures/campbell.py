"""The Campbell diagram beside the amplitude of a sweep over the same speeds."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .save import pyplot, save_figure
from .sweep import plot_amplitude


def plot_campbell(diagram, path: str | Path | None = None, sweep=None, coordinate: str | None = None):
    """Left: natural frequencies (horizontal), excitation orders (through the origin), their crossings.
    Right (with ``sweep``, a SweepResult in physical units over the same speeds): the amplitude, with the
    crossing speeds marked."""
    plt = pyplot()
    panels = 2 if sweep is not None else 1
    fig, axs = plt.subplots(1, panels, figsize=(6.5 * panels, 4.8), constrained_layout=True, squeeze=False)
    ax = axs[0, 0]
    speeds = np.linspace(0.0, float(diagram.speeds.max()), 200)
    top = max([*diagram.natural_frequencies, 1.0]) * 1.6
    for i, order in enumerate(diagram.orders):
        style = "-" if order.kind == "mesh" else ":"
        ax.plot(speeds, order.frequency(diagram.speeds_rad_s(speeds)), style, color=f"C{i}", lw=1.1,
                label=order.label)
    for fn in diagram.natural_frequencies:
        ax.axhline(fn, color="k", lw=1.0)
        ax.text(speeds[1], fn, f" {fn:.0f} Hz", va="bottom", fontsize=8)
    for c in diagram.crossings:
        ax.plot(c.speed, c.natural_frequency, "o", mfc="none", mec="r", ms=8)
    ax.axvspan(float(diagram.speeds.min()), float(diagram.speeds.max()), color="0.92", zorder=0)
    ax.set_xlim(0, speeds[-1])
    ax.set_ylim(0, top)
    ax.set_xlabel(f"speed [{diagram.speed_unit}]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(f"{diagram.model}: Campbell diagram (circles: an order meets a natural frequency)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    if sweep is not None:
        right = axs[0, 1]
        plot_amplitude(right, sweep, coordinate)
        at: dict[float, list[str]] = {}
        for c in diagram.crossings:
            at.setdefault(round(c.speed, 6), []).append(c.order)
        for speed, names in at.items():
            right.axvline(speed, color="r", lw=0.8, ls="--")
            right.text(speed, right.get_ylim()[1], " " + ", ".join(names), rotation=90, va="top", ha="right",
                       fontsize=7, color="r")
        right.set_xlim(float(diagram.speeds.min()), float(diagram.speeds.max()))
        right.set_xlabel(f"speed [{diagram.speed_unit}]")
        right.set_title("amplitude over the same speeds (dashed: the crossings)", fontsize=9)
        right.legend(fontsize=7)
    if path is not None:
        save_figure(fig, path, dpi=120)
    return fig
