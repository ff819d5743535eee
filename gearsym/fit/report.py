"""What ``gearsym explain`` writes: report.md, report.json, figures and the derived model's equations.

The page leads with the verdict; then each candidate with its held-out error (and why a rejected one
was), the residual's spectrum in harmonics of the forcing with the orders that stand out, the terms
proposed beyond the library, and the estimates before and after in canonical form (amplitudes >= 0,
phases in (-pi, pi]; not identifiable or at a physical bound where so).
"""
from __future__ import annotations

import math
from pathlib import Path

import sympy as sp

from ..system import FirstOrderSystem
from .effects import effect_terms
from .selection import MIN_SCORE, Candidate, Explanation

VERDICTS = {
    "explained": "the effects added explain the data: what is left looks like measurement noise",
    "partly explained": "the effects added lower the error, but something systematic is left",
    "unexplained": "no effect of the library explains what the model misses",
    "nothing missing": "the model as declared predicts the data to the noise: no effect is missing",
}


#: the files of a report, replaced together (:func:`~gearsym.files.sets.written_together`)
REPORT_FILES = ("report.json", "residuals.png", "prediction.png", "derived_model.md", "report.md")
#: the figure of a tooth-by-tooth form's values, tooth by tooth, written beside them when one was tried
TEETH_FIGURE = "teeth.png"
#: the file that says a report folder is partial (a run killed while it replaced the files)
PARTIAL_MARKER = "REPORT-INCOMPLETE.txt"


def report_page(ex: Explanation, system: FirstOrderSystem, derived: FirstOrderSystem, data: dict, sources) -> str:
    before, after = ex.base, ex.final
    lines = [f"# What the data say {system.name} lacks", "", "<!-- written by `gearsym explain` -->", ""]
    lines += [f"## Verdict: {ex.verdict}", "", f"**{VERDICTS[ex.verdict].capitalize()}.**", ""]
    if ex.effects:
        lines += [f"- Added: **{', '.join(ex.effects)}**. Held-out error {before.error:.4g} → {after.error:.4g} "
                  f"({before.error / after.error:.1f}× lower)."]
    elif "displaced" in ex.info:
        d = ex.info["displaced"]
        lines += [f"- No effect added: {', '.join(d['effects'])} lowered the held-out error to {d['error']:.4g}, but "
                  f"only by standing in for `{d['term']}`: with that term, the model does as well without "
                  f"{'them' if len(d['effects']) > 1 else 'it'} ({d['error_alone']:.4g}) as with "
                  f"({d['error_with']:.4g}), so it is not reported as found."]
    else:
        lines += [f"- No effect added: no candidate lowered the held-out error ({before.error:.4g}) by the required "
                  "margin."]
    lines += fault_lines(data["faults"])
    for name, h in data["harmonics"].items():
        lines += [f"- {name}: order {h['order']}, amplitude {_pm(h['amplitude'], h['amplitude_stderr'])}, phase "
                  f"{_pm(h['phase'], h['phase_stderr'])} rad (the term {h['form'].replace('A', 'amplitude')})."]
    state = "is not noise" if ex.unexplained else "looks like measurement noise"
    lines += [f"- The held-out residual {state}: its sample-to-sample correlation is {ex.correlation:.2f} (above "
              f"0.5 means something systematic is left)."]
    if data["not_identifiable"]:
        lines += [f"- Not identifiable from these data: {', '.join(data['not_identifiable'])}."]
    for a, b, rho in data["correlated"]:
        lines += [f"- Strongly correlated: {a} and {b} (correlation {rho:+.3f}): the data fix a combination of the "
                  "two better than either."]
    if ex.proposed:
        best = ex.proposed[0]
        lines += [f"- Beyond the library, the residual asks for `{best.term}`: refitted with it, the held-out error is "
                  f"{best.error:.4g} (see *Proposed terms*; try it with `--add-term \"{best.term}\"`)."]
    lines += [""]
    if sources:
        lines += ["Data: " + ", ".join(f"`{Path(s).name}`" for s in sources) + ".", ""]
    channels = ", ".join(dict.fromkeys(k for r in after.fit.residuals for k in r))
    lines += [f"Fitted: {', '.join(ex.fitted)} (and every window's start state"
              + (f", and the offsets of {', '.join(ex.bias)}" if ex.bias else "")
              + (", fitted by default: an acceleration's steady mean is zero for bounded motion, so a constant "
                 "offset is the sensor's bias" if ex.bias_by_default else "")
              + f"), by multiple shooting over one-forcing-period windows of the channels {channels}; the last "
              f"{ex.held_out:.0%} of each record is held out and judged by the one-period-ahead prediction error "
              "(normalised RMS).", ""]
    lines += _candidates(ex) + _spectrum(ex) + _sidebands(data) + _proposals(ex) + _estimates(ex, data)
    lines += ["## The derived model", ""]
    if ex.effects:
        for name in (e for e in ex.effects if ex.library[e].gears):
            lines += [f"- **{name}**: {ex.library[name].description}; the teeth that do not stand out at 0.", ""]
        for name, rows in effect_terms(system, [ex.library[e] for e in ex.effects if not ex.library[e].gears]).items():
            lines += [f"- **{name}** ({ex.library[name].description}) adds:", ""]
            for state, term in rows.items():
                lines += [f"$$ \\frac{{d{sp.latex(sp.Symbol(state))}}}{{d\\tau}} \\mathrel{{+}}= {sp.latex(term)} $$", ""]
        lines += [f"Full equations of `{derived.name}`: [`derived_model.md`](derived_model.md).", ""]
    else:
        lines += ["The model as declared.", ""]
    lines += ["## Figures", "", "![held-out prediction before and after](prediction.png)", "",
              "*One period ahead on the held-out data: the measurement, and the model as declared and after.*", "",
              "![residuals](residuals.png)", "",
              "*The held-out residual (measurement − prediction) against the mesh phase, the coordinate and its "
              "rate, as declared (grey) and after (black); and its spectrum in harmonics of the forcing, with the "
              "level white noise would reach.*", ""]
    return "\n".join(lines)


def fault_lines(faults: list[dict]) -> list[str]:
    """The verdict's lines of the shaft-order effects found: which gear, which tooth, how much."""
    out = []
    for f in faults:
        if f["kind"] in ("tooth stiffness", "tooth profile"):
            out += _tooth_lines(f)
        elif f["kind"] == "spall":
            change = _pm_percent(f["stiffness_change_percent"], f["stiffness_change_stderr_percent"])
            where = f"tooth {f['tooth']} of {f['gear']}" if f["tooth"] is not None else \
                f"{f['gear']}, " + ", ".join(f"tooth {n} in {r}" for r, n in f["tooth_by_record"].items())
            out.append(f"- **{where}: a spall, face width {change}** (`{f['effect']}`: the pair of that tooth, counted "
                       f"from the record's start, loses this fraction of its width over the middle of its path of "
                       f"contact; {f['teeth']} teeth).")
        elif f["kind"] == "tooth fault":
            change = _pm_percent(f["stiffness_change_percent"], f["stiffness_change_stderr_percent"])
            if f["tooth"] is not None:
                where = f"tooth {f['tooth']} of {f['gear']}"
            else:
                where = f"{f['gear']}, " + ", ".join(f"tooth {n} in {r}" for r, n in f["tooth_by_record"].items())
            out.append(f"- **{where}: stiffness {change}** (`{f['effect']}`: the pair of that tooth, counted from "
                       f"the record's start, loses this fraction of its stiffness while in mesh; {f['teeth']} teeth).")
        elif f["kind"] == "eccentricity":
            out.append(f"- **eccentricity of {f['gear']}**: amplitude {_pm(f['amplitude'], f['amplitude_stderr'])}, "
                       f"phase {_pm(f['phase'], f['phase_stderr'])} rad (`{f['effect']}`: the transmission error "
                       f"{f['form'].replace('A', 'amplitude')}, in the length unit of the mesh coordinate).")
        else:
            shown = ", ".join(f"{e:.3g}" for e in f["errors"])
            out.append(f"- **spacing errors of {f['gear']}** (`{f['effect']}`, tooth 1 ... {f['teeth']} from "
                       f"tau = 0): {shown}.")
    return out


def _tooth_lines(f: dict) -> list[str]:
    """A tooth-by-tooth form's verdict lines: the teeth that stand out, gear by gear, counted from each record's
    start, with their refitted values; or that none does."""
    stiffness = f["kind"] == "tooth stiffness"
    out = []
    for gear, teeth in f["standing_out"].items():
        if not teeth:
            continue
        by_record = {r: g[gear] for r, g in f["standing_out_by_record"].items()}
        counted = set(map(tuple, by_record.values()))
        numbers = (", ".join(map(str, counted.pop())) if len(counted) == 1 else
                   "; ".join(f"{', '.join(map(str, n))} in {r}" for r, n in by_record.items()))
        values = []
        for n in teeth:
            value, err = f["refitted"][gear][n] if n in f["refitted"][gear] else f["refitted"][gear][str(n)]
            values.append(_pm_percent(-100 * value, None if err is None else 100 * err) if stiffness
                          else _pm(value, err))
        what = "mesh stiffness while in mesh" if stiffness else "profile error"
        out.append(f"- **{gear}, tooth {numbers}: {what} {', '.join(values)}** (`{f['effect']}`: every tooth of "
                   f"both gears fitted, {sum(f['gears'].values())} parameters; the teeth that stand out, counted from "
                   "the record's start, refitted; see teeth.png).")
    if not out:
        out.append(f"- `{f['effect']}`: no tooth stands out (every tooth of both gears fitted; see teeth.png).")
    return out


def _pm_percent(value: float, err: float | None) -> str:
    sign = "−" if value < 0 else "+"
    shown = f"{sign}{abs(value):.3g} %"
    return f"{shown} ± {err:.2g} %" if err is not None and math.isfinite(err) else shown


def _number(value) -> str:
    """A number of the report's JSON (None where it was not finite) as the page shows it."""
    return "—" if value is None else f"{value:.3g}"


def _sidebands(data: dict) -> list[str]:
    evidence = data.get("sidebands")
    notes = [f"- not tried: {name}: {why}." for name, why in (data.get("not_tried") or {}).items()]
    if not evidence or not evidence.get("before"):
        return (["## Shaft orders", ""] + notes + [""]) if notes else []
    before, after = evidence["before"], evidence.get("after") or {}
    gears = list(before["gears"])
    lines = ["## The residual's sidebands (shaft orders)", "",
             "Lines of the training residual at each gear's shaft orders and at the mesh harmonics ± them "
             f"(relative to each channel's spread, averaged over records; one line of white noise reaches about "
             f"{before['noise']:.2g}). Gears: " + ", ".join(f"{g} ({z} teeth)" for g, z in before["gears"].items())
             + ".", "", "| gear | sideband energy as declared | after | strongest lines as declared |", "|---|---|---|---|"]
    for g in gears:
        top = sorted(((k, v) for k, v in before["lines"].items() if g in k.split()), key=lambda kv: -kv[1])[:3]
        shown = ", ".join(f"{k} {v:.2g}" for k, v in top)
        lines.append(f"| {g} | {_number(before['energy'].get(g))} | {_number(after.get('energy', {}).get(g))} | "
                     f"{shown} |")
    return lines + [""] + notes + ([""] if notes else [])


def _candidates(ex: Explanation) -> list[str]:
    lines = ["## Candidates (held-out error, lower is better)", "",
             "| model | held-out error | training σ | its estimates | note |", "|---|---|---|---|---|"]
    for c in ex.tried:
        own = [p for e in c.effects for p in ex.library[e].fitted if p in c.fit.estimates] or list(ex.fitted)
        shown = ", ".join(f"{p} = {_estimate(c, p)}" for p in own)
        if any(ex.library[e].gears for e in c.effects) and not shown:
            shown = "no tooth stands out"
        note = f"rejected: {c.rejected}" if c.rejected else ("**chosen**" if c is ex.final and c.effects else "")
        lines.append(f"| {'+'.join(c.effects) or 'as declared'} | {c.error:.4g} | {c.fit.sigma:.4g} | {shown} | {note} |")
    lines.append("")
    for step in ex.info.get("screened", []):
        skipped = [name for name in step["gains"] if name not in step["refitted"]]
        if not skipped:
            continue
        after = f"after {'+'.join(step['after'])}" if step["after"] else "as declared"
        shown = "; ".join(f"{name}: {step['why_not'][name]}" if name in step["why_not"]
                          else f"{name} {step['gains'][name]:.2g}" for name in skipped)
        lines += [f"Screened out {after} by the linearised gain (the fraction of the residual a candidate would remove "
                  f"to first order; those of {MIN_SCORE:g} or more are refitted, the largest first): {shown}.", ""]
    return lines


def _spectrum(ex: Explanation) -> list[str]:
    if ex.spectrum is None:
        return []
    s0, s1 = ex.spectrum, ex.final_spectrum
    lines = ["## The residual's spectrum (harmonics of the forcing)", "",
             "Amplitude of the held-out residual at each harmonic, relative to each channel's spread; white noise "
             f"would reach about {s0.noise:.2g}. Orders that stand out as declared: "
             f"{', '.join(map(str, s0.standout)) or 'none'}"
             + (f"; after: {', '.join(map(str, s1.standout)) or 'none'}" if s1 is not s0 and ex.effects else "") + ".",
             "", "| order | " + " | ".join(map(str, s0.orders)) + " |", "|---|" + "---|" * len(s0.orders),
             "| as declared | " + " | ".join(_amp(a, o in s0.standout) for o, a in zip(s0.orders, s0.amplitude)) + " |"]
    if ex.effects:
        lines.append("| after | " + " | ".join(_amp(a, o in s1.standout) for o, a in zip(s1.orders, s1.amplitude))
                     + " |")
    return lines + [""]


def _amp(value: float, standout: bool) -> str:
    return f"**{value:.3g}**" if standout else f"{value:.3g}"


def _proposals(ex: Explanation) -> list[str]:
    if not ex.proposed:
        return []
    lines = ["## Proposed terms (beyond the library)", "",
             "Terms of a generic dictionary (polynomials in the states, g(x, η) and its powers, harmonics of τ, their "
             "products) that a sparse regression of the residual chose, each added to dv/dτ of the mesh coordinate "
             "and refitted (`g` is the mesh's g(x, η)):", "",
             "| term | coefficient | held-out error (without → with) |", "|---|---|---|"]
    for p in ex.proposed:
        lines.append(f"| `{p.term}` | {_pm(p.coefficient, p.stderr)} | {p.error_before:.4g} → {p.error:.4g} |")
    return lines + ["", "Accept one with `gearsym explain ... --add-term \"TERM\"`: it is then tried like any effect.", ""]


def _estimates(ex: Explanation, data: dict) -> list[str]:
    before, after = ex.base, ex.final
    lines = ["## Estimates (amplitudes ≥ 0, phases in (−π, π])", "", "| parameter | before | after |", "|---|---|---|"]
    for name in dict.fromkeys([*before.fit.estimates, *after.fit.estimates]):
        lines.append(f"| {name} | {_estimate(before, name)} | {_estimate(after, name)} |")
    for name in after.fit.bias:
        lines.append(f"| offset of {name} | {_pm(before.fit.bias[name], before.fit.bias_stderr[name])} | "
                     f"{_pm(after.fit.bias[name], after.fit.bias_stderr[name])} |")
    return lines + [""]


def derived_model_page(system: FirstOrderSystem, derived: FirstOrderSystem, effects) -> str:
    """The equations of ``derived`` (``system`` with ``effects`` added) and the terms that were added."""
    lines = [f"# `{derived.name}`", "", "<!-- written by `gearsym explain` -->", "",
             f"{derived.title or derived.name}. Equations in the paper's τ-form:", ""]
    for s, f in zip(derived.states, derived.rhs):
        lines += [f"$$ \\frac{{d{sp.latex(s)}}}{{d\\tau}} = {sp.latex(f)} $$", ""]
    if effects:
        lines += ["Terms added to the declared model:", ""]
        for name, rows in effect_terms(system, effects).items():
            for state, term in rows.items():
                lines += [f"- {name}, in d{state}/dτ: $ {sp.latex(term)} $"]
        new = [p for p in derived.parameters if p not in system.parameters]
        lines += ["", "New parameters: " + ", ".join(f"`{p}`" for p in new) + ".", ""]
    return "\n".join(lines)


def _pm(value: float, err: float | None) -> str:
    return f"{value:.4g} ± {err:.2g}" if err is not None and math.isfinite(err) else f"{value:.4g}"


def _estimate(c: Candidate, name: str) -> str:
    f = c.fit
    if name not in f.estimates:
        return ""
    if name in f.at_bound:
        return f"{f.estimates[name]:.4g} (at its bound)"
    if not f.identifiable.get(name, True):
        return "not identifiable"
    return _pm(f.estimates[name], f.stderr[name])


__all__ = ["REPORT_FILES", "PARTIAL_MARKER", "TEETH_FIGURE", "VERDICTS",
           "derived_model_page", "report_page"]
