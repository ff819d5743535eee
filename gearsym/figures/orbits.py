"""The frequency-response curve of a continuation: branches of periodic orbits, stable solid and unstable
dashed, their bifurcations marked, optionally over the points of a brute-force sweep; and the largest
Floquet multiplier along each branch.

:func:`plot_branches` draws on a given ``Axes`` (the reproduction's Fig. 3a uses it);
:func:`plot_orbits` is the figure behind ``gearsym orbits --plot``.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from ..errors import GearsymError
from ..periodic import FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING, Continuation
from .save import pyplot, save_figure
from .sweep import _axis_label, _with_unit

#: marker and short label of each kind of bifurcation
MARKS = {FOLD: ("o", "F", "fold (a multiplier through +1)"),
         PERIOD_DOUBLING: ("s", "PD", "period doubling (a multiplier through -1)"),
         NEIMARK_SACKER: ("D", "NS", "Neimark-Sacker (a complex pair through |mu| = 1)"),
         GRAZING: ("^", "G", "grazing (the orbit touches a backlash surface)")}
#: at most this many bifurcations get their value written beside the marker
LABELLED = 16


def branch_color(period_multiple: int) -> str:
    return {1: "k", 2: "C0", 3: "C1", 4: "C2", 8: "C3"}.get(period_multiple, "C4")


def _stable_segments(values: np.ndarray, y: np.ndarray, largest: np.ndarray):
    """Runs of consecutive points of one stability, each with its end points (so that the curve is unbroken);
    a segment is stable where the mean of its ends' largest |mu| is below 1 (a located bifurcation sits
    on 1, the point beside it says which side the segment is on)."""
    if len(values) < 2:
        return
    stable = (largest[1:] + largest[:-1]) / 2 < 1.0
    start = 0
    for i in range(1, len(stable) + 1):
        if i == len(stable) or stable[i] != stable[start]:
            yield bool(stable[start]), values[start:i + 1], y[start:i + 1]
            start = i


def plot_branches(ax, result: Continuation, coordinate: str | None = None, *, label_values: bool = True,
                  legend: bool = True) -> None:
    """Amplitude of ``coordinate`` (default the first observed state) along every branch, with the
    bifurcations marked (and their parameter values written, for up to ``LABELLED`` of them)."""
    coordinate = coordinate or result.observed[0]
    if coordinate not in result.observed:
        raise GearsymError(f"no coordinate {coordinate!r} in the continuation; the coordinates are "
                           f"{', '.join(result.observed)}")
    j = result.observed.index(coordinate)
    for br in result.branches:
        largest = np.max(np.abs(br.multipliers), axis=1)
        for stable, x, y in _stable_segments(br.values, br.amplitude[:, j], largest):
            ax.plot(x, y, "-" if stable else "--", color=branch_color(br.period_multiple), lw=1.2 if stable else 0.9)
    labelled = len(result.bifurcations) <= LABELLED and label_values
    for k, b in enumerate(result.bifurcations):
        br = result.branches[b.branch]
        i = int(np.argmin(np.abs(br.values - b.value) + np.where(np.isin(np.arange(len(br)), br.events), 0, 1e9)))
        marker, short, _ = MARKS[b.kind]
        ax.plot(b.value, br.amplitude[i, j], marker, ms=5, mfc="white", mec="C3", mew=1.2, zorder=5)
        if labelled:
            value = f"{b.value:.0f}" if abs(b.value) >= 1000 else f"{b.value:.3f}"  # (rpm: whole numbers)
            ax.annotate(f"{short} {value}", (b.value, br.amplitude[i, j]), fontsize=6, color="C3",
                        xytext=(3, 4 if k % 2 == 0 else -9), textcoords="offset points")
    ax.set_xlabel(_axis_label(result.parameter, result.units))
    ax.set_ylabel(_with_unit(f"$A$ ({coordinate})", result.units, f"A_{coordinate}"))
    if legend:
        ax.legend(handles=legend_handles(result), fontsize=7, loc="best")


def legend_handles(result: Continuation, sweep: bool = False) -> list:
    from matplotlib.lines import Line2D
    handles = []
    for n in sorted({b.period_multiple for b in result.branches}):
        color = branch_color(n)
        handles += [Line2D([], [], color=color, lw=1.2, label=f"period {n}, stable"),
                    Line2D([], [], color=color, lw=0.9, ls="--", label=f"period {n}, unstable")]
    for kind in dict.fromkeys(b.kind for b in result.bifurcations):
        marker, short, meaning = MARKS[kind]
        handles.append(Line2D([], [], ls="", marker=marker, mfc="white", mec="C3", mew=1.2, label=f"{short}: {meaning}"))
    if sweep:
        handles += [Line2D([], [], ls="", marker=".", color="0.55", label="sweep, continuation up"),
                    Line2D([], [], ls="", marker="o", mfc="none", mec="0.55", ms=3, label="sweep, continuation down")]
    return handles


def plot_largest_multiplier(ax, result: Continuation) -> None:
    """max |mu| along every branch, on a log scale, with the unit circle's 1."""
    for br in result.branches:
        ax.semilogy(br.values, np.max(np.abs(br.multipliers), axis=1), "-", lw=0.9,
                    color=branch_color(br.period_multiple))
    ax.axhline(1.0, color="C3", lw=0.7)
    ax.set_ylabel(r"largest $|\mu|$")
    ax.set_xlabel(_axis_label(result.parameter, result.units))


def plot_sweep_points(ax, sweep, parameter: str, coordinate: str) -> None:
    """The amplitudes of a brute-force sweep (``gearsym.read_sweep``), up as dots and down as rings."""
    column = f"A_{coordinate}"
    if parameter not in sweep.columns or column not in sweep.columns:
        raise GearsymError(f"the sweep has no columns {parameter!r} and {column!r} to draw under the branches")
    for direction, style in (("up", dict(marker=".", color="0.55", ms=3)),
                             ("down", dict(marker="o", mfc="none", mec="0.55", ms=3))):
        keep = sweep["direction"] == direction
        ax.plot(sweep[parameter][keep], sweep[column][keep], ls="", zorder=1, **style)


def orbits_title(result: Continuation, width: int = 110) -> str:
    """The model, the range, the bifurcations found and the fixed values (a physical model's as the user gave
    them)."""
    physical = result.settings.get("physical")
    if physical:
        fixed = "values: " + ", ".join(f"{k}={v}" for k, v in physical["inputs"].items() if k != result.parameter)
    else:
        fixed = ", ".join(f"{k}={v:g}" for k, v in result.parameters.items())
    unit = f" {result.units[result.parameter]}" if result.parameter in result.units else ""
    kinds = ", ".join(f"{len(result.of_kind(k))} {k}" for k in MARKS if result.of_kind(k)) or "no bifurcations"
    return textwrap.fill(f"{result.model}: periodic orbits over {result.parameter} = {result.start:g}..{result.stop:g}"
                         f"{unit} ({len(result.branches)} branches; {kinds}). {fixed}", width)


def plot_orbits(result: Continuation, path: str | Path | None = None, coordinate: str | None = None, sweep=None):
    """The frequency-response curve of ``coordinate`` over the sweep's points (if given), and the largest
    multiplier below it; written to ``path`` if given. Returns the Figure."""
    plt = pyplot()
    coordinate = coordinate or result.observed[0]
    fig, axs = plt.subplots(2, 1, figsize=(9, 8), sharex=True, constrained_layout=True,
                            gridspec_kw={"height_ratios": [3, 1.3]})
    if sweep is not None:
        plot_sweep_points(axs[0], sweep, result.parameter, coordinate)
    plot_branches(axs[0], result, coordinate, legend=False)
    axs[0].legend(handles=legend_handles(result, sweep is not None), fontsize=7, loc="upper right")
    axs[0].set_xlabel("")
    plot_largest_multiplier(axs[1], result)
    axs[0].set_title(orbits_title(result, 105), fontsize=8)
    if path is not None:
        save_figure(fig, path, dpi=120)
    return fig
