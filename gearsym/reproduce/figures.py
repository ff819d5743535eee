"""The paper's figures (3, 4, 6, 7) redrawn from our runs, and the figures that go beyond them.

Panels follow the captions: curves labelled '1', '2', '3' as in the paper, the
same axes and the same grids. The paper's claimed regions are shaded grey
behind our curves, so that agreement can be seen, not only read. Every figure
says at its top which parameter set it shows (:data:`~gearsym.reproduce.plan.SCENARIOS`:
calibrated to the paper, or the models' defaults) with the values the paper leaves
open, and the values it does give.

Each ``figureN(c)`` returns a matplotlib Figure (tests read it); :func:`draw_all` writes them, and
:func:`draw_stability` the stability chart's.
"""
from __future__ import annotations

import textwrap
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..figures.basins import plot_basin_fractions, plot_basin_map, run_text
from ..figures.layout import fit_texts, outside_below
from ..figures.orbits import legend_handles, plot_branches, plot_sweep_points
from ..figures.poincare import PhasePanel, plot_attractors, plot_phase_portraits
from ..physical.text import parameter_text
from ..figures.save import pyplot, save_figure
from ..figures.stability import plot_stability
from ..figures.sweep import (add_colorbar, plot_amplitude, plot_bifurcation, plot_exponents, plot_map,
                             plot_regime_strip, ZERO_CONTOUR)
from ..stability.chart import StabilityChart
from .compute import Computed
from .plan import CHAOS_BAND, NEAR_ONE, NOT_IN_PAPER, PAPER_JUMPS
from .stability import MODEL as STABILITY_MODEL

CURVE_COLORS = ("C0", "C3", "C2")
DPI = 110
#: the phase-plane figures carry many points: a finer raster
FINE_DPI = 150


def parameter_set(c: Computed, runs: Mapping[str, Mapping[str, float]], varied=()) -> str:
    """Two lines for a figure's top: the parameter set with the values the paper leaves open, per model
    (``runs``: model -> its parameter values), and the values the paper gives, except those ``varied``
    along the figure's axes or between its curves."""
    open_values: dict[str, list[str]] = {}
    for model, values in runs.items():
        if open_text(values, varied):
            open_values.setdefault(open_text(values, varied), []).append(model)
    if len(open_values) <= 1:
        opened = "".join(open_values)
    else:
        opened = "; ".join(f"{' and '.join(models)}: {text}" for text, models in open_values.items())
    return f"parameter set: {c.plan.scenario.label}" + (f" ({opened})" if opened else "") + "\n" + paper_text(runs, varied)


def paper_text(runs: Mapping[str, Mapping[str, float]], varied=()) -> str:
    """"the paper's values: ζ=0.08, ...": those of ``runs`` the paper gives, except those ``varied``."""
    given: dict[str, float] = {}
    for values in runs.values():
        given.update({k: v for k, v in values.items() if k not in NOT_IN_PAPER and k not in varied})
    return f"the paper's values: {', '.join(parameter_text(k, v) for k, v in given.items())}"


def open_text(values: Mapping[str, float], varied=()) -> str:
    """'k_a=0.05, I1=2, ...': the values of what the paper leaves open (except those ``varied``)."""
    return ", ".join(parameter_text(k, values[k]) for k in NOT_IN_PAPER if k in values and k not in varied)


def _sweep_parameters(c: Computed, *names: str) -> dict[str, dict[str, float]]:
    return {c.sweeps[n].model: c.sweeps[n].record["parameters"] for n in names}


def _paper_chaos(ax) -> None:
    for lo, hi in (NEAR_ONE, CHAOS_BAND):
        ax.axvspan(lo, hi, color="0.88", lw=0, zorder=0)


def _letter(ax, letter: str) -> None:
    ax.text(0.01, 0.97, f"({letter})", transform=ax.transAxes, va="top", fontweight="bold")


def _legend_below(ax) -> None:
    """The curves' legend under the panel (in it, it would cover curves)."""
    handles, labels = ax.get_legend_handles_labels()
    outside_below(ax, handles=handles, labels=labels, columns=min(len(labels), 4) or 1, fontsize=8,
                  title="continuation up in ω", title_fontsize=8)


def _finish_omega(ax) -> None:
    ax.set_xlabel(r"$\omega$")
    ax.set_xlim(0.1, 2.0)


def figure3(c: Computed):
    plt = pyplot()
    d0, d2 = c.sweeps["fig3_D0"], c.sweeps["fig3_D2"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5.4), constrained_layout=True)
    for ax in (a, b):
        _paper_chaos(ax)
    for (r, label), color in zip(((d0, "'1'  D = 0"), (d2, "'2'  D = 2")), CURVE_COLORS):
        plot_amplitude(a, r, direction="up", label=label, color=color)
        plot_exponents(b, r, direction="up", label=label, color=color)
    for w in PAPER_JUMPS:
        a.axvline(w, color="0.4", ls=":", lw=0.9)
    a.text(PAPER_JUMPS[0], 0.6, " paper: jumps", transform=a.get_xaxis_transform(), fontsize=8, color="0.3")
    a.set_ylabel(r"$A$")
    for ax, letter in ((a, "a"), (b, "b")):
        _finish_omega(ax)
        _legend_below(ax)
        _letter(ax, letter)
    a.set_title("grey: the paper's chaotic regions for D = 0; dotted: the jumps it reports for D = 2", fontsize=8)
    b.set_title("grey: the paper's chaotic regions for D = 0", fontsize=8)
    fig.suptitle("Fig. 3: Eq. 2 (D = 0) and Eq. 6 (D = 2) — "
                 + parameter_set(c, _sweep_parameters(c, "fig3_D0", "fig3_D2"), ("omega", "D")), fontsize=8)
    return fig


def figure3_orbits(c: Computed):
    """Fig. 3a with the branches of periodic orbits: the sweeps' points (up and down) under the period-1 and
    period-2 branches, stable solid and unstable dashed, their bifurcations marked."""
    plt = pyplot()
    fig, axs = plt.subplots(1, 2, figsize=(13, 6.4), constrained_layout=True)
    for ax, (name, title), letter in zip(axs, (("fig3_D0", "'1'  D = 0 (Eq. 2)"), ("fig3_D2", "'2'  D = 2 (Eq. 6)")),
                                         "ab"):
        result = c.orbits[name]
        local = c.local.get(name, ())
        plot_sweep_points(ax, c.sweeps[name], "omega", result.observed[0])
        for other in local:  # the orbits of other periods a jump left, continued across it
            plot_branches(ax, other, label_values=False, legend=False)
        plot_branches(ax, result, label_values=False, legend=False)
        handles = legend_handles(result, c.sweeps[name], others=local)
        outside_below(ax, handles=handles, columns=2, fontsize=7)
        for w in PAPER_JUMPS if name == "fig3_D2" else ():
            ax.axvline(w, color="0.4", ls=":", lw=0.9)
        jumps = "; dotted: the paper's jumps" if name == "fig3_D2" else ""
        periods = sorted({b.period_multiple for r in local for b in r.branches} - {1, 2})
        landed = f"; period {', '.join(map(str, periods))}: the orbits a jump lands on" if periods else ""
        ax.set_title(f"{title}: periodic orbits over the continuation's points{landed}{jumps}", fontsize=9)
        ax.set_ylabel(r"$A$")
        _finish_omega(ax)
        _letter(ax, letter)
    fig.suptitle("Fig. 3a with its periodic branches (crossings located; the sweeps: the paper's scheme) — "
                 + parameter_set(c, _sweep_parameters(c, "fig3_D0", "fig3_D2"), ("omega", "D")), fontsize=8)
    return fig


def figure6(c: Computed):
    plt = pyplot()
    r = c.sweeps["fig6"]
    fig, axs = plt.subplots(2, 2, figsize=(12, 9.6), constrained_layout=True)
    (a, b), (cc, d) = axs
    for ax in (a, b):
        _paper_chaos(ax)
    for i, (ks, color) in enumerate(zip((0.0, 0.1, 1.0), CURVE_COLORS), start=1):
        label = f"'{i}'  kS = {ks:g}"
        plot_amplitude(a, r, "x1", direction="up", label=label, color=color, kS=ks)
        plot_exponents(b, r, direction="up", label=label, color=color, kS=ks)
    for ax, ks in ((cc, 0.1), (d, 1.0)):
        plot_exponents(ax, r, which=range(1, 5), direction="up", kS=ks)
        ax.set_title(f"kS = {ks:g}: the four exponents", fontsize=9)
    for ax in (a, b):
        ax.set_title("grey: the paper's chaotic regions for the gear pair (D = 0)", fontsize=8)
    a.set_ylabel(r"$A$ ($x_1$)")
    _clip_peak(a, r["omega"], r["A_x1"])
    for ax, letter in zip((a, b, cc, d), "abcd"):
        _finish_omega(ax)
        _legend_below(ax)
        _letter(ax, letter)
    for ax, ks in ((cc, 0.1), (d, 1.0)):
        _zoom_near_zero(ax, r, kS=ks)
    fig.suptitle("Fig. 6: Eq. 9, the flexible shaft — " + parameter_set(c, _sweep_parameters(c, "fig6"),
                                                                        ("omega", "kS")), fontsize=8)
    return fig


def _zoom_near_zero(ax, r, **fixed) -> None:
    """An inset on lambda_1 and lambda_2 near zero, where the main panel's scale (set by the most negative
    exponents) draws them on top of each other: it shows whether lambda_2 is above zero too (hyperchaos)."""
    inset = ax.inset_axes([0.36, 0.07, 0.62, 0.42])
    plot_exponents(inset, r, which=(1, 2), direction="up", **fixed)
    line = next(idx for d, values, idx in r.lines()
                if d == "up" and all(np.isclose(values[k], v) for k, v in fixed.items()))
    second = r["lambda_2"][line]
    half = max(2.5 * float(np.max(np.abs(second[r["omega"][line] >= 0.5]), initial=0.0)), 0.01)
    inset.set_ylim(-half, half)
    inset.set_xlim(0.1, 2.0)
    inset.set_ylabel("")
    inset.tick_params(labelsize=7)
    inset.set_title(r"zoom near zero: $\lambda_1$, $\lambda_2$", fontsize=7, pad=2)
    inset.set_facecolor("white")


def _clip_peak(ax, x: np.ndarray, y: np.ndarray) -> None:
    """A lone resonance peak far above the rest would flatten every curve: cut it and say so."""
    typical = float(np.percentile(y, 98))
    top = float(np.max(y))
    if top > 3 * typical:
        ax.set_ylim(0, 1.6 * typical)
        at = float(x[int(np.argmax(y))])
        ax.annotate(f"peak A = {top:.0f} at ω = {at:g} (off scale)", xy=(at, 1.6 * typical), xytext=(at + 0.1, 1.45 * typical),
                    fontsize=8, arrowprops={"arrowstyle": "->", "lw": 0.8})


def figure4(c: Computed):
    panels = [[c.attractors[("one_stage", omega)], c.attractors[("one_stage_resonant", omega)]] for omega in (1.5, 1.6)]
    fig = plot_attractors(panels, colors=["0.6", "k"], labels=["D = 0 (Eq. 2)", "D = 2 (Eq. 6)"])
    runs = {s.model: s.parameters for panel in panels for s in panel}
    fig.suptitle("Fig. 4: coexisting attractors — "
                 + parameter_set(c, runs, ("omega", "D")), fontsize=8)
    return fig


def figure7(c: Computed):
    panels = [PhasePanel(p.trajectory, _portrait_title(p), p.x, p.y) for p in c.portraits]
    fig = plot_phase_portraits(panels)
    runs = {c.plan.portrait_model: c.portraits[0].spectrum.parameters} if c.portraits else {}
    fig.suptitle(f"Fig. 7: ω = {c.plan.portrait_omega:g}, from the paper's initial state — "
                 + parameter_set(c, runs, ("omega", "kS")), fontsize=8)
    return fig


def _portrait_title(p) -> str:
    """'$k_S$ = 0: chaotic, λ₁ = +0.055': the setting, and the regime and λ₁ of the run drawn."""
    lam = p.spectrum.exponents[0]
    return f"$k_S$ = {p.settings['kS']:g}: {p.spectrum.regime}, λ₁ = {lam:+.4f}"


def hysteresis(c: Computed):
    """Beyond the paper: up and down runs, and the bifurcation diagrams, of both one-stage models."""
    plt = pyplot()
    fig, axs = plt.subplots(3, 2, figsize=(12, 9.5), sharex=True, constrained_layout=True,
                            gridspec_kw={"height_ratios": [3, 3, 1]})
    for col, (name, title) in enumerate((("fig3_D0", "D = 0 (Eq. 2)"), ("fig3_D2", "D = 2 (Eq. 6)"))):
        r = c.sweeps[name]
        plot_amplitude(axs[0, col], r, label=None)
        axs[0, col].set_title(f"{title}: up (solid) and down (dashed)", fontsize=9)
        axs[0, col].legend(fontsize=8)
        plot_bifurcation(axs[1, col], r, direction="up")
        axs[1, col].set_title("bifurcation diagram: x at t = kT, the up run", fontsize=9)
        plot_regime_strip(axs[2, col], r)
        _finish_omega(axs[2, col])
    fig.suptitle("Hysteresis: continuation up, then down in ω — "
                 + parameter_set(c, _sweep_parameters(c, "fig3_D0", "fig3_D2"), ("omega", "D")), fontsize=8)
    return fig


def study(c: Computed):
    """Beyond the paper: lambda_1 and the regime over omega and a parameter the paper leaves open."""
    plt = pyplot()
    names = ("study_kS", "study_ka", "study_inertia")
    fig, axs = plt.subplots(len(names), 2, figsize=(13, 11), constrained_layout=True)
    for row, name in enumerate(names):
        r = c.sweeps[name]
        mesh = plot_map(axs[row, 0], r, "lambda_1", direction="up")
        add_colorbar(fig, axs[row, 0], mesh, r"$\lambda_1$")
        mesh = plot_map(axs[row, 1], r, "regime", direction="up")
        add_colorbar(fig, axs[row, 1], mesh, "regime", short={"quasi-periodic": "quasi-per."})
        job = c.plan.sweep(name)
        fixed = open_text(r.record["parameters"], [a.name for a in r.axes])
        axs[row, 0].set_title(f"{job.model}: {job.title}" + (f"; {fixed}" if fixed else ""), fontsize=8, loc="left")
        for ax in axs[row]:
            for lo, hi in (NEAR_ONE, CHAOS_BAND):
                ax.axvline(lo, color="k", ls=":", lw=0.7)
                ax.axvline(hi, color="k", ls=":", lw=0.7)
    swept = {a.name for n in names for a in c.sweeps[n].axes} | {"kS"}
    fig.suptitle(f"Parameter study, continuation up in ω — parameter set: {c.plan.scenario.label} (the values each "
                 f"row keeps fixed are in its title); left: λ₁ ({ZERO_CONTOUR}), right: the regime; dotted: the "
                 f"paper's chaotic bands for D = 0\n{paper_text(_sweep_parameters(c, *names), swept)}", fontsize=8)
    return fig


MODEL_NAMES = {"one_stage": "D = 0 (Eq. 2)", "one_stage_resonant": "D = 2 (Eq. 6)"}


def basin_maps(c: Computed):
    """Fig. 4 seen as basins: which attractor every start of the box of Fig. 4's random starts reaches."""
    plt = pyplot()
    omegas = sorted({w for _, w in c.basins})
    models = list(dict.fromkeys(m for m, _ in c.basins))
    fig, axs = plt.subplots(len(omegas), len(models), figsize=(6.2 * len(models), 6.4 * len(omegas)), squeeze=False,
                            constrained_layout=True)
    for i, omega in enumerate(omegas):
        for j, model in enumerate(models):
            m = c.basins[(model, omega)]
            plot_basin_map(m, ax=axs[i, j])
            axs[i, j].set_title(f"({chr(ord('a') + i * len(models) + j)}) {MODEL_NAMES.get(model, model)}, "
                                f"ω = {omega:g}: {m.labels.shape[1]} x {m.labels.shape[0]} starts", fontsize=9)
    first = next(iter(c.basins.values()))
    runs = {m.model: m.parameters for m in c.basins.values()}
    fig.suptitle("Fig. 4 as basins of attraction (colour: the attractor a start reaches; markers: its Poincaré "
                 "points) — " + parameter_set(c, runs, ("omega", "D")) + "\n" + run_text(first), fontsize=8)
    return fig


def basin_fractions(c: Computed):
    """The basin fractions along omega across the paper's jumps of Fig. 3 (D = 2)."""
    model, r = next(iter(c.fractions.items()))
    fig = plot_basin_fractions(r)
    for ax in fig.axes[:2]:
        for w in PAPER_JUMPS:
            ax.axvline(w, color="0.3", ls="--", lw=0.9)
    fig.axes[0].text(PAPER_JUMPS[0], 0.5, " the paper's jumps (dashed)", fontsize=7, color="0.3",
                     transform=fig.axes[0].get_xaxis_transform())
    grid = r.record["grid"]
    values = next((m.parameters for (name, _), m in c.basins.items() if name == model), r.record["settings"])
    fig.suptitle(textwrap.fill(f"The jumps of Fig. 3a as basins: {MODEL_NAMES.get(model, model)}, the fraction of "
                               f"the starts of a {len(grid['x'])} x {len(grid['v'])} grid over [-5, 5]² that reach "
                               "each attractor (by its id, followed from one ω to the next by its Poincaré set); "
                               f"{r.record['periods']} periods per start, {r.record['discard']} discarded, plain RK4 "
                               "(the paper's scheme)", 150)
                 + "\n" + parameter_set(c, {model: values}, ("omega", "D")), fontsize=8)
    return fig


#: the figures of one scenario: file stem -> (builder, dpi)
FIGURES = {"fig3": (figure3, DPI), "fig3-orbits": (figure3_orbits, DPI), "fig4": (figure4, FINE_DPI),
           "fig6": (figure6, DPI), "fig7": (figure7, FINE_DPI), "hysteresis": (hysteresis, DPI), "study": (study, DPI),
           "basins": (basin_maps, DPI), "basin-fractions": (basin_fractions, DPI)}


def build(name: str, c: Computed):
    """The figure ``name`` of :data:`FIGURES`, its titles wrapped to fit, as it is written."""
    return fit_texts(FIGURES[name][0](c))


def draw_all(c: Computed, out: str | Path, suffix: str = "") -> list[Path]:
    """Every figure of one computed plan; ``suffix`` tells the file names of another scenario apart."""
    out = Path(out)
    names = [n for n in FIGURES if (n != "study" or "study_ka" in c.sweeps) and (n != "fig3-orbits" or c.orbits)
             and (n != "basins" or c.basins) and (n != "basin-fractions" or c.fractions)]
    # (fitted as they are written, at their resolution: build's fit at the screen's would be laid out again)
    return [save_figure(FIGURES[n][0](c), out / f"{n}{suffix}.png", FIGURES[n][1], keep_same=True) for n in names]


def draw_stability(chart: StabilityChart, out: str | Path) -> Path:
    """The stability chart of the paper's model (:mod:`.stability`), kept if the picture is the same (keep_same),
    as the paper's figures are: another CPU's or matplotlib's rounding moves a pixel or two, and the main job must
    leave the committed figure as it is."""
    return save_figure(plot_stability(chart, title=f"{STABILITY_MODEL} at the paper's values (Eq. 2)"),
                       Path(out) / "stability.png", dpi=110, keep_same=True)
