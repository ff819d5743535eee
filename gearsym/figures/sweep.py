"""Pictures of a sweep: amplitude, exponents, regimes and the bifurcation diagram along the first
parameter; maps of lambda_1 and the regime over two parameters.

The panel functions draw on a given matplotlib ``Axes`` so that the paper's
figures (:mod:`gearsym.reproduce`) compose them; :func:`plot_sweep` is the
one-call overview behind ``gearsym sweep --plot``.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap, TwoSlopeNorm  # noqa: E402

from ..analysis.regime import REGIMES  # noqa: E402
from ..sweep.result import SweepResult  # noqa: E402
from .save import save_figure  # noqa: E402

REGIME_COLORS = {"periodic": "#4c72b0", "quasi-periodic": "#55a868", "chaotic": "#dd8452",
                 "hyperchaotic": "#c44e52", "equilibrium": "#8172b3"}
_LINESTYLE = {"up": "-", "down": "--", "independent": "-"}


def _axis_label(name: str) -> str:
    return {"omega": r"$\omega$", "kS": r"$k_S$", "zeta": r"$\zeta$", "k_a": r"$k_a$"}.get(name, name)


def _runs(result: SweepResult, direction: str | None = None, **fixed):
    for d, values, idx in result.lines():
        if (direction is None or d == direction) and all(np.isclose(values.get(k, np.nan), v) for k, v in fixed.items()):
            yield d, values, idx


def plot_amplitude(ax, result: SweepResult, coordinate: str | None = None, *, direction: str | None = None,
                   label: str | None = None, color=None, **fixed) -> None:
    """A of ``coordinate`` against the first parameter, one curve per run."""
    coordinate = coordinate or result.coordinates[0]
    x = result.axes[0].name
    for d, values, idx in _runs(result, direction, **fixed):
        ax.plot(result[x][idx], result[f"A_{coordinate}"][idx], _LINESTYLE.get(d, "-"), lw=1.1, color=color,
                label=label if label is not None else _run_label(d, values))
    ax.set_ylabel(f"$A$ ({coordinate})")


def plot_exponents(ax, result: SweepResult, which=(1,), *, direction: str | None = None, label: str | None = None,
                   color=None, errors: bool = False, **fixed) -> None:
    """lambda_i against the first parameter (``which``: the exponent numbers), with a zero line."""
    x = result.axes[0].name
    for d, values, idx in _runs(result, direction, **fixed):
        for i in which:
            lam = result[f"lambda_{i}"][idx]
            line, = ax.plot(result[x][idx], lam, _LINESTYLE.get(d, "-"), lw=1.0, color=color or f"C{i - 1}",
                            label=label if label is not None else rf"$\lambda_{i}$")
            if errors:
                err = result[f"stderr_{i}"][idx]
                ax.fill_between(result[x][idx], lam - 3 * err, lam + 3 * err, color=line.get_color(), alpha=0.2, lw=0)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel(r"$\lambda_1$" if tuple(which) == (1,) else r"$\lambda_i$")


def plot_bifurcation(ax, result: SweepResult, state: str | None = None, *, direction: str | None = None,
                     color="k", **fixed) -> None:
    """The stroboscopic samples of ``state`` against the first parameter: one dot per sample."""
    state = state or result.coordinates[0]
    x = result.axes[0].name
    s = result.strobe
    if not s or state not in s:
        ax.text(0.5, 0.5, "no Poincaré samples in this sweep", transform=ax.transAxes, ha="center")
        return
    keep = np.ones(len(s[x]), dtype=bool)
    if direction is not None:
        keep &= s["direction"] == direction
    for k, v in fixed.items():
        keep &= np.isclose(s[k], v)
    ax.plot(s[x][keep], s[state][keep], ".", ms=1.0, mew=0, color=color, alpha=0.7)
    ax.set_ylabel(f"{state} at t = kT")


def plot_regime_strip(ax, result: SweepResult, *, direction: str | None = None, **fixed) -> None:
    """One coloured bar per point: the regime along the first parameter (one row per run)."""
    x = result.axes[0].name
    runs = list(_runs(result, direction, **fixed))
    for row, (d, values, idx) in enumerate(runs):
        xs = result[x][idx]
        width = np.min(np.diff(np.sort(xs))) if len(xs) > 1 else 1.0
        for xv, reg in zip(xs, result["regime"][idx]):
            ax.broken_barh([(xv - width / 2, width)], (row, 0.8), color=REGIME_COLORS.get(reg, "0.5"), lw=0)
    ax.set_yticks([r + 0.4 for r in range(len(runs))], [_run_label(d, v) for d, v, _ in runs], fontsize=7)
    ax.set_ylim(0, max(len(runs), 1))
    handles = [plt.Rectangle((0, 0), 1, 1, color=REGIME_COLORS[r]) for r in REGIMES]
    ax.legend(handles, REGIMES, ncol=4, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.45), frameon=False)


def plot_map(ax, result: SweepResult, column: str = "lambda_1", *, direction: str | None = None):
    """``column`` over the first two parameters (lambda_1: diverging colours, zero white, and its zero contour)."""
    x, y = result.axes[0].name, result.axes[1].name
    xs, ys = np.array(result.axes[0].values), np.array(result.axes[1].values)
    grid = np.full((len(ys), len(xs)), np.nan)
    keep = np.ones(len(result), dtype=bool) if direction is None else result["direction"] == direction
    ix = np.searchsorted(xs, result[x][keep])
    iy = np.searchsorted(ys, result[y][keep])
    if column == "regime":
        codes = {r: i for i, r in enumerate(REGIMES)}
        grid[iy, ix] = [codes.get(r, np.nan) for r in result["regime"][keep]]
        cmap = ListedColormap([REGIME_COLORS[r] for r in REGIMES])
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap=cmap, norm=BoundaryNorm(np.arange(-0.5, 4), 4))
    elif column.startswith("lambda_"):
        grid[iy, ix] = result[column][keep]
        finite = np.abs(grid[np.isfinite(grid)])
        span = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap="RdBu_r", norm=TwoSlopeNorm(0.0, -span, span))
        if len(xs) > 1 and len(ys) > 1:
            ax.contour(xs, ys, grid, levels=[0.0], colors="k", linewidths=0.6)
    else:
        grid[iy, ix] = result[column][keep]
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap="viridis")
    if _geometric(ys):
        ax.set_yscale("log")
        ax.set_yticks(ys, [f"{v:g}" for v in ys])
        ax.minorticks_off()
    ax.set_xlabel(_axis_label(x))
    ax.set_ylabel(_axis_label(y))
    return mesh


def _edges(v: np.ndarray) -> np.ndarray:
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    if _geometric(v):  # 0.5, 1, 2, 4, 8: cells of equal width on a log axis
        return np.exp(_edges(np.log(v)))
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _geometric(v: np.ndarray) -> bool:
    return len(v) >= 3 and bool(np.all(v > 0)) and bool(np.allclose(np.diff(np.log(v)), np.log(v[1] / v[0])))


def _run_label(direction: str, values: dict) -> str:
    fixed = ", ".join(f"{k}={v:g}" for k, v in values.items())
    return ", ".join(p for p in (direction if direction != "independent" else "", fixed) if p) or "sweep"


def plot_sweep(result: SweepResult, path: str | Path) -> Path:
    """Overview PNG: for one swept parameter A, lambda_i, bifurcation diagram and regimes against it;
    for two, maps of lambda_1, the regime and A over both."""
    title = f"{result.model}: " + ", ".join(f"{a.name} {a.values[0]:g}..{a.values[-1]:g}" for a in result.axes)
    if len(result.axes) >= 2:
        fig, axs = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
        direction = None if result.mode == "independent" else ("down" if result.record.get("direction") == "down" else "up")
        for ax, column, label in zip(axs, ("lambda_1", "regime", f"A_{result.coordinates[0]}"),
                                     (r"$\lambda_1$", "regime", f"A ({result.coordinates[0]})")):
            mesh = plot_map(ax, result, column, direction=direction)
            if column != "regime":
                fig.colorbar(mesh, ax=ax, label=label)
            else:
                cbar = fig.colorbar(mesh, ax=ax, ticks=range(4))
                cbar.ax.set_yticklabels(REGIMES, fontsize=7)
        axs[1].set_title(title + (f" ({direction})" if direction else ""), fontsize=9)
    else:
        fig, axs = plt.subplots(4, 1, figsize=(8, 9.5), sharex=True, constrained_layout=True,
                                gridspec_kw={"height_ratios": [3, 3, 3, 1]})
        plot_amplitude(axs[0], result)
        plot_exponents(axs[1], result, which=range(1, result.exponent_count + 1), direction=None)
        plot_bifurcation(axs[2], result)
        plot_regime_strip(axs[3], result)
        axs[0].legend(fontsize=7)
        handles, labels = axs[1].get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        axs[1].legend(unique.values(), unique.keys(), fontsize=7, ncol=4)
        axs[3].set_xlabel(_axis_label(result.axes[0].name))
        axs[0].set_title(title, fontsize=9)
    return save_figure(fig, path, dpi=120)
