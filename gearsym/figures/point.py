"""One parameter point at a glance: how the exponents converged, and the attractor.

Left: the running estimate of every Lyapunov exponent over the measured
periods, with the final value and its standard error. Right: the phase
portrait of a coordinate against the state after it (the last periods, every RK4
step) with the stroboscopic Poincare points of every measured period on top.
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..analysis.lyapunov import LyapunovSpectrum
from ..analysis.poincare import Trajectory
from .layout import line_style, outside_below
from .phase_plane import phase_axes
from .save import finish, pyplot


def plot_point(spectrum: LyapunovSpectrum, trajectory: Trajectory, path: str | Path | None = None,
               x: str | None = None, y: str | None = None, *, units: Mapping[str, str] | None = None,
               title: str | None = None):
    """The two-panel figure, written to ``path`` (PNG) if given; returns the matplotlib Figure.
    ``x``/``y`` choose the phase-plane axes (default the first state, and the state after ``x``). For a run in
    physical units (``gearsym.physical``: exponents, their history and the states converted) ``units`` gives
    the unit of each state and of the ``"exponents"``, ``title`` the figure's title."""
    plt = pyplot()
    names = list(trajectory.state_names)
    x, y = phase_axes(names, x, y)
    fig, (ax_l, ax_p) = plt.subplots(1, 2, figsize=(11, 4.8), constrained_layout=True)

    periods = np.arange(spectrum.discard + 1, spectrum.periods + 1)
    units = units or {}
    per = units.get("exponents")
    count = len(spectrum.exponents)
    known = getattr(spectrum, "resolution", None)
    for i, (lam, err) in enumerate(zip(spectrum.exponents, spectrum.stderr)):
        name = rf"$\lambda_{{{i + 1}}}$"  # (braced: lambda_10 is "λ₁₀", not "λ₁0")
        text = (f"{name}: not resolved ({known.reasons[i]})" if known is not None and not known.resolved[i] else
                rf"{name} = {lam:+.5g} ± {err:.3g} {per}" if per else rf"{name} = {lam:+.4f} ± {err:.4f}")
        line, = ax_l.plot(periods, spectrum.history[:, i], lw=1.2, **line_style(i, count, len(periods)), label=text)
        ax_l.axhspan(lam - err, lam + err, color=line.get_color(), alpha=0.15, lw=0)
    ax_l.axhline(0, color="k", lw=0.6)
    ax_l.set_xlabel("forcing periods")
    ax_l.set_ylabel(f"running estimate of $\\lambda_i$ [{per}]" if per else
                    "running estimate of $\\lambda_i$ (per unit time)")
    ax_l.set_title("Lyapunov exponents: convergence")
    outside_below(ax_l, columns=2 if count <= 4 else 3, fontsize=8)

    ix, iy = names.index(x), names.index(y)
    shown = round((trajectory.time[-1] - trajectory.time[0]) / spectrum.period)
    ax_p.plot(trajectory.states[ix], trajectory.states[iy], lw=0.5, color="0.55",
              label=f"trajectory: the last {shown} periods")
    strobe = spectrum.strobe
    ax_p.plot(strobe[ix], strobe[iy], ".", ms=4, color="C3",
              label=f"Poincaré points: all {strobe.shape[1]} measured periods")
    ax_p.set_xlabel(f"{x} [{units[x]}]" if x in units else x)
    ax_p.set_ylabel(f"{y} [{units[y]}]" if y in units else y)
    ax_p.set_title("phase portrait and stroboscopic section")
    outside_below(ax_p, fontsize=8)  # (outside: a legend in the axes would cover Poincare points)

    if title is None:
        values = ", ".join(f"{k}={v:g}" for k, v in spectrum.parameters.items())
        title = f"{spectrum.model}: {values}\n{spectrum.regime}, λ₁ = {spectrum.exponents[0]:+.4f}"
    fig.suptitle(title, fontsize=9)
    return finish(fig, path, dpi=120)
