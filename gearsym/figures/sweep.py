"""Pictures of a sweep: amplitude, exponents, regimes and the bifurcation diagram along the first
parameter; maps of lambda_1 and the regime over two parameters.

The panel functions draw on a given matplotlib ``Axes`` so that the paper's
figures (:mod:`gearsym.reproduce`) compose them; :func:`plot_sweep` is the
one-call overview behind ``gearsym sweep --plot``.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from ..analysis.regime import DIVERGED, REGIMES, UNDETERMINED
from ..errors import GearsymError
from ..sweep.result import SweepResult
from .layout import line_style
from .save import finish, pyplot

REGIME_COLORS = {"periodic": "#4c72b0", "quasi-periodic": "#55a868", "chaotic": "#dd8452",
                 "hyperchaotic": "#c44e52", "equilibrium": "#8172b3", UNDETERMINED: "#b0b0b0", DIVERGED: "#222222"}
#: what a regime strip or map can show: the regimes, and the two verdicts that are not (shown where they occur)
SHOWN = (*REGIMES, UNDETERMINED, DIVERGED)
#: a regime without a colour of its own (a verdict added later)
OTHER_REGIME_COLOR = "0.65"
_LINESTYLE = {"up": "-", "down": "--", "independent": "-"}
_STYLE_NAME = {"-": "solid", "--": "dashed"}
#: the bifurcation diagram's dots (points): a period-1 orbit is one dot per parameter value, and must show
BIFURCATION_DOT = 2.4
_CONTINUATION = {"up": "continuation upward", "down": "continuation downward", "both": "continuation up, then down"}


def _axis_label(name: str, units: dict | None = None) -> str:
    label = {"omega": r"$\omega$", "kS": r"$k_S$", "zeta": r"$\zeta$", "k_a": r"$k_a$"}.get(name, name)
    return _with_unit(label, units, name)


def _with_unit(label: str, units: dict | None, column: str) -> str:
    """``label [unit]`` for a sweep carried to physical units (``SweepResult.units``)."""
    unit = (units or {}).get(column)
    return f"{label} [{unit}]" if unit else label


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
    ax.set_ylabel(_with_unit(f"$A$ ({coordinate})", result.units, f"A_{coordinate}"))


def plot_exponents(ax, result: SweepResult, which=(1,), *, direction: str | None = None, label: str | None = None,
                   color=None, errors: bool = False, **fixed) -> None:
    """lambda_i against the first parameter (``which``: the exponent numbers), with a zero line."""
    x = result.axes[0].name
    which = list(which)
    for d, values, idx in _runs(result, direction, **fixed):
        for k, i in enumerate(which):
            lam = result[f"lambda_{i}"][idx]
            style = line_style(k, len(which), len(idx)) if color is None else {"color": color}
            line, = ax.plot(result[x][idx], lam, _LINESTYLE.get(d, "-"), lw=1.0, **style,
                            label=label if label is not None else rf"$\lambda_{i}$")
            if errors:
                err = result[f"stderr_{i}"][idx]
                ax.fill_between(result[x][idx], lam - 3 * err, lam + 3 * err, color=line.get_color(), alpha=0.2, lw=0)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel(_with_unit(r"$\lambda_1$" if tuple(which) == (1,) else r"$\lambda_i$", result.units, "lambda_1"))


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
    ax.plot(s[x][keep], s[state][keep], ".", ms=BIFURCATION_DOT, mew=0, color=color, alpha=0.6, rasterized=True)
    ax.set_ylabel(_with_unit(f"{state} at t = kT", result.units, state))


def regimes_shown(regimes) -> list[str]:
    """The regimes among ``regimes``, in the order of :data:`REGIMES` (any other, e.g. a verdict added
    later, after them in the order met)."""
    present = dict.fromkeys(str(r) for r in regimes)
    return [r for r in REGIMES if r in present] + [r for r in present if r not in REGIMES]


def regime_color(regime: str) -> str:
    return REGIME_COLORS.get(regime, OTHER_REGIME_COLOR)


def plot_regime_strip(ax, result: SweepResult, *, direction: str | None = None, **fixed) -> None:
    """One coloured bar per point: the regime along the first parameter (one row per run), and a legend of
    the regimes drawn."""
    plt = pyplot()
    x = result.axes[0].name
    runs = list(_runs(result, direction, **fixed))
    for row, (d, values, idx) in enumerate(runs):
        xs = result[x][idx]
        width = np.min(np.diff(np.sort(xs))) if len(xs) > 1 else 1.0
        if len(xs):  # (one collection a row, its bars drawn in the order of its points, as one bar each would be)
            ax.broken_barh([(xv - width / 2, width) for xv in xs], (row, 0.8),
                           color=[regime_color(reg) for reg in result["regime"][idx]], lw=0)
    ax.set_yticks([r + 0.4 for r in range(len(runs))], [_run_label(d, v, style=False) for d, v, _ in runs], fontsize=7)
    ax.set_ylim(0, max(len(runs), 1))
    shown = regimes_shown(r for _, _, idx in runs for r in result["regime"][idx])
    handles = [plt.Rectangle((0, 0), 1, 1, color=regime_color(r)) for r in shown]
    ax.legend(handles, shown, ncol=min(len(shown), 5) or 1, fontsize=7, loc="upper center",
              bbox_to_anchor=(0.5, -0.45), frameon=False)


def plot_map(ax, result: SweepResult, column: str = "lambda_1", *, direction: str | None = None):
    """``column`` over the first two parameters. lambda_1: diverging colours, zero white, each sign over its
    own range (the 2nd and 98th percentiles: one outlier does not wash out the rest; beyond them the colour
    bar's ends), and its zero contour, which the title names. Another column: viridis, on a log scale where
    it spans more than two decades. The regime: a colour per regime drawn (the
    mesh's ``regimes``, for :func:`add_colorbar`)."""
    from matplotlib.colors import BoundaryNorm
    from matplotlib.colors import ListedColormap
    from matplotlib.colors import LogNorm
    x, y = result.axes[0].name, result.axes[1].name
    xs, ys = np.array(result.axes[0].values), np.array(result.axes[1].values)
    grid = np.full((len(ys), len(xs)), np.nan)
    keep = np.ones(len(result), dtype=bool) if direction is None else result["direction"] == direction
    ix = np.searchsorted(xs, result[x][keep])
    iy = np.searchsorted(ys, result[y][keep])
    if column == "regime":
        shown = regimes_shown(result["regime"][keep])
        codes = {r: i for i, r in enumerate(shown)}
        grid[iy, ix] = [codes[str(r)] for r in result["regime"][keep]]
        cmap = ListedColormap([regime_color(r) for r in shown])
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap=cmap,
                             norm=BoundaryNorm(np.arange(-0.5, len(shown)), len(shown)))
        mesh.regimes = shown
    elif column.startswith("lambda_"):
        grid[iy, ix] = result[column][keep]
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap="RdBu_r", norm=exponent_norm(grid))
        if len(xs) > 1 and len(ys) > 1 and np.nanmin(grid) < 0 < np.nanmax(grid):
            mesh.zero_contour = ax.contour(xs, ys, grid, levels=[0.0], colors="k", linewidths=0.7)
    else:
        grid[iy, ix] = result[column][keep]
        finite = grid[np.isfinite(grid)]
        spread = finite.size and finite.min() > 0 and finite.max() > 100 * finite.min()
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap="viridis",
                             norm=LogNorm() if spread else None)  # (decades: a free shaft drifting)
    if _geometric(ys):
        ax.set_yscale("log")
        ax.set_yticks(ys, [f"{v:g}" for v in ys])
        ax.minorticks_off()
    ax.set_xlabel(_axis_label(x, result.units))
    ax.set_ylabel(_axis_label(y, result.units))
    return mesh


#: what the black line of an exponent's map is
ZERO_CONTOUR = "black line: λ₁ = 0"


def exponent_norm(values: np.ndarray):
    """Diverging colours for exponents: zero white, the negative side over the 2nd percentile .. 0 and the
    positive side over 0 .. the 98th percentile, so that each side uses its whole range of colours."""
    from matplotlib.colors import TwoSlopeNorm
    finite = values[np.isfinite(values)]
    if not finite.size:
        return TwoSlopeNorm(0.0, -1.0, 1.0)
    tiny = 1e-3 * max(float(np.max(np.abs(finite))), 1e-12)
    low = min(float(np.percentile(finite, 2)), -tiny)
    high = max(float(np.percentile(finite, 98)), tiny)
    return TwoSlopeNorm(0.0, low, high)


def add_colorbar(fig, ax, mesh, label: str, short: dict | None = None):
    """The colour bar of a map from :func:`plot_map`: a tick per regime drawn (``short`` abbreviates their
    names), or ``label`` and arrows where the colours are clipped."""
    regimes = getattr(mesh, "regimes", None)
    if regimes is not None:
        bar = fig.colorbar(mesh, ax=ax, ticks=range(len(regimes)))
        bar.ax.set_yticklabels([(short or {}).get(r, r) for r in regimes], fontsize=7)
        return bar
    values = mesh.get_array()
    values = np.asarray(values[np.isfinite(values)] if values is not None else [])
    norm = mesh.norm
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[
        (bool(values.size and values.min() < norm.vmin), bool(values.size and values.max() > norm.vmax))]
    return fig.colorbar(mesh, ax=ax, label=label, extend=extend)


def _edges(v: np.ndarray) -> np.ndarray:
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    if _geometric(v):  # 0.5, 1, 2, 4, 8: cells of equal width on a log axis
        return np.exp(_edges(np.log(v)))
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _geometric(v: np.ndarray) -> bool:
    return len(v) >= 3 and bool(np.all(v > 0)) and bool(np.allclose(np.diff(np.log(v)), np.log(v[1] / v[0])))


def _run_label(direction: str, values: dict, style: bool = True) -> str:
    """'up (solid), kS=0.1': the run, and how its curves are drawn."""
    fixed = ", ".join(f"{k}={v:g}" for k, v in values.items())
    run = "" if direction == "independent" else direction
    if run and style:
        run += f" ({_STYLE_NAME[_LINESTYLE[direction]]})"
    return ", ".join(p for p in (run, fixed) if p) or "sweep"


def _style_legend(result: SweepResult) -> list:
    """Legend entries for the line styles of the directions in ``result`` (none for independent points)."""
    from matplotlib.lines import Line2D
    directions = [d for d in dict.fromkeys(result["direction"].tolist()) if d in ("up", "down")]
    return [Line2D([], [], color="0.3", lw=1.0, ls=_LINESTYLE[d], label=f"{_STYLE_NAME[_LINESTYLE[d]]}: {d}")
            for d in directions]


def fixed_parameters(result: SweepResult) -> str:
    """The values of every parameter not swept: those the sweep set first, then the model's defaults; for a sweep
    in physical units, the physical values as the user gave them."""
    swept = {a.name for a in result.axes}
    physical = result.record.get("physical")
    if physical:
        return "values: " + ", ".join(f"{k}={v}" for k, v in physical["inputs"].items() if k not in swept)
    given = {k: v for k, v in result.record.get("settings", {}).items() if k not in swept}
    defaults = {k: v for k, v in result.record.get("parameters", {}).items() if k not in swept and k not in given}
    parts = [*(["set: " + ", ".join(f"{k}={v}" for k, v in given.items())] if given else []),
             *(["defaults: " + ", ".join(f"{k}={v:g}" for k, v in defaults.items())] if defaults else [])]
    return "; ".join(parts)


def sweep_title(result: SweepResult, width: int = 110) -> str:
    """The model, the swept ranges and the fixed parameters, wrapped to ``width`` characters."""
    swept = ", ".join(f"{a.name} = {a.values[0]:g}..{a.values[-1]:g}{_unit_text(result, a.name)} ({len(a.values)} values)"
                      for a in result.axes)
    mode = ("independent points" if result.mode == "independent" else
            _CONTINUATION.get(result.record.get("direction"), "continuation"))
    return textwrap.fill(f"{result.model}: {swept}, {mode}. {fixed_parameters(result)}", width)


def _unit_text(result: SweepResult, column: str) -> str:
    unit = result.units.get(column)
    return f" {unit}" if unit else ""


def _shown_direction(result: SweepResult) -> str | None:
    """The one run a panel that cannot overlay both shows: up if there is one (None: independent points)."""
    if result.mode == "independent":
        return None
    directions = list(dict.fromkeys(result["direction"].tolist()))
    return "up" if "up" in directions or not directions else directions[0]


def plot_sweep(result: SweepResult, path: str | Path | None = None, coordinate: str | None = None):
    """Overview, written to ``path`` (PNG) if given; returns the Figure. For one swept parameter: A of
    ``coordinate`` (default the first), lambda_i, the bifurcation diagram of ``coordinate`` and the regimes
    against it; for two, maps of lambda_1, the regime and A of every coordinate (``coordinate`` first) over
    both."""
    plt = pyplot()
    from matplotlib.lines import Line2D
    coordinate = coordinate or result.coordinates[0]
    if coordinate not in result.coordinates:
        raise GearsymError(f"plot_sweep: no coordinate {coordinate!r}; the coordinates are "
                           f"{', '.join(result.coordinates)}")
    direction = _shown_direction(result)
    run = f" ({direction})" if direction else ""
    if len(result.axes) >= 2:
        coordinates = [coordinate, *(c for c in result.coordinates if c != coordinate)]
        panels = [("lambda_1", r"$\lambda_1$"), ("regime", "regime"),
                  *((f"A_{c}", f"A ({c})") for c in coordinates)]
        columns = min(3, len(panels))
        rows = -(-len(panels) // columns)
        fig, axs = plt.subplots(rows, columns, figsize=(5 * columns, 4.2 * rows + 0.4), constrained_layout=True,
                                squeeze=False)
        over = f"over {result.axes[0].name} and {result.axes[1].name}"
        for ax, (column, label) in zip(axs.flat, panels):
            mesh = plot_map(ax, result, column, direction=direction)
            unit = (result.units or {}).get(column)
            named = f"{label} [{unit}]" if unit else label
            line = f" ({ZERO_CONTOUR})" if getattr(mesh, "zero_contour", None) is not None else ""
            ax.set_title(f"{named} {over}{run}{line}", fontsize=9)
            add_colorbar(fig, ax, mesh, named)
        for ax in list(axs.flat)[len(panels):]:
            ax.set_visible(False)
        fig.suptitle(sweep_title(result, 160), fontsize=9)
    else:
        fig, axs = plt.subplots(4, 1, figsize=(9.5, 10.5), sharex=True, constrained_layout=True,
                                gridspec_kw={"height_ratios": [3, 3, 3, 1]})
        plot_amplitude(axs[0], result, coordinate)
        plot_exponents(axs[1], result, which=range(1, result.exponent_count + 1), direction=None)
        plot_bifurcation(axs[2], result, coordinate, direction=direction)
        plot_regime_strip(axs[3], result)
        beside = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, frameon=False)  # off the curves
        axs[0].legend(**beside)
        handles, labels = axs[1].get_legend_handles_labels()
        colours = [Line2D([], [], color=h.get_color(), marker=h.get_marker(), mfc=h.get_markerfacecolor(),
                          ms=h.get_markersize(), lw=1.0, label=k) for k, h in dict(zip(labels, handles)).items()]
        axs[1].legend(handles=[*colours, *_style_legend(result)], **beside)
        axs[2].set_title(f"bifurcation diagram: {coordinate} at t = kT"
                         + (f", the {direction} run" if direction else ", independent points"), fontsize=9)
        axs[3].set_xlabel(_axis_label(result.axes[0].name, result.units))
        fig.suptitle(sweep_title(result, 100), fontsize=8)
    return finish(fig, path, dpi=120)
