"""Basin maps and basin fractions along a parameter.

:func:`plot_basin_map` colours every start of the grid by the attractor it reached (a colour per attractor;
black: diverged; light grey: undetermined), draws each attractor's Poincare points on top in a darker shade of its
colour (the axes widen to show them where they lie outside the grid), and says in the legend what each attractor
is (period, regime, amplitude) and how much of the grid its basin covers. :func:`plot_basin_fractions` draws the
fraction of every attractor (by its id along the parameter) with its standard error, and its amplitude, against
the parameter, with the appearances, merges and vanishings marked.

:func:`save_basin_map` and :func:`save_basin_fractions` write a result's files as the command writes them: its
tables (:mod:`gearsym.physical.files`) and its picture, each whole.

Each takes the result it draws as it is shown (:class:`~gearsym.physical.basins.ShownBasinMap`,
:class:`~gearsym.physical.basins.ShownFractions`: a model with physical values in µm, mm/s, rpm), or the engine's
result, drawn in the model's own numbers.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from ..analysis.basins import BasinMap
from ..files.atomic import write_atomically
from ..physical.basins import ShownBasinMap, ShownFractions
from ..physical.files import write_basin_fractions, write_basin_map
from ..physical.text import SYMBOLS
from ..sweep.basin_continuation import BasinContinuation
from .save import figure_bytes, pyplot, save_figure

#: the resolution the basins' figures are written at
BASINS_DPI = 120
#: colours of the attractors by number (or id), then of the two other classes
COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",
          "#7f7f7f")
DIVERGED_COLOR, UNDETERMINED_COLOR = "#000000", "#dddddd"
REGIME_MARKERS = {"periodic": "o", "quasi-periodic": "s", "chaotic": "^", "hyperchaotic": "D", "undetermined": "v"}


def color(number: int) -> str:
    return COLORS[(number - 1) % len(COLORS)]


def axis_label(name: str, unit: str) -> str:
    symbol = SYMBOLS.get(name, name)
    return f"{symbol} [{unit}]" if unit else symbol


def cell_edges(v: np.ndarray) -> np.ndarray:
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _darker(c: str) -> tuple:
    from matplotlib.colors import to_rgb
    return tuple(0.55 * x for x in to_rgb(c))


def run_text(result) -> str:
    scheme = "crossings located" if result.locate_crossings else "plain RK4 (the paper's scheme)"
    return (f"{result.periods} periods per start, the first {result.discard} discarded; {result.steps_per_period} "
            f"RK4 steps/period, {scheme}")


def map_title(shown: ShownBasinMap, width: int = 100) -> str:
    result = shown.result
    held = ", ".join(f"{n} = {_shown_number(shown, n, v)}" for n, v in result.held.items())
    (x, xs), (y, ys) = result.axes
    text = (f"{result.model}: basins of attraction over {x} and {y} ({xs.size} x {ys.size} starts"
            + (f"; held: {held}" if held else "") + f") at {shown.parameters_text()}")
    return textwrap.fill(text, width)


def _shown_number(shown: ShownBasinMap, name: str, value: float) -> str:
    v, unit = shown.number(name, value)
    return f"{v:.4g}" + (f" {unit}" if unit else "")


def attractor_label(a, shown: ShownBasinMap) -> str:
    amplitude = ", ".join(f"A_{k} = {_shown_number(shown, k, v)}" for k, v in a.amplitude.items())
    lam = f", λ₁ = {shown.exponent(a.exponents[0])}" if len(a.exponents) and np.isfinite(a.exponents[0]) else ""
    return (f"{a.number}: {a.description}, {100 * a.fraction:.1f} ± {100 * a.stderr:.1f} % of starts; "
            f"{amplitude}{lam}")


def plot_basin_map(shown: ShownBasinMap | BasinMap, path: str | Path | None = None, ax=None):
    """The basin map (as shown, or a :class:`~gearsym.analysis.basins.BasinMap` in the model's own numbers),
    written to ``path`` if given; returns the Figure."""
    plt = pyplot()
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    shown = ShownBasinMap.of(shown)
    result = shown.result
    (x, xs), (y, ys) = result.axes
    sx, ux = shown.state(x, xs)
    sy, uy = shown.state(y, ys)
    numbers = [a.number for a in result.attractors]
    classes = [-1, 0, *numbers]
    cmap = ListedColormap([DIVERGED_COLOR, UNDETERMINED_COLOR, *(color(k) for k in numbers)])
    index = np.searchsorted(classes, result.labels)  # (classes are sorted: -1, 0, 1, 2, ...)
    own = ax is None
    fig, ax = (plt.subplots(figsize=(10.5, 6.2), constrained_layout=True) if own else (ax.figure, ax))
    ax.pcolormesh(cell_edges(sx), cell_edges(sy), index, cmap=cmap, vmin=-0.5, vmax=len(classes) - 0.5, shading="flat",
                  rasterized=True)
    ix, iy = result.state_names.index(x), result.state_names.index(y)
    handles = []
    for a in result.attractors:
        c = color(a.number)
        px, _ = shown.state(x, a.points[ix])
        py, _ = shown.state(y, a.points[iy])
        marker = REGIME_MARKERS.get(a.regime, "o")
        size = 28 if a.points.shape[1] <= 64 else 6
        ax.scatter(px, py, s=size, marker=marker, color=c, edgecolors=[_darker(c)], linewidths=0.9, zorder=3)
        handles.append(Patch(facecolor=c, edgecolor=_darker(c), label=attractor_label(a, shown)))
    empty = []  # (a class no start is in has no colour on the map: the legend's title says so instead)
    for label, share, c in (("diverged", result.diverged, DIVERGED_COLOR), ("undetermined", result.undetermined,
                                                                             UNDETERMINED_COLOR)):
        if share.starts:
            handles.append(Patch(facecolor=c, edgecolor="0.4",
                                 label=f"{label}: {100 * share.fraction:.1f} ± {100 * share.stderr:.1f} % of starts"))
        else:
            empty.append(label)
    ax.set_xlabel(axis_label(x, ux))
    ax.set_ylabel(axis_label(y, uy))
    ax.margins(0.02)
    title = "attractor: what it is, its basin (the markers: its Poincaré points)" + (
        "\nno start " + " or ".join(empty) if empty else "")
    if own:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, frameon=False,
                  title=title, title_fontsize=7.5)
    else:  # a panel among others: the legend below it
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=6.5, frameon=False,
                  title=title, title_fontsize=6.5)
    if own:
        ax.set_title(map_title(shown), fontsize=8.5)
        fig.supxlabel(textwrap.fill(run_text(result) + ". Each attractor's exponents from one tangent run on it; a "
                                    "basin's ± is the binomial standard error of the fraction.", 150),
                      fontsize=7, color="0.35")
    if path is not None:
        save_figure(fig, path, dpi=BASINS_DPI)
    return fig


def plot_basin_fractions(shown: ShownFractions | BasinContinuation, path: str | Path | None = None):
    """The fractions and amplitudes of a basin continuation (as shown, or a
    :class:`~gearsym.sweep.basin_continuation.BasinContinuation` in the model's own numbers) against its parameter,
    written to ``path`` if given; returns the Figure."""
    plt = pyplot()
    shown = ShownFractions.of(shown)
    result = shown.result
    name, values, unit = shown.parameter()
    where = dict(zip(result.values, values))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7.5), sharex=True, constrained_layout=True,
                                      gridspec_kw={"height_ratios": [3, 2]})
    from matplotlib.lines import Line2D

    keys = []  # (the legend's keys are the lines the error bars are drawn on: a key per attractor, as drawn)
    for aid in result.ids:
        rows = [r for r in result.rows if r.id == aid]
        px = np.array([where[r.value] for r in rows])
        top.errorbar(px, [r.fraction for r in rows], yerr=[r.stderr for r in rows], color=color(aid), lw=1.2,
                     marker="o", ms=3.5, capsize=2)
        keys.append(Line2D([], [], color=color(aid), lw=1.2, marker="o", ms=3.5, label=f"attractor {aid}"))
        for r, xv in zip(rows, px):
            for k, amp in r.amplitude.items():
                shown_amp, _ = shown.amplitude(k, amp, r.value)
                bottom.plot(xv, shown_amp, marker=REGIME_MARKERS.get(r.regime, "o"), color=color(aid), ms=4.5,
                            ls="none")
        first = next(iter(rows[0].amplitude), None)
        if first is not None:
            amps = [shown.amplitude(first, r.amplitude[first], r.value)[0] for r in rows]
            bottom.plot(px, amps, color=color(aid), lw=0.8, alpha=0.6)
    for kind, c in (("diverged", DIVERGED_COLOR), ("undetermined", UNDETERMINED_COLOR)):
        f = result.fractions(kind)
        if f.any():
            top.plot(values, f, color=c if kind == "diverged" else "0.6", ls="--", lw=1.0, label=kind)
    said: dict[float, list[str]] = {}
    for e in result.events:
        said.setdefault(where[e["value"]], []).append(
            {"appears": f"{e['attractor']} appears", "vanishes": f"{e['attractor']} vanishes",
             "merges": f"{e['attractor']} merges into {e['into']}"}[e["event"]])
    for xv, texts in said.items():  # (one line per value: the events of one value never overlap)
        top.axvline(xv, color="0.7", ls=":", lw=0.8)
        top.annotate(", ".join(texts), (xv, 1.0), xytext=(2, -4), textcoords="offset points", rotation=90, va="top",
                     fontsize=6.5, color="0.3")
    top.set_ylim(-0.02, 1.05)
    top.set_ylabel("fraction of starts (± binomial s.e.)")
    top.legend(handles=[*keys, *top.get_legend_handles_labels()[0]], fontsize=7, ncol=4, loc="lower left",
               bbox_to_anchor=(0.0, 1.0), frameon=False)
    coordinate = next((k for r in result.rows for k in r.amplitude), "")
    unit_a = shown.unit(coordinate) if coordinate else ""
    bottom.set_ylabel(f"A ({coordinate})" + (f" [{unit_a}]" if unit_a else ""))
    regimes = {r.regime for r in result.rows}  # (a key for each regime drawn, none for the others)
    bottom.legend(handles=[Line2D([], [], marker=m, ls="none", color="0.3", label=k) for k, m in REGIME_MARKERS.items()
                           if k in regimes],
                  fontsize=7, ncol=4, loc="best", title="regime (from the exponents)", title_fontsize=7)
    bottom.set_xlabel(axis_label(name, unit))
    record = result.record
    fixed = {k: v for k, v in record.get("settings", {}).items()}
    grid = record.get("grid")
    grid_text = ", ".join(grid) if isinstance(grid, list) else " x ".join(
        f"{k} in [{min(v):g}, {max(v):g}] ({len(v)})" for k, v in grid.items())
    title = (f"{result.model}: basin fractions along {SYMBOLS.get(name, name)} (each attractor by its id, matched "
             f"from one value to the next by its Poincaré set); grid {grid_text}"
             + (f"; {shown.parameters_text(fixed)} (the rest: the model's declared values)" if fixed
                else "; the other parameters: the model's declared values")
             + f"; {record['periods']} periods per start, {record['discard']} discarded, "
             + ("crossings located" if record.get("locate_crossings") else "plain RK4"))
    fig.suptitle(textwrap.fill(title, 150), fontsize=8)
    if path is not None:
        save_figure(fig, path, dpi=BASINS_DPI)
    return fig


def save_basin_map(shown: ShownBasinMap | BasinMap, out: str | Path | None = None,
                   plot: str | Path | None = None) -> list[Path]:
    """A basin map's files, each written whole: ``out`` (one row per start) with its record beside it
    (:func:`~gearsym.physical.files.write_basin_map`), and the picture ``plot``; the picture is drawn before
    anything is written, so that a figure that fails leaves no table without its picture. Returns the paths
    written, in that order."""
    shown = ShownBasinMap.of(shown)
    picture = figure_bytes(plot_basin_map(shown), plot, BASINS_DPI) if plot else None
    written = list(write_basin_map(shown, out)) if out else []
    return written + ([write_atomically(plot, picture)] if plot else [])


def save_basin_fractions(shown: ShownFractions | BasinContinuation, physical: str | Path | None = None,
                         plot: str | Path | None = None) -> list[Path]:
    """A continuation's files beside its own (which it writes as it goes), each written whole: the fractions in
    the model's units (``physical``: :func:`~gearsym.physical.files.write_basin_fractions`) and the picture
    ``plot``, drawn before anything is written. Returns the paths written, in that order."""
    shown = ShownFractions.of(shown)
    picture = figure_bytes(plot_basin_fractions(shown), plot, BASINS_DPI) if plot else None
    written = [write_basin_fractions(shown, physical)] if physical is not None else []
    return written + ([write_atomically(plot, picture)] if plot else [])
