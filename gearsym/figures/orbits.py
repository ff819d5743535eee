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
from .layout import fit_texts
from .save import pyplot, save_figure
from .sweep import _axis_label, _with_unit

#: marker and short label of each kind of bifurcation
MARKS = {FOLD: ("o", "F", "fold (a multiplier through +1)"),
         PERIOD_DOUBLING: ("s", "PD", "period doubling (a multiplier through -1)"),
         NEIMARK_SACKER: ("D", "NS", "Neimark-Sacker (a complex pair through |mu| = 1)"),
         GRAZING: ("^", "G", "grazing (the orbit touches a backlash surface)")}
#: the bifurcations' markers: open (an open marker never hides another at the same point), in one colour,
#: above every curve and sweep point; a smaller marker drawn above a larger one
MARK_COLOR = "C3"
MARK_STYLE = {FOLD: dict(ms=6.0, zorder=6), PERIOD_DOUBLING: dict(ms=6.5, zorder=5),
              NEIMARK_SACKER: dict(ms=6.0, zorder=6), GRAZING: dict(ms=5.0, zorder=7)}
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


def _stabilities(br) -> set[bool]:
    """Which stabilities (True: stable) a branch's curve draws."""
    largest = np.max(np.abs(br.multipliers), axis=1)
    return {stable for stable, _, _ in _stable_segments(br.values, br.amplitude[:, 0], largest)}


def _marked(result: Continuation, j: int) -> list[tuple[float, float, object]]:
    """(parameter value, amplitude of coordinate ``j``, bifurcation) of every located bifurcation."""
    out = []
    for b in result.bifurcations:
        br = result.branches[b.branch]
        i = int(np.argmin(np.abs(br.values - b.value) + np.where(np.isin(np.arange(len(br)), br.events), 0, 1e9)))
        out.append((float(b.value), float(br.amplitude[i, j]), b))
    return out


def plot_branches(ax, result: Continuation, coordinate: str | None = None, *, label_values: bool = True,
                  legend: bool = True) -> None:
    """Amplitude of ``coordinate`` (default the first observed state) along every branch, with the
    bifurcations marked (open markers above the curves) and, for up to ``LABELLED`` of them, their parameter
    values written where no other label, marker or the legend is (:func:`place_labels`)."""
    coordinate = coordinate or result.observed[0]
    if coordinate not in result.observed:
        raise GearsymError(f"no coordinate {coordinate!r} in the continuation; the coordinates are "
                           f"{', '.join(result.observed)}")
    j = result.observed.index(coordinate)
    for br in result.branches:
        largest = np.max(np.abs(br.multipliers), axis=1)
        for stable, x, y in _stable_segments(br.values, br.amplitude[:, j], largest):
            ax.plot(x, y, "-" if stable else "--", color=branch_color(br.period_multiple), lw=1.2 if stable else 0.9,
                    zorder=2)
    marked = _marked(result, j)
    for value, amplitude, b in marked:
        marker, short, _ = MARKS[b.kind]
        ax.plot(value, amplitude, marker, mfc="none", mec=MARK_COLOR, mew=1.2, ls="", **MARK_STYLE[b.kind])
    ax.set_xlabel(_axis_label(result.parameter, result.units))
    ax.set_ylabel(_with_unit(f"$A$ ({coordinate})", result.units, f"A_{coordinate}"))
    if legend:
        ax.legend(handles=legend_handles(result), fontsize=7, loc="best")
    if label_values and len(marked) <= LABELLED:
        place_labels(ax, [(v, a, f"{MARKS[b.kind][1]} {_value_text(v)}") for v, a, b in marked])


def _value_text(value: float) -> str:
    """A bifurcation's parameter value as labelled: whole numbers in rpm and other large units, else 3 decimals."""
    return f"{value:.0f}" if abs(value) >= 1000 else f"{value:.3f}"


def place_labels(ax, labels) -> list:
    """Write each (x, y, text) of ``labels`` near its point, where it overlaps no other label, no marked point
    and not the legend, inside the axes, crossing as few curves as it can, joined to its point by a thin
    line when it had to move away. Returns the labels' Annotations.

    The figure is laid out first (fitted: :func:`~.layout.fit_texts`); the labels are placed in pixels (written
    as offsets in points, so that they stay put at any resolution) and kept out of the layout, so that they stay
    where they were put."""
    if not labels:
        return []
    fig = ax.figure
    fit_texts(fig)  # (the layout, where the labels are placed: made already if the figure was fitted)
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    points = ax.transData.transform(np.array([(x, y) for x, y, _ in labels], dtype=float))
    pad = max(MARK_STYLE[k]["ms"] for k in MARK_STYLE) / 2 * fig.dpi / 72 + 1  # a marker's half size, pixels
    blocked = [(px - pad, py - pad, px + pad, py + pad) for px, py in points]
    legend = ax.get_legend()
    if legend is not None:
        box = legend.get_window_extent(renderer)
        blocked.append((box.x0, box.y0, box.x1, box.y1))
    curves = [ax.transData.transform(np.column_stack([ln.get_xdata(), ln.get_ydata()]).astype(float))
              for ln in ax.lines if len(ln.get_xdata()) > 1]
    curve = np.vstack(curves) if curves else np.zeros((0, 2))
    placed, notes = [], []
    angles = np.deg2rad([90, 270, 45, 135, 315, 225, 0, 180, 67.5, 112.5, 292.5, 247.5])
    for (x, y, text), (px, py) in sorted(zip(labels, points), key=lambda item: item[0][0]):
        probe = ax.text(0, 0, text, fontsize=6)
        extent = probe.get_window_extent(renderer)
        probe.remove()
        w, h = extent.width + 2, extent.height + 2
        best, best_cost = None, np.inf
        for r in (2.0, 8.0, 16.0, 26.0, 38.0, 52.0, 70.0):
            for a in angles:
                cx = px + np.cos(a) * (w / 2 + r)
                cy = py + np.sin(a) * (h / 2 + r)
                box = (cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)
                crossed = np.count_nonzero((curve[:, 0] > box[0]) & (curve[:, 0] < box[2])
                                           & (curve[:, 1] > box[1]) & (curve[:, 1] < box[3]))
                cost = 1e3 * (sum(_overlap(box, b) for b in blocked + placed) + _outside(box, frame)) \
                    + crossed + r / 10
                if cost < best_cost:
                    best, best_cost = (cx, cy, box, r), cost
        cx, cy, box, r = best
        placed.append(box)
        scale = 72.0 / fig.dpi
        note = ax.annotate(text, (x, y), xytext=((cx - px) * scale, (cy - py) * scale), textcoords="offset points",
                           fontsize=6, color=MARK_COLOR, ha="center", va="center", zorder=8,
                           arrowprops=dict(arrowstyle="-", color=MARK_COLOR, lw=0.5, shrinkA=0, shrinkB=3)
                           if r > 2.0 else None)
        note.set_in_layout(False)
        notes.append(note)
    return notes


def _overlap(a, b) -> float:
    """The area (pixels) two boxes (x0, y0, x1, y1) share."""
    return max(0.0, min(a[2], b[2]) - max(a[0], b[0])) * max(0.0, min(a[3], b[3]) - max(a[1], b[1]))


def _outside(box, frame) -> float:
    """How much of ``box`` lies outside the axes' ``frame`` (pixels of area, made large)."""
    inside = _overlap(box, (frame.x0, frame.y0, frame.x1, frame.y1))
    return 100.0 * ((box[2] - box[0]) * (box[3] - box[1]) - inside)


def legend_handles(result: Continuation, sweep=None, others=()) -> list:
    """Legend entries of what was drawn, and only that: the line styles of each period's branches (stable,
    unstable: those drawn), the bifurcations located, and with ``sweep`` (a SweepResult; ``True``: both
    directions) its points, a direction each as it ran. ``others``: more continuations drawn in the panel."""
    from matplotlib.lines import Line2D
    results = [result, *others]
    drawn: dict[int, set[bool]] = {}
    for r in results:
        for br in r.branches:
            drawn.setdefault(br.period_multiple, set()).update(_stabilities(br))
    handles = []
    for n in sorted(drawn):
        color = branch_color(n)
        if True in drawn[n]:
            handles.append(Line2D([], [], color=color, lw=1.2, label=f"period {n}, stable"))
        if False in drawn[n]:
            handles.append(Line2D([], [], color=color, lw=0.9, ls="--", label=f"period {n}, unstable"))
    for kind in dict.fromkeys(b.kind for r in results for b in r.bifurcations):
        marker, short, meaning = MARKS[kind]
        handles.append(Line2D([], [], ls="", marker=marker, mfc="none", mec=MARK_COLOR, mew=1.2,
                              ms=MARK_STYLE[kind]["ms"], label=f"{short}: {meaning}"))
    if sweep is True:
        directions = ["up", "down"]
    elif sweep is None or sweep is False:
        directions = []
    else:
        directions = [d for d in ("up", "down", "independent") if np.any(sweep["direction"] == d)]
    for d in directions:
        style = SWEEP_STYLES[d]
        handles.append(Line2D([], [], ls="", label=f"sweep, {SWEEP_LABELS[d]}", **style))
    return handles


#: the brute-force sweep's points under the branches: up as dots, down as rings, independent points as dots
SWEEP_STYLES = {"up": dict(marker=".", color="0.55", ms=3), "down": dict(marker="o", mfc="none", mec="0.55", ms=3),
                "independent": dict(marker=".", color="0.55", ms=3)}
SWEEP_LABELS = {"up": "continuation up", "down": "continuation down", "independent": "independent points"}


def plot_largest_multiplier(ax, result: Continuation) -> None:
    """max |mu| along every branch, on a log scale, with the unit circle's 1."""
    for br in result.branches:
        ax.semilogy(br.values, np.max(np.abs(br.multipliers), axis=1), "-", lw=0.9,
                    color=branch_color(br.period_multiple))
    ax.axhline(1.0, color="C3", lw=0.7)
    ax.set_ylabel(r"largest $|\mu|$")
    ax.set_xlabel(_axis_label(result.parameter, result.units))
    ax.set_title(r"largest Floquet multiplier along each branch (colours as above; red line: $|\mu|$ = 1)",
                 fontsize=8)


def plot_sweep_points(ax, sweep, parameter: str, coordinate: str) -> None:
    """The amplitudes of a brute-force sweep (``gearsym.read_sweep``), up as dots and down as rings, under
    the branches."""
    column = f"A_{coordinate}"
    if parameter not in sweep.columns or column not in sweep.columns:
        raise GearsymError(f"the sweep has no columns {parameter!r} and {column!r} to draw under the branches")
    for direction, style in SWEEP_STYLES.items():
        keep = sweep["direction"] == direction
        if np.any(keep):
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
    fig, axs = plt.subplots(2, 1, figsize=(11.5, 8), sharex=True, constrained_layout=True,
                            gridspec_kw={"height_ratios": [3, 1.3]})
    if sweep is not None:
        plot_sweep_points(axs[0], sweep, result.parameter, coordinate)
    plot_branches(axs[0], result, coordinate, legend=False, label_values=False)
    axs[0].legend(handles=legend_handles(result, sweep), fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                  frameon=False)  # (beside the curves: in the axes it would cover some)
    axs[0].set_xlabel("")
    plot_largest_multiplier(axs[1], result)
    axs[0].set_title(orbits_title(result, 105), fontsize=8)
    fit_texts(fig)
    marked = _marked(result, result.observed.index(coordinate))
    if len(marked) <= LABELLED:
        place_labels(axs[0], [(v, a, f"{MARKS[b.kind][1]} {_value_text(v)}") for v, a, b in marked])
    if path is not None:
        save_figure(fig, path, dpi=120)
    return fig
