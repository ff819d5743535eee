"""What ``gearsym explain`` writes: report.md, report.json, figures and the derived model's equations."""
from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import sympy as sp  # noqa: E402

from ..checks import json_safe  # noqa: E402
from ..figures.save import save_figure  # noqa: E402
from ..system import FirstOrderSystem  # noqa: E402
from .effects import EFFECTS, augment, effect_terms, mesh_term  # noqa: E402
from .explain import Candidate, Explanation  # noqa: E402


def write_report(ex: Explanation, system: FirstOrderSystem, out: str | Path, sources=()) -> dict:
    """Write DIR/report.md, DIR/report.json, DIR/residuals.png, DIR/prediction.png and DIR/derived_model.md."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = json_safe(ex.as_dict())
    (out / "report.json").write_text(json.dumps(data, indent=1, allow_nan=False) + "\n")
    _residual_figure(ex, out / "residuals.png")
    _prediction_figure(ex, out / "prediction.png")
    derived = augment(system, ex.effects) if ex.effects else system
    (out / "derived_model.md").write_text(derived_model_page(system, derived, ex.effects))
    (out / "report.md").write_text(report_page(ex, system, derived, data, sources))
    return data


def report_page(ex: Explanation, system: FirstOrderSystem, derived: FirstOrderSystem, data: dict, sources) -> str:
    before, after = ex.base, ex.final
    lines = [f"# What the data say {system.name} lacks", "",
             "<!-- written by `gearsym explain` -->", ""]
    if sources:
        lines += ["Data: " + ", ".join(f"`{Path(s).name}`" for s in sources) + ".", ""]
    lines += [f"Fitted: {', '.join(ex.fitted)} (and every window's start state), by multiple shooting over "
              f"one-forcing-period windows; the last {ex.held_out:.0%} of each record is held out and judged by "
              "the one-period-ahead prediction error (normalised RMS).", "", "## Verdict", ""]
    if ex.effects:
        lines += [f"**Added: {', '.join(ex.effects)}.** Held-out error {before.error:.4g} → {after.error:.4g} "
                  f"({before.error / after.error:.1f}× lower).", ""]
    else:
        lines += [f"**No effect added.** No candidate lowered the held-out error ({before.error:.4g}) by the "
                  "required margin.", ""]
    if ex.unexplained:
        lines += [f"**Unexplained: yes.** The held-out residual is not noise: its sample-to-sample correlation is "
                  f"{ex.correlation:.2f}. Something systematic is left that none of the candidate effects describes; "
                  "see where it lives in `residuals.png` (against mesh phase, state and velocity, and its spectrum in "
                  "harmonics of the forcing).", ""]
    else:
        lines += [f"**Unexplained: no.** The held-out residual looks like measurement noise (sample-to-sample "
                  f"correlation {ex.correlation:.2f}).", ""]
    lines += ["## Candidates (held-out error, lower is better)", "",
              "| model | held-out error | training σ | " + " | ".join(_names(ex)) + " |",
              "|---|---|---|" + "---|" * len(_names(ex))]
    for c in ex.tried:
        lines.append(f"| {'+'.join(c.effects) or 'as declared'} | {c.error:.4g} | {c.fit.sigma:.4g} | "
                     + " | ".join(_estimate(c, n) for n in _names(ex)) + " |")
    lines += ["", "## Estimates", "", "| parameter | before | after |", "|---|---|---|"]
    for name in dict.fromkeys([*before.fit.estimates, *after.fit.estimates]):
        lines.append(f"| {name} | {_estimate(before, name)} | {_estimate(after, name)} |")
    lines += ["", "## The derived model", ""]
    if ex.effects:
        terms = effect_terms(system, ex.effects)
        m = mesh_term(system)
        for name, term in terms.items():
            lines += [f"- **{name}** ({EFFECTS[name].description}) adds to $d{sp.latex(m.v)}/d\\tau$:", "",
                      f"$$ {sp.latex(term)} $$", ""]
        lines += [f"Full equations of `{derived.name}`: [`derived_model.md`](derived_model.md).", ""]
    else:
        lines += ["The model as declared.", ""]
    lines += ["## Figures", "", "![held-out prediction before and after](prediction.png)", "",
              "*One period ahead on the held-out data: measurement, and the model before and after.*", "",
              "![residuals](residuals.png)", "",
              "*Held-out residual (measurement − prediction) against mesh phase, state and velocity, and its "
              "spectrum in harmonics of the forcing: before (grey) and after (black).*", ""]
    return "\n".join(lines)


def derived_model_page(system: FirstOrderSystem, derived: FirstOrderSystem, effects) -> str:
    """The equations of ``derived`` (``system`` with ``effects`` added) and the terms that were added."""
    lines = [f"# `{derived.name}`", "", "<!-- written by `gearsym explain` -->", "",
             f"{derived.title or derived.name}. Equations in the paper's τ-form:", ""]
    for s, f in zip(derived.states, derived.rhs):
        lines += [f"$$ \\frac{{d{sp.latex(s)}}}{{d\\tau}} = {sp.latex(f)} $$", ""]
    if effects:
        lines += ["Terms added to the declared model:", ""]
        for name, term in effect_terms(system, effects).items():
            lines += [f"- {name}: $ {sp.latex(term)} $"]
        new = [p for p in derived.parameters if p not in system.parameters]
        lines += ["", "New parameters: " + ", ".join(f"`{p}`" for p in new) + ".", ""]
    return "\n".join(lines)


def _names(ex: Explanation) -> list[str]:
    return list(dict.fromkeys(n for c in ex.tried for n in c.fit.estimates))


def _estimate(c: Candidate, name: str) -> str:
    if name not in c.fit.estimates:
        return ""
    return f"{c.fit.estimates[name]:.4g} ± {c.fit.stderr[name]:.2g}"


def _phase_views(c: Candidate, system: FirstOrderSystem):
    p = c.prediction
    names = [s.name for s in system.states]
    coordinate = next(iter(p.residual))
    return (np.mod(p.tau, 2 * np.pi), p.states[names.index(coordinate)],
            p.states[min(names.index(coordinate) + 1, len(names) - 1)], p.residual[coordinate], coordinate)


def _residual_figure(ex: Explanation, path: Path) -> None:
    fig, axs = plt.subplots(1, 4, figsize=(16, 3.6), constrained_layout=True)
    for c, color, label in ((ex.base, "0.65", "as declared"), (ex.final, "k", "+".join(ex.effects) or "as declared")):
        if c is ex.final and not ex.effects:
            continue
        phase, x, v, r, coordinate = _phase_views(c, c.fit.system)
        for ax, what in zip(axs[:3], (phase, x, v)):
            ax.plot(what, r, ".", ms=2, color=color, label=label)
        spectrum = np.abs(np.fft.rfft(r - r.mean())) / len(r)
        harmonics = np.fft.rfftfreq(len(r), d=float(np.median(np.diff(c.prediction.tau)))) * 2 * np.pi
        axs[3].semilogy(harmonics[1:], spectrum[1:], color=color, lw=1, label=label)  # the mean is removed
    for ax, xlabel in zip(axs, ("mesh phase τ mod 2π", "state (predicted)", "velocity (predicted)",
                                "frequency (harmonics of the forcing)")):
        ax.set_xlabel(xlabel)
    axs[0].set_ylabel("held-out residual")
    axs[3].set_xlim(0, 8)
    axs[3].legend(fontsize=8)
    save_figure(fig, path, dpi=100)


def _prediction_figure(ex: Explanation, path: Path) -> None:
    p0, p1 = ex.base.prediction, ex.final.prediction
    coordinate = next(iter(p0.measured))
    count = min(len(p0.tau), 3 * len(p0.tau) // max(p0.pairs, 1))  # the first three predicted periods
    idx = np.arange(count)
    fig, ax = plt.subplots(figsize=(11, 3.6), constrained_layout=True)
    ax.plot(idx, p0.measured[coordinate][:count], ".", ms=3, color="C0", label="measured (held out)")
    ax.plot(idx, p0.predicted[coordinate][:count], "-", color="0.6", lw=1.2,
            label=f"as declared: error {ex.base.error:.3g}")
    if ex.effects:
        ax.plot(idx, p1.predicted[coordinate][:count], "-", color="k", lw=1,
                label=f"+{'+'.join(ex.effects)}: error {ex.final.error:.3g}")
    ax.set_xlabel("held-out sample (one period ahead of each estimated start)")
    ax.set_ylabel(coordinate)
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=100)


__all__ = ["derived_model_page", "report_page", "write_report"]
