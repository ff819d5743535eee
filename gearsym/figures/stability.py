"""The stability chart: the tongues shaded by the kind of instability, the boundaries drawn over them, the axes in
the user's units, the model and its fixed parameters in the title; for a model with several meshes whose phases
differ (a planetary set), a second panel with the first-order prediction of which tongues the mesh phasing
leaves and which it suppresses (:mod:`gearsym.stability.phasing`)."""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..stability.chart import StabilityChart
from ..stability.kinds import FOLD, NEIMARK_SACKER, PERIOD_DOUBLING
from ..physical.basins import OwnNumbers
from .basins import axis_label, cell_edges
from .save import finish, pyplot

#: the colour of each kind (stable: white), and of the points without a result
KIND_COLORS = {FOLD: "#f4a261", PERIOD_DOUBLING: "#4c8bd6", NEIMARK_SACKER: "#8fbf6a"}
NO_RESULT_COLOR = "#9a9a9a"
KIND_LABELS = {FOLD: "fold: a multiplier through +1 (T-periodic on the boundary)",
               PERIOD_DOUBLING: "period doubling: through -1 (2T-periodic on the boundary)",
               NEIMARK_SACKER: "Neimark-Sacker: a complex pair (combination resonance)"}


def draw_chart(ax, chart: StabilityChart, *, boundaries: bool = True) -> list:
    """The shaded kinds and the boundary curves on ``ax``; returns the legend's handles."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    a, b = chart.values
    codes = {None: 0, FOLD: 1, PERIOD_DOUBLING: 2, NEIMARK_SACKER: 3}
    grid = np.array([[codes.get(k, 4) for k in row] for row in chart.kind], dtype=float)
    cmap = ListedColormap(["white", KIND_COLORS[FOLD], KIND_COLORS[PERIOD_DOUBLING], KIND_COLORS[NEIMARK_SACKER],
                           NO_RESULT_COLOR])
    ax.pcolormesh(cell_edges(np.asarray(a)), cell_edges(np.asarray(b)), grid, cmap=cmap, vmin=-0.5, vmax=4.5,
                  shading="flat", rasterized=True)
    present = {k for row in chart.kind for k in row}
    handles = [Patch(facecolor=KIND_COLORS[k], edgecolor="none", label=KIND_LABELS[k]) for k in KIND_COLORS
               if k in present]
    missing = sorted(k for k in present if k is not None and k not in KIND_COLORS)
    if missing:
        handles.append(Patch(facecolor=NO_RESULT_COLOR, edgecolor="none", label=", ".join(missing)))
    if boundaries and chart.boundaries:
        for curve in chart.boundaries:
            style = dict(color="black", lw=0.9) if len(curve.points) > 1 else dict(color="black", marker="|", ms=8)
            ax.plot(curve.points[:, 0], curve.points[:, 1], **style)
        from matplotlib.lines import Line2D
        tol = ", ".join(f"{axis_label(n, u)} to {t:.2g}" for n, u, t in zip(chart.names, chart.units, chart.tolerance))
        handles.append(Line2D([], [], color="black", lw=0.9, label=f"boundary |μ|max = 1 (located: {tol})"))
    ax.set_xlim(cell_edges(np.asarray(a))[[0, -1]])
    ax.set_ylim(cell_edges(np.asarray(b))[[0, -1]])
    ax.set_xlabel(axis_label(chart.names[0], chart.units[0]))
    ax.set_ylabel(axis_label(chart.names[1], chart.units[1]))
    return handles


def chart_title(chart: StabilityChart, shown: OwnNumbers | None = None, title: str | None = None,
                fixed: str | None = None) -> str:
    """The chart's title: the model, what is charted, and the values held over it (``fixed``: as the user gave
    them, for a model with physical values; else the chart's own numbers)."""
    shown = shown or OwnNumbers()
    about = "its static state" if chart.about == "static" else "its period-1 orbit"
    fixed = fixed if fixed is not None else shown.parameters(chart.fixed)
    return (f"{title or chart.model}: Floquet stability of {about}, {chart.steps_per_period} RK4 steps/period\n"
            f"{fixed}")


def plot_stability(chart: StabilityChart, path: str | Path | None = None, *, shown: OwnNumbers | None = None,
                   prediction=None, exact: Sequence[tuple[str, np.ndarray]] = (), title: str | None = None,
                   fixed: str | None = None):
    """The chart (and, with ``prediction``, the phasing rule's panel beside it); ``exact``: curves (label,
    points k x 2) drawn dashed over the chart (a check against known transition curves); ``fixed``: the values held
    over it as the user gave them (:func:`chart_title`). Written to ``path`` if given; returns the Figure."""
    plt = pyplot()
    panels = 2 if prediction is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(7.2 * panels, 6.4), squeeze=False, constrained_layout=True)
    ax = axes[0, 0]
    handles = draw_chart(ax, chart)
    from matplotlib.lines import Line2D
    for k, (label, points) in enumerate(exact):
        ax.plot(points[:, 0], points[:, 1], ls=(0, (4, 3)), color="#c0392b", lw=1.1,
                label=label if k == 0 else None)
    if exact:
        handles.append(Line2D([], [], ls=(0, (4, 3)), color="#c0392b", lw=1.1, label=exact[0][0]))
    ax.set_title("unstable where a multiplier lies outside the unit circle", fontsize=9)
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.11), fontsize=8, frameon=False, ncol=1)
    if prediction is not None:
        draw_prediction(axes[0, 1], prediction, chart)
    fig.suptitle(chart_title(chart, shown, title, fixed), fontsize=10)
    return finish(fig, path, dpi=130)


def draw_prediction(ax, prediction, chart: StabilityChart) -> None:
    """The phasing rule's panel: each first-order tongue as a wedge from the axis (kept: shaded; suppressed by
    the mesh phasing: a dotted line and a cross), with the chart's boundaries in grey for comparison."""
    a, b = chart.values
    for curve in chart.boundaries:
        ax.plot(curve.points[:, 0], curve.points[:, 1], color="0.65", lw=0.7)
    top, bottom, span = float(np.max(b)), float(np.min(b)), float(np.ptp(a)) or 1.0
    kept_drawn = suppressed_drawn = False
    for t in prediction.tongues:
        if not (np.min(a) <= t.centre <= np.max(a)):
            continue
        if t.suppressed:
            ax.plot([t.centre, t.centre], [bottom, top], ls=":", color="#b03030", lw=1.0)
            ax.plot([t.centre], [bottom], marker="x", color="#b03030", ms=6, ls="none",
                    label=None if suppressed_drawn else "suppressed by the mesh phasing (its coupling is 0)")
            suppressed_drawn = True
        else:
            if 2 * t.half_width < 2e-3 * span:  # (too thin to see at this scale: left out, and not labelled)
                continue
            eps = np.linspace(0, top, 50)
            lo, hi = t.edges(eps, prediction.scale)
            ax.fill_betweenx(eps, lo, hi, color=KIND_COLORS[t.kind], alpha=0.55, lw=0,
                             label=None if kept_drawn else "first-order tongue, undamped (kept by the phasing)")
            kept_drawn = True
        ax.annotate(t.label, (t.centre, bottom), xytext=(2, 4), textcoords="offset points", fontsize=6.5,
                    rotation=90, ha="left", va="bottom", color="#b03030" if t.suppressed else "black")
    ax.set_xlim(cell_edges(np.asarray(a))[[0, -1]])
    ax.set_ylim(cell_edges(np.asarray(b))[[0, -1]])
    ax.set_xlabel(axis_label(chart.names[0], chart.units[0]))
    ax.set_ylabel(axis_label(chart.names[1], chart.units[1]))
    ax.set_title(prediction.title, fontsize=9)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), fontsize=8, frameon=False)
