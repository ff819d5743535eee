"""The paper's figures (3, 4, 6, 7) redrawn from our runs, and the figures that go beyond them.

Panels follow the captions: curves labelled '1', '2', '3' as in the paper, the
same axes and the same grids. The paper's claimed regions are shaded grey
behind our curves, so that agreement can be seen, not only read.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..figures.save import save_figure  # noqa: E402
from ..figures.sweep import plot_amplitude, plot_bifurcation, plot_exponents, plot_map, plot_regime_strip  # noqa: E402
from .compute import Computed  # noqa: E402
from .plan import CHAOS_BAND, NEAR_ONE, PAPER_JUMPS  # noqa: E402

CURVE_COLORS = ("C0", "C3", "C2")
DPI = 110




def _paper_chaos(ax) -> None:
    for lo, hi in (NEAR_ONE, CHAOS_BAND):
        ax.axvspan(lo, hi, color="0.88", lw=0, zorder=0)


def _letter(ax, letter: str) -> None:
    ax.text(0.01, 0.97, f"({letter})", transform=ax.transAxes, va="top", fontweight="bold")


def _finish_omega(ax) -> None:
    ax.set_xlabel(r"$\omega$")
    ax.set_xlim(0.1, 2.0)


def figure3(c: Computed, out: Path, suffix: str = "") -> Path:
    d0, d2 = c.sweeps["fig3_D0"], c.sweeps["fig3_D2"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.3), constrained_layout=True)
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
        ax.legend(fontsize=8, loc="upper right")
        _letter(ax, letter)
    b.set_title("grey: the paper's chaotic regions for D = 0", fontsize=8)
    return save_figure(fig, out / f"fig3{suffix}.png", DPI)


def figure6(c: Computed, out: Path, suffix: str = "") -> Path:
    r = c.sweeps["fig6"]
    fig, axs = plt.subplots(2, 2, figsize=(12, 8), constrained_layout=True)
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
    a.set_ylabel(r"$A$ ($x_1$)")
    _clip_peak(a, r["omega"], r["A_x1"])
    for ax, letter in zip((a, b, cc, d), "abcd"):
        _finish_omega(ax)
        ax.legend(fontsize=8, loc="upper right")
        _letter(ax, letter)
    return save_figure(fig, out / f"fig6{suffix}.png", DPI)


def _clip_peak(ax, x: np.ndarray, y: np.ndarray) -> None:
    """A lone resonance peak far above the rest would flatten every curve: cut it and say so."""
    typical = float(np.percentile(y, 98))
    top = float(np.max(y))
    if top > 3 * typical:
        ax.set_ylim(0, 1.6 * typical)
        at = float(x[int(np.argmax(y))])
        ax.annotate(f"peak A = {top:.0f} at ω = {at:g} (off scale)", xy=(at, 1.6 * typical), xytext=(at + 0.1, 1.45 * typical),
                    fontsize=8, arrowprops={"arrowstyle": "->", "lw": 0.8})


def figure4(c: Computed, out: Path, suffix: str = "") -> Path:
    from ..figures.poincare import plot_attractors

    panels = [[c.attractors[("one_stage", omega)], c.attractors[("one_stage_resonant", omega)]] for omega in (1.5, 1.6)]
    return plot_attractors(panels, out / f"fig4{suffix}.png", colors=["0.6", "k"], labels=["D = 0 (Eq. 2)", "D = 2 (Eq. 6)"])


def figure7(c: Computed, out: Path, suffix: str = "") -> Path:
    from ..figures.poincare import PhasePanel, plot_phase_portraits

    panels = [PhasePanel(p.trajectory, p.spectrum.strobe, f"ω = {p.settings['omega']:g}, $k_S$ = {p.settings['kS']:g}",
                         p.x, p.y) for p in c.portraits]
    return plot_phase_portraits(panels, out / f"fig7{suffix}.png")


def hysteresis(c: Computed, out: Path, suffix: str = "") -> Path:
    """Beyond the paper: up and down runs, and the bifurcation diagrams, of both one-stage models."""
    fig, axs = plt.subplots(3, 2, figsize=(12, 9), sharex=True, constrained_layout=True,
                            gridspec_kw={"height_ratios": [3, 3, 1]})
    for col, (name, title) in enumerate((("fig3_D0", "D = 0 (Eq. 2)"), ("fig3_D2", "D = 2 (Eq. 6)"))):
        r = c.sweeps[name]
        plot_amplitude(axs[0, col], r, label=None)
        axs[0, col].set_title(f"{title}: up (solid) and down (dashed)", fontsize=9)
        axs[0, col].legend(fontsize=8)
        plot_bifurcation(axs[1, col], r, direction="up")
        axs[1, col].set_title("bifurcation diagram: x at t = kT (up)", fontsize=9)
        plot_regime_strip(axs[2, col], r)
        _finish_omega(axs[2, col])
    return save_figure(fig, out / f"hysteresis{suffix}.png", DPI)


def study(c: Computed, out: Path, suffix: str = "") -> Path:
    """Beyond the paper: lambda_1 and the regime over omega and a parameter the paper leaves open."""
    names = ("study_kS", "study_ka", "study_inertia")
    fig, axs = plt.subplots(len(names), 2, figsize=(13, 10.5), constrained_layout=True)
    for row, name in enumerate(names):
        r = c.sweeps[name]
        mesh = plot_map(axs[row, 0], r, "lambda_1", direction="up")
        fig.colorbar(mesh, ax=axs[row, 0], label=r"$\lambda_1$")
        mesh = plot_map(axs[row, 1], r, "regime", direction="up")
        bar = fig.colorbar(mesh, ax=axs[row, 1], ticks=range(4))
        bar.ax.set_yticklabels(["periodic", "quasi-per.", "chaotic", "hyperchaotic"], fontsize=7)
        job = c.plan.sweep(name)
        axs[row, 0].set_title(f"{job.model}: {job.title}", fontsize=8)
        for ax in axs[row]:
            for lo, hi in (NEAR_ONE, CHAOS_BAND):
                ax.axvline(lo, color="k", ls=":", lw=0.7)
                ax.axvline(hi, color="k", ls=":", lw=0.7)
    return save_figure(fig, out / f"study{suffix}.png", DPI)


def draw_all(c: Computed, out: str | Path, suffix: str = "") -> list[Path]:
    """Every figure of one computed plan; ``suffix`` tells the file names of another scenario apart."""
    out = Path(out)
    drawn = [figure3(c, out, suffix), figure4(c, out, suffix), figure6(c, out, suffix), figure7(c, out, suffix),
             hysteresis(c, out, suffix)]
    return drawn + ([study(c, out, suffix)] if "study_ka" in c.sweeps else [])
