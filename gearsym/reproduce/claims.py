"""The paper's claims, each checked against what gearsym computed.

A claim is stated as the paper states it, measured with a number that can
disagree (a fraction of grid points, a ratio, a list of attractors), and given
a verdict by a rule written next to it: ``agrees``, ``partly`` or
``disagrees`` (``not testable`` when the data hold nothing to test). The
parameter study adds, for the claims it can speak to, the declared values
under which the claim would hold, because k(tau) and the inertias are not in
the paper and the defaults are our choice.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..sweep import SweepResult
from .compute import Computed
from .plan import CHAOS_BAND, JUMP_TOLERANCE, NEAR_ONE, PAPER_JUMPS

CHAOTIC = ("chaotic", "hyperchaotic")
REGULAR = ("periodic", "quasi-periodic")  # (an undetermined point is neither: its run cannot say)


def _undetermined(regimes) -> str:
    """'; 3 of them undetermined (...)', where some points are neither regular nor chaotic."""
    count = int(np.sum(np.asarray(regimes) == "undetermined"))
    return (f"; {count} of them undetermined (λ₁ within its error of 0 and the Poincaré points not settled: "
            "counted as neither)" if count else "")
AGREES, PARTLY, DISAGREES, UNTESTABLE = "agrees", "partly", "disagrees", "not testable"


def _line(result: SweepResult, direction: str = "up", **fixed) -> np.ndarray:
    """Row indices of one run, in ascending order of the first parameter."""
    first = result.axes[0].name
    keep = result["direction"] == direction
    for k, v in fixed.items():
        keep &= np.isclose(result[k], v)
    idx = np.nonzero(keep)[0]
    return idx[np.argsort(result[first][idx], kind="stable")]


def _in(values: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    return (values >= band[0] - 1e-9) & (values <= band[1] + 1e-9)


def _fraction(mask: np.ndarray) -> float:
    return float(mask.mean()) if mask.size else float("nan")


def _chaos_windows(result: SweepResult, idx: np.ndarray) -> dict[str, float]:
    omega, chaotic = result["omega"][idx], np.isin(result["regime"][idx], CHAOTIC)
    return {"near_1": _fraction(chaotic[_in(omega, NEAR_ONE)]), "band": _fraction(chaotic[_in(omega, CHAOS_BAND)])}


def intervals(values: np.ndarray, mask: np.ndarray, gap: int = 1) -> list[tuple[float, float]]:
    """Maximal runs of consecutive grid points where ``mask`` holds (``values`` ascending)."""
    out, start, last = [], None, None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        if m:
            last = i
        if start is not None and (not m and i - last >= gap or i == len(mask) - 1):
            out.append((float(values[start]), float(values[last])))
            start = None
    return out


def _fmt_intervals(iv: list[tuple[float, float]]) -> str:
    return ", ".join(f"{a:.2f}" if a == b else f"[{a:.2f}, {b:.2f}]" for a, b in iv) or "none"


def _pct(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{100 * x:.0f} %"


def _claim(cid, figure, paper, measured, verdict, values, holds_for="") -> dict:
    return {"id": cid, "figure": figure, "paper": paper, "measured": measured, "verdict": verdict,
            "values": values, "holds_for": holds_for}


def _grade(x: float, agree: float, partly: float) -> str:
    if not np.isfinite(x):
        return UNTESTABLE
    return AGREES if x >= agree else PARTLY if x >= partly else DISAGREES


# ------------------------------------------------------------------ Fig. 3: the one-stage model, D = 0 and D = 2
def chaos_d0(c: Computed, study: dict) -> dict:
    r = c.sweeps["fig3_D0"]
    idx = _line(r)
    w = _chaos_windows(r, idx)
    chaotic = np.isin(r["regime"][idx], CHAOTIC)
    verdict = (AGREES if min(w.values()) >= 0.5 else PARTLY if max(w.values()) >= 0.5 or min(w.values()) >= 0.2
               else DISAGREES)
    return _claim("chaos-D0", "3b", "D = 0 (curve '1') is chaotic (λ₁ > 0) near ω = 1.0 and in "
                  "[1.24, 1.62].",
                  f"chaotic at {_pct(w['near_1'])} of the points in [{NEAR_ONE[0]}, {NEAR_ONE[1]}] and "
                  f"{_pct(w['band'])} in [{CHAOS_BAND[0]}, {CHAOS_BAND[1]}]; chaotic intervals: "
                  f"{_fmt_intervals(intervals(r['omega'][idx], chaotic))}",
                  verdict, {**w, "chaotic_intervals": intervals(r["omega"][idx], chaotic)}, study.get("chaos-D0", ""))


def regular_d2(c: Computed, study: dict) -> dict:
    r0, r2 = c.sweeps["fig3_D0"], c.sweeps["fig3_D2"]
    i0, i2 = _line(r0), _line(r2)
    chaotic0 = np.isin(r0["regime"][i0], CHAOTIC)
    regular2 = np.isin(r2["regime"][i2], REGULAR)
    share = _fraction(regular2[chaotic0])
    return _claim("regular-D2", "3b", "With D = 2 (curve '2') the motion is regular at most of the points where "
                  "D = 0 is chaotic.",
                  f"regular at {_pct(share)} of the {int(chaotic0.sum())} points where D = 0 is chaotic; D = 2 "
                  f"chaotic intervals: {_fmt_intervals(intervals(r2['omega'][i2], np.isin(r2['regime'][i2], CHAOTIC)))}"
                  + _undetermined(r2["regime"][i2][chaotic0]),
                  _grade(share, 0.5, 0.25), {"regular_share": share, "d0_chaotic_points": int(chaotic0.sum())})


def amplitude_d2(c: Computed, study: dict) -> dict:
    r0, r2 = c.sweeps["fig3_D0"], c.sweeps["fig3_D2"]
    i0, i2 = _line(r0), _line(r2)
    ratio = r2["A_x"][i2] / r0["A_x"][i0]
    median, larger = float(np.median(ratio)), _fraction(ratio > 1)
    verdict = AGREES if 1.0 < median <= 1.5 and larger >= 0.5 else PARTLY if larger >= 0.4 else DISAGREES
    return _claim("amplitude-D2", "3a", "The amplitude with D = 2 is slightly larger than with D = 0.",
                  f"A(D=2)/A(D=0): median {median:.3f}; larger at {_pct(larger)} of the points",
                  verdict, {"median_ratio": median, "larger_share": larger})


def _matched(jumps: list[dict]) -> list[float]:
    """The paper's jump locations that one of ``jumps`` lies at (within the tolerance)."""
    return [w for w in PAPER_JUMPS
            if any(min(j["from"], j["to"]) - JUMP_TOLERANCE <= w <= max(j["from"], j["to"]) + JUMP_TOLERANCE
                   for j in jumps)]


def jumps_d2(c: Computed, study: dict) -> dict:
    """Agrees only if the paper's jumps are among the largest ones found (the paper names two, so the
    two largest plus one): with many small jumps, some would fall near 1.36 and 1.70 by chance."""
    r = c.sweeps["fig3_D2"]
    findings = r.findings()
    up = [j for j in findings["jumps"] if j["direction"] == "up"]
    largest = sorted(up, key=lambda j: -abs(j["A_after"] - j["A_before"]))[:len(PAPER_JUMPS) + 1]
    matched, matched_large = _matched(up), _matched(largest)
    listing = "; ".join(f"{j['from']:.2f}->{j['to']:.2f} (A {j['A_before']:.2f}->{j['A_after']:.2f})" for j in up)
    hyst = "; ".join(f"[{h['from']:.2f}, {h['to']:.2f}]" for h in findings["hysteresis"]) or "none"
    verdict = AGREES if len(matched_large) == len(PAPER_JUMPS) else PARTLY if matched else DISAGREES
    return _claim("jumps-D2", "3a", "The amplitude with D = 2 jumps near ω = 1.36 and 1.70.",
                  f"{len(up)} jumps on the way up: {listing or 'none'}; within +-{JUMP_TOLERANCE} of the paper's: "
                  f"{', '.join(map(str, matched)) or 'none'}, of which among the {len(largest)} largest: "
                  f"{', '.join(map(str, matched_large)) or 'none'}; hysteresis (up and down differ): {hyst}",
                  verdict, {"jumps_up": up, "matched": matched, "matched_largest": matched_large,
                            "hysteresis": findings["hysteresis"]})


# ------------------------------------------------------------------ Fig. 4: coexisting attractors
def _attractor_summary(s) -> str:
    return ", ".join(f"'{a.paper_label}' {a.description} ({len(a.members)}/{len(s.results)} starts, "
                     f"λ₁ {a.lambda1:+.3f})" for a in s.attractors)


def _kinds(s) -> tuple[bool, bool]:
    return any(a.regular for a in s.attractors), any(not a.regular for a in s.attractors)


def coexistence_15(c: Computed, study: dict) -> dict:
    found = {m: c.attractors[(m, 1.5)] for m in ("one_stage", "one_stage_resonant")}
    both = [all(_kinds(s)) for s in found.values()]
    verdict = AGREES if all(both) else PARTLY if any(both) else DISAGREES
    return _claim("attractors-1.5", "4a", "At ω = 1.5 a regular ('1') and a chaotic ('2') attractor coexist, "
                  "for D = 0 and D = 2 alike.",
                  f"D = 0: {_attractor_summary(found['one_stage'])}. D = 2: "
                  f"{_attractor_summary(found['one_stage_resonant'])}",
                  verdict, {m: s.as_dict() | {"initial_conditions": None} for m, s in found.items()})


def coexistence_16(c: Computed, study: dict) -> dict:
    d0, d2 = c.attractors[("one_stage", 1.6)], c.attractors[("one_stage_resonant", 1.6)]
    parts = [not _kinds(d0)[0], _kinds(d2)[0], _kinds(d2)[1]]
    verdict = AGREES if all(parts) else PARTLY if any(parts) else DISAGREES
    return _claim("attractors-1.6", "4b", "At ω = 1.6 the regular attractor of D = 0 is gone; with D = 2 it "
                  "remains, and a chaotic attractor appears beside it.",
                  f"D = 0: {_attractor_summary(d0)}. D = 2: {_attractor_summary(d2)}",
                  verdict, {"one_stage": d0.as_dict() | {"initial_conditions": None},
                            "one_stage_resonant": d2.as_dict() | {"initial_conditions": None}})


# ------------------------------------------------------------------ Fig. 6: the flexible shaft
def _windows_mask(omega: np.ndarray) -> np.ndarray:
    return _in(omega, NEAR_ONE) | _in(omega, CHAOS_BAND)


def amplitude_ks(c: Computed, study: dict) -> dict:
    r = c.sweeps["fig6"]
    a0, a1 = (r["A_x1"][_line(r, kS=k)] for k in (0.0, 1.0))
    ratio = a1 / a0
    median, lower = float(np.median(ratio)), _fraction(ratio < 1)
    return _claim("amplitude-kS1", "6a", "The stiff shaft (kS = 1.0, curve '3') lowers the amplitude.",
                  f"A(kS=1)/A(kS=0): median {median:.3f}; lower at {_pct(lower)} of the points",
                  AGREES if median < 1 and lower >= 0.5 else PARTLY if lower >= 0.3 else DISAGREES,
                  {"median_ratio": median, "lower_share": lower})


def _flex_window_stats(r: SweepResult, **fixed) -> dict[str, float]:
    idx = _line(r, **fixed)
    win = _windows_mask(r["omega"][idx])
    regime = r["regime"][idx][win]
    chaotic = np.isin(regime, CHAOTIC)
    return {"chaotic": _fraction(chaotic), "regular": _fraction(np.isin(regime, REGULAR)),
            "hyper_of_chaotic": _fraction(regime[chaotic] == "hyperchaotic") if chaotic.any() else float("nan"),
            "single_of_chaotic": _fraction(regime[chaotic] == "chaotic") if chaotic.any() else float("nan")}


def chaos_ks01(c: Computed, study: dict) -> dict:
    r = c.sweeps["fig6"]
    s0, s1 = _flex_window_stats(r, kS=0.0), _flex_window_stats(r, kS=0.1)
    kept = s1["chaotic"] / s0["chaotic"] if s0["chaotic"] else float("nan")
    return _claim("chaos-kS0.1", "6b", "The weak shaft (kS = 0.1, curve '2') does not reduce the chaos of kS = 0 "
                  "near ω = 1.0 and in [1.24, 1.62].",
                  f"chaotic in those windows at {_pct(s1['chaotic'])} of the points for kS = 0.1, against "
                  f"{_pct(s0['chaotic'])} for kS = 0 (ratio {kept:.2f})",
                  _grade(kept, 0.8, 0.5), {"kS=0": s0, "kS=0.1": s1, "kept": kept}, study.get("chaos-kS0.1", ""))


def tamed_ks1(c: Computed, study: dict) -> dict:
    s = _flex_window_stats(c.sweeps["fig6"], kS=1.0)
    return _claim("tamed-kS1", "6b", "The stiff shaft (kS = 1.0) tames the chaos in those regions.",
                  f"regular at {_pct(s['regular'])} of the points near ω = 1.0 and in [1.24, 1.62]",
                  _grade(s["regular"], 0.8, 0.5), s, study.get("tamed-kS1", ""))


def hyperchaos_ks01(c: Computed, study: dict) -> dict:
    r = c.sweeps["fig6"]
    idx = _line(r, kS=0.1)
    whole = _whole_line(r, minimum=1, kS=0.1)
    return _claim("hyperchaos-kS0.1", "6c", "For kS = 0.1 most chaotic regions have two positive exponents "
                  "(hyperchaos).",
                  f"{whole['chaotic_points']} chaotic points over the whole sweep, {_pct(whole['hyper_share'])} of "
                  f"them with two positive exponents; hyperchaotic at "
                  f"{_fmt_intervals(intervals(r['omega'][idx], r['regime'][idx] == 'hyperchaotic'))}",
                  _grade(whole["hyper_share"], 0.5, 0.2), whole, study.get("hyperchaos-kS0.1", ""))


def single_ks1(c: Computed, study: dict) -> dict:
    r = c.sweeps["fig6"]
    regime = r["regime"][_line(r, kS=1.0)]
    chaotic = np.isin(regime, CHAOTIC)
    share = _fraction(regime[chaotic] == "chaotic") if chaotic.any() else float("nan")
    return _claim("single-kS1", "6d", "For kS = 1.0 the chaotic regions have only one positive exponent.",
                  f"{int(chaotic.sum())} chaotic points, {_pct(share)} of them with exactly one positive exponent",
                  _grade(share, 0.8, 0.5), {"chaotic_points": int(chaotic.sum()), "single_share": share})


# ------------------------------------------------------------------ Fig. 7: portraits at ω = 1.5
def portraits(c: Computed, study: dict) -> dict:
    by = {p.letter: p for p in c.portraits}
    reg = {k: by[k].spectrum.regime for k in "abc"}
    strobe = by["b"].spectrum.strobe[:, -50:]  # synchronised: the last Poincare points are one point
    period1 = bool(np.all(np.abs(strobe - strobe[:, -1:]) <= 1e-4 * (1 + np.abs(strobe[:, -1:]))))
    parts = [reg["a"] in CHAOTIC, reg["b"] in REGULAR and period1, reg["c"] == "hyperchaotic"]
    lam = {k: ", ".join(f"{x:+.3f}" for x in by[k].spectrum.exponents) for k in "abc"}
    return _claim("portraits-1.5", "7", "At ω = 1.5 from the paper's start: kS = 0 chaotic (a), kS = 1.0 regular "
                  "and synchronised with the excitation (b), kS = 0.1 hyperchaotic (c, d).",
                  f"(a) kS = 0: {reg['a']} ({lam['a']}); (b) kS = 1.0: {reg['b']}"
                  f"{', period 1' if period1 else ''} ({lam['b']}); (c) kS = 0.1: {reg['c']} ({lam['c']})",
                  AGREES if all(parts) else PARTLY if any(parts) else DISAGREES,
                  {"regimes": reg, "period1_at_kS1": period1})


CHECKS: tuple[Callable[[Computed, dict], dict], ...] = (
    chaos_d0, regular_d2, amplitude_d2, jumps_d2, coexistence_15, coexistence_16,
    amplitude_ks, chaos_ks01, tamed_ks1, hyperchaos_ks01, single_ks1, portraits,
)


# ------------------------------------------------------------------ the parameter study
#: the fewest chaotic points over a line for a hyperchaotic share to mean anything
MIN_CHAOTIC = 5


def _whole_line(r: SweepResult, minimum: int = MIN_CHAOTIC, **fixed) -> dict[str, float]:
    """Chaotic points over the whole line, and the hyperchaotic share of them (the hyperchaos claim's
    measure); the share is NaN with fewer than ``minimum`` chaotic points."""
    regime = r["regime"][_line(r, **fixed)]
    chaotic = np.isin(regime, CHAOTIC)
    share = _fraction(regime[chaotic] == "hyperchaotic") if chaotic.sum() >= max(minimum, 1) else float("nan")
    return {"chaotic_points": int(chaotic.sum()), "hyper_share": share}


def study_rows(c: Computed) -> dict[str, list[dict]]:
    """Per value of each study parameter: the measures the claims use, on the study's grid.
    ``kept``: chaos in the windows at this value over chaos at kS = 0 with the same other values."""
    out = {}
    ka = c.sweeps["study_ka"]
    out["k_a"] = [{"value": v, **_chaos_windows(ka, _line(ka, k_a=v))} for v in ka.axes[1].values]
    ks = c.sweeps["study_kS"]
    base = _flex_window_stats(ks, kS=0.0)["chaotic"]
    out["kS"] = [{"value": v, **(s := _flex_window_stats(ks, kS=v)), **_whole_line(ks, kS=v),
                  "kept": s["chaotic"] / base if base else float("nan")} for v in ks.axes[1].values]
    inertia, inertia0 = c.sweeps["study_inertia"], c.sweeps["study_inertia_kS0"]
    rows = []
    for v in inertia.axes[1].values:
        s, b = _flex_window_stats(inertia, I2=v), _flex_window_stats(inertia0, I2=v)["chaotic"]
        rows.append({"value": v, **s, **_whole_line(inertia, I2=v), "kept": s["chaotic"] / b if b else float("nan")})
    out["I2"] = rows
    return out


def _values_where(rows: list[dict], test: Callable[[dict], bool]) -> list[float]:
    return [r["value"] for r in rows if test(r)]


def _listing(name: str, values: list[float], of: list[dict]) -> str:
    studied = ", ".join(f"{r['value']:g}" for r in of)
    if not values:
        return f"holds for none of the {name} values studied ({studied})"
    return f"holds for {name} = {', '.join(f'{v:g}' for v in values)} (of {studied})"


def study_holds(rows: dict[str, list[dict]]) -> dict[str, str]:
    """For the claims the study can speak to: under which studied values the claim's rule says 'agrees'."""
    ka, ks, inertia = rows["k_a"], rows["kS"], rows["I2"]
    return {
        "chaos-D0": _listing("k_a", _values_where(ka, lambda r: min(r["near_1"], r["band"]) >= 0.5), ka),
        "chaos-kS0.1": _listing("kS", _values_where(ks, lambda r: r["kept"] >= 0.8 and r["value"] > 0), ks)
        + "; at kS = 0.1 " + _listing("I2", _values_where(inertia, lambda r: r["kept"] >= 0.8), inertia),
        "tamed-kS1": _listing("kS", _values_where(ks, lambda r: r["regular"] >= 0.8), ks),
        "hyperchaos-kS0.1": _listing("kS", _values_where(ks, lambda r: r["hyper_share"] >= 0.5), ks)
        + "; at kS = 0.1 " + _listing("I2", _values_where(inertia, lambda r: r["hyper_share"] >= 0.5), inertia),
    }


def evaluate(c: Computed) -> dict:
    """Every claim, and (if the plan has it) the study behind the 'holds for' notes; JSON-ready."""
    if "study_ka" not in c.sweeps:
        return {"claims": [check(c, {}) for check in CHECKS]}
    rows = study_rows(c)
    return {"claims": [check(c, study_holds(rows)) for check in CHECKS], "study": rows}
