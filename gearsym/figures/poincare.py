"""Poincare maps of coexisting attractors (the paper's Fig. 4) and phase portraits (its Fig. 7).

:func:`plot_attractors` draws the stroboscopic points of every attractor that
:func:`~gearsym.analysis.attractors.find_attractors` found, one panel per
parameter point; several sets may share a panel (Fig. 4 overlays D = 0 in gray
and D = 2 in black at one omega). Each attractor carries the paper's mark, '1'
regular or '2' chaotic, and the marker of its regime: the same kind of attractor
looks the same in every panel, whatever order it was found in.

:func:`plot_phase_portraits` draws a grid of phase portraits: every RK4 step of
some periods as a gray line, the Poincare points of those periods in black on top
(Fig. 7 a-d).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.attractors import Attractor, AttractorSet
from ..analysis.poincare import Trajectory, phase_trajectory
from ..errors import GearsymError
from ..physical.text import parameter_text
from .phase_plane import phase_axes
from .save import finish, pyplot

#: overlaid layers: gray first, then black, as the paper's Fig. 4; then colours
LAYER_COLORS = ("0.55", "k", "C3", "C0", "C2", "C1")
#: one set alone: a colour per class of attractor, the paper's '1' (regular) and '2' (chaotic)
CLASS_COLORS = {"1": "k", "2": "C3"}
#: regular attractors: a marker per regime (chaotic ones are clouds of dots)
REGIME_MARKERS = {"periodic": "o", "quasi-periodic": "s", "equilibrium": "D", "undetermined": "^", "chaotic": ".",
                  "hyperchaotic": "."}
#: how captions write each marker
MARKER_GLYPHS = {"o": "○", "s": "□", "D": "◇", "^": "△", ".": "·"}
#: short forms of the regimes in the annotations
SHORT = {"periodic": "P", "quasi-periodic": "QP", "chaotic": "chaotic", "hyperchaotic": "hyperchaotic",
         "equilibrium": "eq.", "undetermined": "undetermined"}

_STYLE = {"font.size": 9, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 8,
          "axes.linewidth": 0.8, "xtick.direction": "in", "ytick.direction": "in",
          "xtick.top": True, "ytick.right": True}


# ------------------------------------------------------------------------------------ Fig. 4: attractors
def plot_attractors(sets: AttractorSet | Sequence[AttractorSet | Sequence[AttractorSet]], path: str | Path | None = None,
                    x: str | None = None, y: str | None = None, colors: Sequence[str] | None = None,
                    labels: Sequence[str] | None = None):
    """The Poincare points of every attractor, written to ``path`` (PNG) if given; returns the Figure.

    ``sets``: one AttractorSet (one panel), or a sequence whose items are panels;
    a panel is one AttractorSet or a sequence of them drawn on top of each other
    (layer 0 in gray, layer 1 in black, unless ``colors`` says otherwise;
    ``labels`` names the layers in the legend, default the model names).
    ``x``/``y`` choose the state on each axis (default the first state, and the state after ``x``).
    An attractor is marked by its regime, not by the order it was found in: the paper's '1'
    (regular) or '2' (chaotic), the marker of its regime (:data:`REGIME_MARKERS`), and, alone in
    a panel, the colour of its class; so one kind of attractor looks the same in every panel.
    """
    plt = pyplot()
    panels = _panels(sets)
    layers = max(len(p) for p in panels)
    colors = list(colors) if colors else list(LAYER_COLORS[:max(layers, 1)])
    if len(colors) < layers:
        raise GearsymError(f"plot_attractors: {layers} overlaid sets but only {len(colors)} colors")
    if labels is not None and len(labels) < layers:
        raise GearsymError(f"plot_attractors: {layers} overlaid sets but only {len(labels)} labels")
    x, y = phase_axes(panels[0][0].state_names, x, y)
    for panel in panels:
        for s in panel:
            missing = {x, y} - set(s.state_names)
            if missing:
                raise GearsymError(f"plot_attractors: {s.model} has no state {sorted(missing)[0]!r}; "
                                   f"its states are {', '.join(s.state_names)}")

    with plt.rc_context(_STYLE):
        fig, axes = plt.subplots(1, len(panels), figsize=(4.8 * len(panels), 5.0), squeeze=False,
                                 constrained_layout=True)
        for k, (ax, panel) in enumerate(zip(axes[0], panels)):
            drawn = []  # (attractor, x points, y points, color)
            for layer, s in enumerate(panel):
                name = labels[layer] if labels is not None else s.model
                ix, iy = s.state_names.index(x), s.state_names.index(y)
                for a in sorted(s.attractors, key=lambda a: (a.paper_label, -len(a.members))):
                    color = colors[layer] if len(panel) > 1 else CLASS_COLORS[a.paper_label]
                    prefix = f"{name}: " if len(panel) > 1 else ""
                    _draw_attractor(ax, a, a.points[ix], a.points[iy], color, prefix, layer)
                    drawn.append((a, a.points[ix], a.points[iy], color))
            ax.margins(0.12)
            _place_labels(ax, drawn)
            ax.set_xlabel(x)
            ax.set_ylabel(y)
            letter = f"({chr(ord('a') + k)}) " if len(panels) > 1 else ""
            ax.set_title(letter + _common_title(panel))
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), frameon=False, handletextpad=0.3,
                      fontsize=7.5, markerscale=1.0)
        fig.supxlabel(_caption(panels), fontsize=7, color="0.35")
        fig.suptitle(attractors_title(panels, labels), fontsize=9)
        return finish(fig, path, dpi=150)


def attractors_title(panels: Sequence[Sequence[AttractorSet]], labels: Sequence[str] | None = None) -> str:
    """'one_stage: ω=1.6, ζ=0.08, B0=1, ...': the model(s) and every parameter value the sets share; then,
    per overlaid layer, the values that set it apart (those that differ between panels are in the panels'
    titles)."""
    sets = [s for panel in panels for s in panel]
    models = ", ".join(dict.fromkeys(s.model for s in sets))
    shared = dict(sets[0].parameters)
    for s in sets[1:]:
        shared = {k: v for k, v in shared.items() if s.parameters.get(k) == v}
    text = f"{models}: " + (", ".join(parameter_text(k, v) for k, v in shared.items()) or "(no shared values)")
    layers = max(len(p) for p in panels)
    for layer in range(layers if layers > 1 else 0):
        in_layer = [p[layer] for p in panels if layer < len(p)]
        own = {k: v for k, v in in_layer[0].parameters.items() if k not in shared
               and all(s.parameters.get(k) == v for s in in_layer)}
        if own:
            name = labels[layer] if labels is not None else in_layer[0].model
            text += f"; {name}: " + ", ".join(parameter_text(k, v) for k, v in own.items())
    return text


def _panels(sets) -> list[list[AttractorSet]]:
    if isinstance(sets, AttractorSet):
        return [[sets]]
    panels = [[p] if isinstance(p, AttractorSet) else list(p) for p in sets]
    if not panels or any(not p or not all(isinstance(s, AttractorSet) for s in p) for p in panels):
        raise GearsymError("plot_attractors needs AttractorSets: one, a list of them (one panel each), "
                           "or a list of lists (sets overlaid in one panel)")
    return panels


def attractor_kind(a: Attractor) -> str:
    """'P6', 'QP', 'chaotic': the regime in a few letters, with the period of a periodic orbit."""
    return f"P{a.period}" if a.regime == "periodic" and a.period else SHORT.get(a.regime, a.regime)


def _draw_attractor(ax, a: Attractor, px: np.ndarray, py: np.ndarray, color: str, prefix: str, layer: int) -> None:
    """Regular attractors (few points) as the marker of their regime, chaotic ones as a cloud of dots."""
    label = f"{prefix}'{a.paper_label}' {attractor_kind(a)}, λ₁={a.lambda1:+.4f} ({len(a.members)} ICs)"
    marker = REGIME_MARKERS.get(a.regime, ".")
    if marker != ".":
        ax.plot(px, py, marker, ms=4.5, mfc="white" if layer == 0 else color, mec=color, mew=1.0, color=color,
                label=label, zorder=4 + layer)
    else:
        ax.plot(px, py, ".", ms=1.8, mew=0, color=color, alpha=0.85, rasterized=True, zorder=3 + layer)
        ax.plot([], [], ".", ms=6, color=color, label=label)  # a legend mark large enough to see


def _place_labels(ax, drawn) -> None:
    """Each attractor's mark ('1' regular, '2' chaotic, then its number), joined to one of its points.

    Candidate spots: a short step in each of eight directions from (a sample of) the
    attractor's points, inside the axes. The spot taken is the one farthest from every
    plotted point and every label placed so far (in axes fractions), so that marks
    neither hide points nor collide.
    """
    if not drawn:
        return
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()

    def frac(px, py) -> np.ndarray:
        return np.column_stack([(np.asarray(px) - x0) / (x1 - x0), (np.asarray(py) - y0) / (y1 - y0)])

    everything = _thin_rows(np.vstack([frac(d[1], d[2]) for d in drawn]))
    half = np.array([0.065, 0.035])  # half the size of a mark's text, in axes fractions
    angles = np.deg2rad(np.arange(8) * 45.0 + 22.5)
    steps = np.column_stack([np.cos(angles), np.sin(angles)]) * (half + 0.025)
    placed: list[np.ndarray] = []
    for a, px, py, color in drawn:
        anchors = _thin_rows(frac(px, py), 120)
        spots = (anchors[:, None, :] + steps[None, :, :]).reshape(-1, 2)
        inside = np.all((spots > half + 0.01) & (spots < 1 - half - 0.01), axis=1)
        if not inside.any():
            inside[:] = True
        obstacles = np.vstack([everything, *placed]) if placed else everything
        # box distance in units of the text's half size: below 1 the text covers the obstacle (the two coordinates'
        # distances compared elementwise: a maximum over an axis of two is numpy's slowest reduction)
        clearance = np.maximum(np.abs(spots[:, 0, None] - obstacles[None, :, 0]) / half[0],
                               np.abs(spots[:, 1, None] - obstacles[None, :, 1]) / half[1]).min(axis=1)
        best = int(np.argmax(np.where(inside, clearance, -1.0)))
        anchor = anchors[best // len(steps)]
        spot = spots[best]
        placed.append(spot + half * np.array([[-1, -1], [-1, 1], [1, -1], [1, 1], [0, 0]]))  # the text's box
        point = (x0 + anchor[0] * (x1 - x0), y0 + anchor[1] * (y1 - y0))
        ax.annotate(f"$\\mathbf{{{a.paper_label}}}$ {attractor_kind(a)}", point, xytext=tuple(spot),
                    textcoords="axes fraction", ha="center", va="center", fontsize=9, color=_darker(color),
                    arrowprops=dict(arrowstyle="-", color=color, lw=0.6, shrinkA=4, shrinkB=2), zorder=10)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)


def _darker(color: str) -> str:
    """Gray levels ('0.55') a little darker for text; named colours as they are."""
    try:
        return f"{max(float(color) - 0.2, 0.0):g}"
    except ValueError:
        return color


def _thin_rows(points: np.ndarray, limit: int = 2000) -> np.ndarray:
    if len(points) <= limit:
        return points
    return points[np.linspace(0, len(points) - 1, limit).round().astype(int)]


def _common_title(panel: Sequence[AttractorSet]) -> str:
    """The parameters every set of the panel shares, omega first (the paper titles by omega)."""
    shared = dict(panel[0].parameters)
    for s in panel[1:]:
        shared = {k: v for k, v in shared.items() if s.parameters.get(k) == v}
    if "omega" in shared:
        return parameter_text("omega", shared["omega"])
    return ", ".join(parameter_text(k, v) for k, v in list(shared.items())[:3])


def _caption(panels: Sequence[Sequence[AttractorSet]]) -> str:
    s = panels[0][0]
    origin = f"seed {s.seed}" if s.seed is not None else "given initial states"
    regimes = {a.regime: None for panel in panels for s_ in panel for a in s_.attractors}
    marks = ", ".join(f"{MARKER_GLYPHS[REGIME_MARKERS.get(r, '.')]} {r}" for r in sorted(regimes, key=_regime_order))
    return (f"{len(s.results)} initial states ({origin}), {s.measured} periods after {s.discard}; "
            f"'1' regular, '2' chaotic; {marks}")


def _regime_order(regime: str) -> int:
    return list(REGIME_MARKERS).index(regime) if regime in REGIME_MARKERS else len(REGIME_MARKERS)


# ------------------------------------------------------------------------------------ Fig. 7: phase portraits
@dataclass(frozen=True)
class PhasePanel:
    """One phase portrait in the plane x-y: the trajectory (gray line) and, in black, its own Poincare
    points (the states at t = kT within the trajectory's time window, so both show the same motion)."""

    trajectory: Trajectory
    title: str = ""
    x: str | None = None
    y: str | None = None

    @property
    def points(self) -> np.ndarray:
        return self.trajectory.strobe


def phase_panel(model, *, title: str | None = None, x: str | None = None, y: str | None = None,
                periods: int = 100, discard: int = 300, y0=None, title_parameters: Sequence[str] = ("omega",),
                **values) -> PhasePanel:
    """Compute one panel: ``periods`` periods of trajectory after ``discard`` transient ones from ``y0``.

    ``model`` is a compiled model (its scheme is used; ``values`` are parameter values). The default title
    lists ``title_parameters`` and every parameter given in ``values``, e.g. 'ω=1.5, k_S=0.1'.
    """
    trajectory = phase_trajectory(model, options=model.integration.run(discard + periods, discard), y0=y0, **values)
    if title is None:
        shown = dict.fromkeys([*title_parameters, *values])
        used = dict(zip(model.parameter_names, map(float, model.parameter_vector(values))))
        title = ", ".join(parameter_text(k, used[k]) for k in shown if k in used)
    return PhasePanel(trajectory, title, x, y)


def plot_phase_portraits(panels: Sequence[PhasePanel], path: str | Path | None = None, columns: int | None = None):
    """A grid of phase portraits, captioned (a), (b), ... in order, written to ``path`` (PNG) if given;
    returns the Figure."""
    plt = pyplot()
    panels = list(panels)
    if not panels or not all(isinstance(p, PhasePanel) for p in panels):
        raise GearsymError("plot_phase_portraits needs a list of PhasePanel (see phase_panel)")
    columns = columns or (2 if len(panels) > 1 else 1)
    rows = -(-len(panels) // columns)
    with plt.rc_context(_STYLE):
        fig, axes = plt.subplots(rows, columns, figsize=(4.3 * columns, 3.8 * rows), squeeze=False,
                                 constrained_layout=True)
        for k, ax in enumerate(axes.flat):
            if k >= len(panels):
                ax.set_visible(False)
                continue
            panel = panels[k]
            names = panel.trajectory.state_names
            x, y = phase_axes(names, panel.x, panel.y)
            for name in (x, y):
                if name not in names:
                    raise GearsymError(f"phase portrait ({chr(ord('a') + k)}): no state {name!r}; "
                                       f"the states are {', '.join(names)}")
            ix, iy = names.index(x), names.index(y)
            traj = panel.trajectory.states
            points = panel.points
            ax.plot(traj[ix], traj[iy], lw=0.4, color="0.6", rasterized=True, zorder=1)
            distinct = np.unique(np.round(points[[ix, iy]], 6), axis=1).shape[1]
            ax.plot(points[ix], points[iy], "o" if distinct <= 50 else ".", ms=3.5 if distinct <= 50 else 3.0,
                    color="k", mew=0, rasterized=True, zorder=2)  # a periodic orbit's few points must show
            ax.set_xlabel(x)
            ax.set_ylabel(y)
            ax.set_title(panel.title)
            ax.text(0.02, 0.97, f"({chr(ord('a') + k)})", transform=ax.transAxes, ha="left", va="top",
                    fontsize=11, fontweight="bold")
        fig.supxlabel(_window_caption(panels), fontsize=7, color="0.35")
        return finish(fig, path, dpi=150)


def _window_caption(panels: Sequence[PhasePanel]) -> str:
    windows = {(float(p.trajectory.time[0]), float(p.trajectory.time[-1]), p.points.shape[1] - 1) for p in panels}
    if len(windows) == 1:
        t0, t1, periods = windows.pop()
        return (f"gray: the trajectory over t = {t0:.4g} .. {t1:.4g} ({periods} forcing periods, every RK4 step); "
                "black: its Poincaré points (t = kT) in that window")
    return "gray: each panel's trajectory; black: its Poincaré points (t = kT) in the same window"
