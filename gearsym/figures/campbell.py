"""The Campbell diagram beside the amplitude of a sweep over the same speeds."""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .layout import LINE_COLORS
from .save import finish, pyplot
from .sweep import plot_amplitude

#: a crossing (an order meets a natural frequency): the same mark in both panels
CROSSING = dict(marker="o", mfc="none", mec="C3", mew=1.3, ms=8, ls="", zorder=6)


def coinciding_orders(orders) -> list[tuple[str, str, float]]:
    """(label, kind, frequency per speed) of each line to draw: orders of the same frequency (the torque's
    first harmonic at the mesh frequency) are one line named after all of them, so that none hides another;
    drawn solid if a mesh order is among them, dotted if only torque orders are."""
    lines: dict[float, list] = {}
    for o in orders:
        lines.setdefault(round(o.per_speed, 9), []).append(o)
    return [(" = ".join(o.label for o in same), "mesh" if any(o.kind == "mesh" for o in same) else "torque",
             same[0].per_speed) for same in lines.values()]


def crossings_at(crossings) -> dict[tuple[float, float], list[str]]:
    """The orders meeting each (speed, natural frequency): coinciding orders meet it at one point."""
    at: dict[tuple[float, float], list[str]] = {}
    for c in crossings:
        at.setdefault((round(c.speed, 6), round(c.natural_frequency, 6)), []).append(c.order)
    return at


def frequency_range(diagram) -> float:
    """The top of the frequency axis: the range that holds the crossings (a quarter above the highest), or
    without any, what the orders reach over the speeds and the lowest natural frequency; natural frequencies above
    it are named, not drawn."""
    fastest = max((per_speed for _, _, per_speed in coinciding_orders(diagram.orders)), default=0.0)
    reached = fastest * float(np.max(diagram.speeds_rad_s(np.array([diagram.speeds.max()])))) / (2 * np.pi)
    crossed = [c.natural_frequency for c in diagram.crossings]
    if crossed:
        return 1.25 * max(crossed)
    lowest = min(diagram.natural_frequencies, default=1.0)
    return 1.25 * max(min(reached, lowest), 1.0) if reached else 1.6 * lowest


def plot_campbell(diagram, path: str | Path | None = None, sweep=None, coordinate: str | None = None, *,
                  settings: Mapping[str, str] | None = None):
    """Left: natural frequencies (horizontal), excitation orders (through the origin), their crossings.
    Right (with ``sweep``, a SweepResult in physical units over the same speeds): the amplitude, with the
    crossing speeds marked. Both panels span the diagram's speeds; ``settings`` (as given, in the user's
    units) go into the title."""
    plt = pyplot()
    panels = 2 if sweep is not None else 1
    fig, axs = plt.subplots(1, panels, figsize=(6.5 * panels, 5.0), constrained_layout=True, squeeze=False)
    ax = axs[0, 0]
    low, high = float(diagram.speeds.min()), float(diagram.speeds.max())
    speeds = np.linspace(low, high, 200)
    top = frequency_range(diagram)
    unit = diagram.speed_unit
    for i, (label, kind, per_speed) in enumerate(coinciding_orders(diagram.orders)):
        hz = per_speed * diagram.speeds_rad_s(speeds) / (2 * np.pi)
        ax.plot(speeds, hz, "-" if kind == "mesh" else ":", color=LINE_COLORS[i % len(LINE_COLORS)],
                lw=1.4 if kind == "mesh" else 1.8, label=label, zorder=3)
    shown = [fn for fn in diagram.natural_frequencies if fn <= top]
    for k, fn in enumerate(shown):
        ax.axhline(fn, color="k", lw=1.0, zorder=2)
        close = k > 0 and fn - shown[k - 1] < 0.04 * top  # (labels of close frequencies: one above, one below)
        ax.text(0.01, fn, f"natural frequency {fn:.0f} Hz", transform=ax.get_yaxis_transform(),
                va="top" if close else "bottom", ha="left", fontsize=7.5)  # (at the low speeds)
    above = [fn for fn in diagram.natural_frequencies if fn > top]
    if above:  # (no order reaches them over these speeds: named, not drawn)
        ax.text(0.99, 0.99, "above, not reached: " + ", ".join(f"{fn:.0f} Hz" for fn in above),
                transform=ax.transAxes, ha="right", va="top", fontsize=7)
    at = crossings_at(diagram.crossings)
    for k, ((speed, fn), names) in enumerate(at.items()):
        ax.plot(speed, fn, **CROSSING, label="crossing: an order meets a natural frequency"
                if k == 0 else "_nolegend_")
        ax.annotate(f"{speed:.0f} {unit}", (speed, fn), xytext=(4, -11), textcoords="offset points", fontsize=7,
                    color="C3")
    ax.set_xlim(low, high)
    ax.set_ylim(0, top)
    ax.set_xlabel(f"speed [{unit}]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("Campbell diagram: excitation orders (solid: mesh, dotted: torque) against the natural "
                 "frequencies", fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=2, frameon=False)
    if sweep is not None:
        right = axs[0, 1]
        plot_amplitude(right, sweep, coordinate)
        column = f"A_{coordinate or sweep.coordinates[0]}"
        x = sweep.axes[0].name
        _, _, run = sweep.lines()[0]  # (the first run: up where there are two)
        along, amplitudes = np.asarray(sweep[x])[run], np.asarray(sweep[column])[run]
        order = np.argsort(along)
        for k, ((speed, _), names) in enumerate(at.items()):
            right.axvline(speed, color="C3", lw=0.8, ls="--", zorder=1,
                          label="crossing speed (left panel's circles)" if k == 0 else "_nolegend_")
            amplitude = np.interp(speed, along[order], amplitudes[order])
            right.plot(speed, amplitude, **CROSSING)
            right.annotate(f"{' = '.join(names)}\n{speed:.0f} {unit}", (speed, 1.0),
                           xycoords=("data", "axes fraction"), xytext=(-3, -4), textcoords="offset points",
                           rotation=90, va="top", ha="right", fontsize=7, color="C3")
        bottom, top = right.get_ylim()
        right.set_ylim(bottom, bottom + (top - bottom) / 0.65)  # the crossings' names above the curve
        right.set_xlim(low, high)
        right.set_xlabel(f"speed [{unit}]")
        right.set_title("amplitude over the same speeds (circles: at the crossing speeds)", fontsize=9)
        right.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=2, frameon=False)
    given = ", ".join(f"{k}={v}" for k, v in (settings or {}).items())
    fig.suptitle(f"{diagram.model}: Campbell diagram over {low:g}..{high:g} {unit}"
                 + (f" ({given})" if given else " (the model's values)") + "; natural frequencies "
                 + ", ".join(f"{f:.6g} Hz" for f in diagram.natural_frequencies), fontsize=9)
    return finish(fig, path, dpi=120)
