"""The data loop: fit, find what the residual says the model lacks, add it, report before and after.

1. Split every record by time: the first part trains, the last ``held_out`` (whole forcing
   periods) is held out.
2. Fit the named parameters to the training windows (multiple shooting, :mod:`.shooting`); the
   held-out error is the one-period-ahead prediction error (:mod:`.prediction`). The held-out
   residual's spectrum in harmonics of the forcing says which orders stand out (:func:`residual_spectrum`).
3. Forward selection over the effect library (:mod:`.effects`): the effects without an order, the
   harmonic families (stiffness, torque, transmission error) at the orders that stand out and at
   each family's order of largest linearised gain, and any term written by hand. The linearised
   gain (a score test on the exact sensitivities, :func:`linearised_gains`) ranks them: a parametric
   harmonic's response spreads over neighbouring orders, so the spectrum alone can miss its order;
   the first ``refits`` whose gain is at least ``MIN_SCORE`` are added and refitted (their own
   parameters with the named ones, within
   their physical bounds); the one that lowers the *held-out* error most is kept if it lowers it by
   at least ``min_gain`` (a fraction). Repeat while one does. In-sample fit never decides: a term that only fits noise does not predict. A
   candidate whose parameter ends on its physical bound (a friction that would push with the
   motion) or that the data cannot determine is rejected, and the report says why.
4. Whether anything is left: the held-out residual of the final model should be measurement noise,
   uncorrelated from one sample to the next. Its lag-1 autocorrelation above ``max_correlation``
   means a smooth, systematic error is left: ``unexplained``. Then terms beyond the library are
   proposed from a generic dictionary (:mod:`.proposals`).

Verdicts: ``explained`` (effects added, the residual is noise), ``partly explained`` (effects added,
something systematic left), ``unexplained`` (nothing added, something left), ``nothing missing``.

Every candidate is a setting of one system, the declared model with *all* candidate effects at 0
(off), so one compiled window integrator serves every fit of the search.
"""
from __future__ import annotations

import math
import time
from collections.abc import Sequence
from pathlib import Path
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import GearsymError, on_command_line, option, option_name as caller_name, suggest
from ..checks import whole_number
from ..data.dataset import Measurements
from ..options import Execution, Integration
from ..system import FirstOrderSystem
from .canonical import amplitude_phase, canonical
from .effects import EFFECTS, FAMILIES, Effect, applies_to, augment, bounds_of, effect, site, term_effect
from .evidence import residual_sidebands
from .prediction import Prediction, predict_ahead
from .proposals import propose_terms
from .result import Fit
from .score import score_columns
from .segment import Segment
from .shaft_effects import BUILDERS as SHAFT_BUILDERS, DEFAULT_KINDS as SHAFT_DEFAULTS, revolution_length, \
    shaft_effects
from .shooting import fit_windows
from .tooth_forms import GENERAL_KINDS, general_forms, local_effect, place_slots, standing_out, tooth_values
from .tooth_scan import from_record_start, Placement, scan_teeth

MIN_GAIN = 0.2
MAX_CORRELATION = 0.5
MAX_EFFECTS = 2
#: the harmonic families are in the library at orders 1 ... HARMONICS (and the dictionary's harmonics) ...
HARMONICS = 4
#: ... and at most MAX_HARMONICS: each order adds three families (six parameters) to the one compiled candidate
#: model, and every fit's tangent is as wide (one_stage at 32 orders: 207 parameters, 18 s to compile)
MAX_HARMONICS = 32
#: orders of the forcing shown in the residual's spectrum
SPECTRUM_ORDERS = 8
#: at most this many orders that stand out are tried per round
STANDOUT_ORDERS = 3
#: at most this many candidates are refitted per round, those of largest linearised gain first ...
REFITS = 8
#: ... and only those whose linearised gain is at least this fraction of the residual (to be kept, a candidate
#: must lower the held-out error by MIN_GAIN, about 36 % of the residual's energy)
MIN_SCORE = 0.02
#: an order stands out if its amplitude is this many standard errors of a harmonic of white noise ...
STANDOUT_SIGMAS = 5.0
#: ... and at least this fraction of the largest
STANDOUT_FRACTION = 0.2


@dataclass(frozen=True)
class Candidate:
    """One model tried: its effects, fit and held-out prediction, and why it may not be chosen ('' if it may)."""

    effects: tuple[str, ...]
    fit: Fit
    prediction: Prediction
    rejected: str = ""
    placements: dict = field(default_factory=dict)  # a tooth fault's effect -> record key -> its tooth (from tau 0)
    system: FirstOrderSystem | None = None  # the compiled model it was fitted on, where not the search's (a
    slots: tuple = ()  # tooth-by-tooth form's, with its slots: :mod:`.tooth_forms`) ...
    regularised: Fit | None = None  # ... and its regularised fit of every tooth (``fit``: the teeth that stand out)

    @property
    def error(self) -> float:
        return self.prediction.error


@dataclass(frozen=True)
class Spectrum:
    """The residual's amplitude at each harmonic of the forcing (normalised by each channel's spread,
    averaged over channels), the amplitude a harmonic of white noise would reach (one standard error),
    and the orders that stand out, largest first."""

    orders: tuple[int, ...]
    amplitude: tuple[float, ...]
    noise: float
    standout: tuple[int, ...]

    def as_dict(self) -> dict:
        return {"orders": list(self.orders), "amplitude": list(self.amplitude), "noise": self.noise,
                "standout": list(self.standout)}


@dataclass(frozen=True)
class Explanation:
    base: Candidate
    final: Candidate
    tried: list[Candidate]  # every candidate evaluated, in order
    unexplained: bool
    correlation: float  # lag-1 autocorrelation of the final held-out residual
    fitted: tuple[str, ...]
    held_out: float
    info: dict = field(default_factory=dict)
    spectrum: Spectrum | None = None  # of the declared model's training residual
    final_spectrum: Spectrum | None = None
    proposed: list = field(default_factory=list)  # proposals.Proposal
    library: dict = field(default_factory=dict)  # name -> Effect of every candidate in the search
    system: FirstOrderSystem | None = None  # the declared model
    bias: tuple[str, ...] = ()
    bias_by_default: tuple[str, ...] = ()  # the acceleration channels whose offsets were fitted without being asked

    @property
    def effects(self) -> list[str]:
        return list(self.final.effects)

    @property
    def verdict(self) -> str:
        if self.effects:
            return "partly explained" if self.unexplained else "explained"
        return "unexplained" if self.unexplained else "nothing missing"

    def harmonics(self, c: Candidate | None = None) -> dict[str, dict]:
        """The (cos, sin) pairs of a candidate's harmonic effects as order, amplitude >= 0, phase in (-pi, pi]."""
        c = c or self.final
        out = {}
        for name in c.effects:
            e = self.library[name]
            for a, b in e.pairs:
                fit = c.fit
                cov = fit.covariance
                C = np.array([[cov[a][a], cov[a][b]], [cov[b][a], cov[b][b]]]) if a in cov and b in cov else None
                A, theta, sA, st = amplitude_phase(fit.estimates[a], fit.estimates[b], C)
                out[name] = {"order": e.order, "amplitude": A, "phase": theta, "amplitude_stderr": sA,
                             "phase_stderr": st, "form": f"A cos({e.order} phi + phase)" if e.acts_on != "torque"
                             else f"A cos({e.order} tau + phase)"}
        return out

    def shaft_orders(self, c: Candidate | None = None) -> list[dict]:
        """What a candidate's shaft-order effects say, gear by gear: a tooth fault's tooth (counted from each record's
        start) and severity, an eccentricity's amplitude and phase, spacing errors."""
        c = c or self.final
        fit, out = c.fit, []
        starts = self.info.get("records", {})
        for name in c.effects:
            e = self.library[name]
            if not e.shaft_order:
                continue
            item = {"effect": name, "gear": e.gear, "teeth": e.teeth}
            order = _order_of(self.system, e)
            if e.gears:
                item = {"effect": name, "gears": {g: z for g, z in e.gears}}
                every = c.regularised or fit  # every tooth (regularised); the ones that stand out refitted in fit
                values = tooth_values(e, every.estimates, every.stderr)
                out_ = standing_out(values)
                refit = {g: {n: [fit.estimates.get(p), fit.stderr.get(p)] for n, p in zip(out_[g], _tooth_names(e, g, out_[g]))}
                         for g in out_}
                stiffness = name.startswith("tooth_stiffness")
                item.update(kind="tooth stiffness" if stiffness else "tooth profile",
                            quantity="loss of mesh stiffness while the tooth is in mesh (fraction)" if stiffness
                            else "transmission error while the tooth carries the load (length unit of the mesh "
                                 "coordinate)",
                            values={g: [v for v, _ in vs] for g, vs in values.items()},
                            stderr={g: [err for _, err in vs] for g, vs in values.items()},
                            median={g: float(np.median([v for v, _ in vs])) for g, vs in values.items()},
                            standing_out=out_, refitted=refit,
                            standing_out_by_record={
                                record_label(key): {g: [from_record_start(n, z, start, order) for n in out_[g]]
                                                     for g, z in e.gears}
                                for key, start in starts.items()})
            elif e.scan:
                q = fit.estimates[e.fitted[0]]
                sq = fit.stderr.get(e.fitted[0])
                by_record = {record_label(key): from_record_start(int(n), e.teeth, starts.get(key, 0.0), order)
                             for key, n in c.placements.get(name, {}).items()}
                common = set(by_record.values())
                item.update(kind="spall" if name.startswith("spall_") else "tooth fault",
                            tooth=common.pop() if len(common) == 1 else None,
                            tooth_by_record=by_record, severity=q, severity_stderr=sq,
                            stiffness_change_percent=-100 * q, stiffness_change_stderr_percent=None if sq is None
                            else 100 * sq)
            elif e.pairs:
                a, b = e.pairs[0]
                cov = fit.covariance
                C = np.array([[cov[a][a], cov[a][b]], [cov[b][a], cov[b][b]]]) if a in cov and b in cov else None
                A, theta, sA, st = amplitude_phase(fit.estimates[a], fit.estimates[b], C)
                item.update(kind="eccentricity", amplitude=A, phase=theta, amplitude_stderr=sA, phase_stderr=st,
                            form=f"A cos(phi/{e.teeth} + phase)")
            else:
                values = [fit.estimates[p] for p in e.fitted]
                item.update(kind="spacing errors", errors=[*values, -sum(values)],
                            stderr=[fit.stderr.get(p) for p in e.fitted] + [None])
            out.append(item)
        return out

    def as_dict(self) -> dict:
        def fit_dict(c: Candidate) -> dict:
            f = c.fit
            return {"effects": list(c.effects), "held_out_error": c.error, "estimates": f.estimates,
                    "stderr": f.stderr, "not_identifiable": [p for p, ok in f.identifiable.items() if not ok],
                    "at_bound": {p: b for p, (b, _) in f.at_bound.items()}, "bias": f.bias,
                    "training_sigma": f.sigma, "converged": f.success, "rejected": c.rejected or None}
        final = self.final.fit
        return {
            "verdict": self.verdict,
            "effects": self.effects,
            "unexplained": self.unexplained,
            "error_before": self.base.error,
            "error_after": self.final.error,
            "parameters": final.estimates,
            "stderr": final.stderr,
            "not_identifiable": [p for p, ok in final.identifiable.items() if not ok],
            "correlated": [[a, b, rho] for a, b, rho in final.correlations],
            "harmonics": self.harmonics(),
            "bias": final.bias,
            "bias_stderr": final.bias_stderr,
            "bias_by_default": list(self.bias_by_default),
            "parameters_before": self.base.fit.estimates,
            "stderr_before": self.base.fit.stderr,
            "residual_correlation": self.correlation,
            "spectrum": self.spectrum.as_dict() if self.spectrum else None,
            "spectrum_after": self.final_spectrum.as_dict() if self.final_spectrum else None,
            "proposed": [p.as_dict() for p in self.proposed],
            "fitted": list(self.fitted),
            "held_out_fraction": self.held_out,
            "candidates": [fit_dict(c) for c in self.tried],
            "screened": self.info.get("screened", []),
            "displaced": self.info.get("displaced"),  # library effects that only stood in for a proposed term
            "faults": self.shaft_orders(),  # shaft-order effects added: which gear, which tooth, how much
            "sidebands": self.info.get("evidence"),  # the residual's shaft-order lines, before and after
            "not_tried": self.info.get("too_short", {}),  # shaft-order effects the records are too short for
        }


def segments_of(system: FirstOrderSystem, measurements: Measurements) -> tuple[list[Segment], list[tuple]]:
    """Every whole-period window as a Segment with the record's full parameter values for ``system``."""
    segments, keys = [], []
    for r in measurements:
        values = {**system.parameters, **measurements.parameters(r)}
        conditions = ", ".join(f"{k}={v:g}" for k, v in r.conditions.items())
        record = f"{r.label} ({conditions})" if conditions else r.label
        for w in r.windows():
            key = ((str(r.source), r.record), w.index)  # (which record, which period)
            segments.append(Segment(w.tau, w.observed, values, f"{record} period {w.index}", r.channels, key))
            keys.append(key)
    return segments, keys


def candidate_library(system: FirstOrderSystem, candidates: Sequence[str | Effect] | None = None,
                      harmonics: int = HARMONICS, terms: Sequence[str] = ()) -> dict[str, Effect]:
    """The effects a search may try, by name: ``candidates`` (default every effect that applies to ``system``,
    with a tooth fault and an eccentricity on every gear with a tooth count; a family's bare name stands for its
    orders 1 ... ``harmonics``, a shaft-order kind's (``tooth_fault``) for every gear's), then the hand-written
    ``terms``."""
    out: dict[str, Effect] = {}
    names = candidates if candidates is not None else [*EFFECTS, *FAMILIES, *SHAFT_DEFAULTS]
    for name in names:
        if isinstance(name, str) and name in FAMILIES:
            chosen = [FAMILIES[name](n) for n in range(1, harmonics + 1)]
        elif isinstance(name, str) and name in SHAFT_BUILDERS:
            chosen = list(shaft_effects(system, (name,)).values())
            if not chosen and candidates is not None:
                raise GearsymError(f"{name}: no gear of {system.name} has a tooth count; give a model that declares "
                                   "Gear(..., teeth=Z), or --teeth Z1,Z2 (teeth=(Z1, Z2) in Python)")
        else:
            chosen = [effect(name, system)]
        for e in chosen:
            if applies_to(system, e):
                out[e.name] = e
            elif candidates is not None:  # asked for by name: say why it has nowhere to act
                site(system, e.acts_on)
    for i, text in enumerate(terms, 1):
        e = term_effect(text, system, i)
        out[e.name] = e
    return out


def explain(system: FirstOrderSystem, measurements: Measurements, fit: Sequence[str], *,
            candidates: Sequence[str | Effect] | None = None, held_out: float = 0.25,
            min_gain: float = MIN_GAIN, max_effects: int = MAX_EFFECTS,
            max_correlation: float = MAX_CORRELATION, execution: Execution | None = None,
            options: Integration = Integration(), bias: Sequence[str] | None = None, terms: Sequence[str] = (),
            harmonics: int | None = None, propose: bool = True, refits: int = REFITS) -> Explanation:
    """Fit ``fit`` on ``measurements``, then add effects from ``candidates`` (default: the whole library) and the
    hand-written ``terms`` while they lower the held-out error; see the module docstring. ``bias``: channels
    with an unknown constant offset, fitted with the parameters (default: the acceleration channels, whose steady
    mean is zero for bounded motion, so that a constant offset in one is the sensor's bias; ``()``: none).
    ``harmonics``: the highest order of the harmonic families (default ``HARMONICS``, or fewer if the data
    resolve fewer)."""
    say = (execution or Execution()).say
    fit = check_fit_names(fit, system)
    harmonics = check_harmonics(harmonics, measurements)
    _check_one_value_each(measurements, fit)
    by_default = acceleration_channels(measurements, system) if bias is None else ()
    bias = list(by_default if bias is None else bias)
    if by_default:
        say(f"fitting the offset of {', '.join(by_default)} (an acceleration's steady mean is zero for bounded "
            f"motion, so a constant offset is the sensor's bias; {_no_bias()} fits none)")
    for name in bias:
        if name not in measurements.observed:
            raise GearsymError(f"bias of {name}: no such channel in the data ({', '.join(measurements.observed)})")
    forms = general_forms(system)
    named_forms = [c for c in candidates or () if isinstance(c, str) and (c in GENERAL_KINDS or c in forms)]
    library = candidate_library(system, None if candidates is None else
                                [c for c in candidates if c not in named_forms], harmonics, terms)
    general = {name: e for name, e in forms.items()
               if candidates is None or name in named_forms or any(name.startswith(k + "_") for k in named_forms)}
    if named_forms and not general:
        raise GearsymError(f"{named_forms[0]}: no mesh of {system.name} has two gears with tooth counts; give a model "
                           "that declares Gear(..., teeth=Z), or --teeth Z1,Z2 (teeth=(Z1, Z2) in Python)")
    named = {c for c in candidates or () if isinstance(c, str)}
    too_short = _too_short(system, measurements, {**library, **general}, named=named)
    library = {name: e for name, e in library.items() if name not in too_short}
    general = {name: e for name, e in general.items() if name not in too_short}
    superset = augment(system, list(library.values()), name=f"{system.name}_candidates") if library else system
    train, test = measurements.split(held_out)
    seg_train, keys_train = segments_of(superset, train)
    seg_test, keys = segments_of(superset, test)
    bounds = bounds_of(list(library.values()))
    scanned: dict[str, Placement] = {}  # a tooth fault's latest scan
    clock = Clock(1 + max_effects * refits)  # fits at most: the model as declared, then up to refits a round
    say(f"{len(seg_train)} training windows of {len(seg_train[0].tau) if seg_train else 0} samples, "
        f"{len(library)} candidate effects; the first fit compiles the windows of the model with every "
        "candidate (once: cached for the next run)")

    def evaluate(effects: tuple[str, ...], start: Candidate | None) -> Candidate:
        names = list(fit) + [p for e in effects for p in library[e].fitted]
        guess = dict(start.fit.estimates) if start else {}
        placements = {e: (start.placements[e] if start and e in start.placements else scanned[e].teeth)
                      for e in effects if library[e].scan}
        train_here, test_here = (placed(segs, placements, library) for segs in (seg_train, seg_test))
        result = fit_windows(superset, train_here, names, guess=guess, options=options, bias=bias, bounds=bounds,
                             starts=start.fit.starts if start else None,
                             guess_bias=start.fit.bias if start else None)
        result = replace(result, estimates=canonical(superset, result.estimates))
        anchors = {key[0]: (seg.tau[0], start) for key, seg, start in zip(keys_train, seg_train, result.starts.T)}
        prediction = predict_ahead(superset, test_here, keys, result.estimates, options=options, bias=result.bias,
                                   anchors=anchors)  # the last training window of each record
        rejected = _rejection(result, [library[e] for e in effects])
        say(f"{'+'.join(effects) or 'the model as declared'}: held-out error {prediction.error:.4g}"
            + (f" (rejected: {rejected})" if rejected else "") + f"; {clock.tick()}")
        return Candidate(effects, result, prediction, rejected, placements)

    def spectrum_of(c: Candidate) -> Spectrum:
        return residual_spectrum(c.prediction, structured=_lag1(c.prediction) > max_correlation)

    base = evaluate((), None)
    spectrum = spectrum_of(base)
    tried, current, current_spectrum, screened = [base], base, spectrum, []
    while len(current.effects) < max_effects:
        open_ = [name for name in library if name not in current.effects]
        here = placed(seg_train, current.placements, library)
        gains = linearised_gains(superset, here, current.fit, library, [n for n in open_ if not library[n].scan],
                                 bias, options)
        # a tooth fault: its tooth scanned in every record
        for name, placement in scan_teeth(superset, here, current.fit, [library[n] for n in open_ if library[n].scan],
                                          bias, options).items():
            scanned[name] = placement
            gains[name] = (placement.gain, placement.why)
        names = _round(library, current, current_spectrum, superset, {k: g for k, (g, _) in gains.items()}, refits)
        screened.append({"after": list(current.effects), "gains": {k: g for k, (g, _) in gains.items()},
                         "why_not": {k: why for k, (_, why) in gains.items() if why}, "refitted": names})
        clock.plan(len(names) + max(0, max_effects - len(current.effects) - 1) * refits)
        say(f"round {len(screened)}: {len(names)} candidate(s) to fit ({', '.join(names) or 'none'})")
        round_ = [evaluate(current.effects + (name,), current) for name in names]
        tried.extend(round_)
        eligible = [c for c in round_ if not c.rejected and np.isfinite(c.error)]
        if not eligible:
            break
        best = min(eligible, key=lambda c: c.error)
        if best.error > (1 - min_gain) * current.error:
            break
        current = best
        current_spectrum = spectrum_of(current)
    if general and (named_forms or _lag1(current.prediction) > max_correlation):
        # the named faults leave something systematic (or the general forms were asked for): every tooth's own
        # parameter, in place of the named tooth faults (the other effects kept); chosen only where it predicts
        # clearly better than the named faults do
        others = tuple(e for e in current.effects if not library[e].scan)
        start = next((c for c in tried if c.effects == others), base)
        round_ = []
        clock.plan(len(general))
        for e in general.values():
            round_.append(_general_candidate(system, library, e, others, start, list(fit), train, test, bounds,
                                             options, bias, say, clock))
            library[e.name] = e
            if not round_[-1].rejected and _lag1(round_[-1].prediction) <= max_correlation:
                break  # (explained: the next form would only cost its compilation)
        tried.extend(round_)
        eligible = [c for c in round_ if not c.rejected and np.isfinite(c.error)]
        if eligible:
            best = min(eligible, key=lambda c: c.error)
            if best.error <= (1 - min_gain) * current.error:
                say(f"{'+'.join(best.effects)} predicts better than the named faults ({best.error:.4g} against "
                    f"{current.error:.4g}): chosen")
                current, current_spectrum = best, spectrum_of(best)
    correlation = _lag1(current.prediction)
    unexplained = bool(correlation > max_correlation)
    evidence = None
    if any(e.shaft_order for e in library.values()):
        evidence = {"before": residual_sidebands(superset, base.fit, seg_train),
                    "after": residual_sidebands(superset, current.fit, placed(seg_train, current.placements, library))}
    info = {"screened": screened, "too_short": too_short, "evidence": evidence,
            "records": _record_starts(keys_train, seg_train),
            "scans": {name: {"gains": p.gains, "gain": p.gain} for name, p in scanned.items()}}
    ex = Explanation(base, current, tried, unexplained, correlation, tuple(fit), held_out, info,
                     spectrum=spectrum, final_spectrum=current_spectrum, library=library, system=system,
                     bias=tuple(bias), bias_by_default=tuple(by_default))
    if unexplained and propose and current.system is None:  # (not on a tooth-by-tooth form's own model)
        final_train, final_test = (placed(segs, current.placements, library) for segs in (seg_train, seg_test))
        ex = replace(ex, proposed=propose_terms(ex, superset, final_train, final_test, keys, options, harmonics,
                                                say))
        if ex.effects and ex.proposed:  # do the effects earn their place beside the term the residual asks for?
            alone = replace(ex, final=base)
            alone = replace(alone, proposed=propose_terms(alone, superset, seg_train, seg_test, keys, options,
                                                          harmonics, say))
            if alone.proposed and ex.proposed[0].error > (1 - min_gain) * alone.proposed[0].error:
                say(f"{'+'.join(ex.effects)} stood in for {alone.proposed[0].term}: not reported as found")
                displaced = {"effects": ex.effects, "error": current.error, "term": alone.proposed[0].term,
                             "error_with": ex.proposed[0].error, "error_alone": alone.proposed[0].error}
                ex = replace(alone, correlation=_lag1(base.prediction), final_spectrum=spectrum,
                             info={**ex.info, "displaced": displaced})
    return ex


def _general_candidate(system: FirstOrderSystem, library: dict[str, Effect], e: Effect, others: tuple[str, ...],
                       start: Candidate, fit: list[str], train, test, bounds: dict, options: Integration,
                       bias: Sequence[str], say, clock: Clock) -> Candidate:
    """The tooth-by-tooth form ``e`` beside the effects ``others``, fitted (regularised, from the fit ``start``) and
    its held-out prediction, on a compiled model of its own: the declared one with ``others`` and ``e``'s slots
    (:func:`.tooth_forms.local_effect`)."""
    coupling = next(c for c in system.couplings if c.coordinate == e.coordinate)
    local, slots = local_effect(e, float(coupling.order or 1), 2 * np.pi)
    model = augment(system, [*(library[o] for o in others), local], name=f"{system.name}_{e.name}_fit")
    seg_train, keys_train = segments_of(model, train)
    seg_test, keys = segments_of(model, test)
    seg_train = place_slots(seg_train, slots)
    names = fit + [p for o in others for p in library[o].fitted]
    scale = 1.0
    if e.prior_unit == "displacement":  # the prior's spread: a fraction of the mesh coordinate's
        row = system.state_names.index(e.coordinate)
        scale = float(np.std(np.concatenate([states[row] for states in start.fit.states]))) or 1.0
    ridge = {p: (start.fit.sigma / (e.prior * scale)) ** 2 for p in e.fitted}
    regularised = fit_windows(model, seg_train, names + list(e.fitted), guess=start.fit.estimates, options=options,
                              bias=bias, bounds={**bounds, **e.bounds}, starts=start.fit.starts,
                              guess_bias=start.fit.bias, slots=slots, ridge=ridge)
    # the teeth that stand out, refitted without the prior (which shrinks them), the others at 0: the prior picks the
    # teeth, the data alone say how much (a regularised estimate's shrinkage and its noise on every other tooth both
    # cost the one-period-ahead prediction more than its training fit shows)
    chosen = [name for gear, teeth in standing_out(tooth_values(e, regularised.estimates, regularised.stderr)).items()
              for name in _tooth_names(e, gear, teeth)]
    result = regularised
    if chosen:
        result = fit_windows(model, seg_train, names + chosen, guess=regularised.estimates, options=options, bias=bias,
                             bounds={**bounds, **e.bounds}, starts=regularised.starts, guess_bias=regularised.bias,
                             slots=slots)
    direct = canonical(model, {k: v for k, v in result.estimates.items() if k in model.parameters})
    result = replace(result, estimates={**result.estimates, **direct})
    anchors = {key[0]: (seg.tau[0], s0) for key, seg, s0 in zip(keys_train, seg_train, result.starts.T)}
    prediction = predict_ahead(model, place_slots(seg_test, slots, result.estimates), keys, direct, options=options,
                               bias=result.bias, anchors=anchors)
    rejected = _rejection(result, [*(library[o] for o in others)]) or _rejection(regularised, [e])
    effects = others + (e.name,)
    say(f"{'+'.join(effects)}: held-out error {prediction.error:.4g}" + (f" (rejected: {rejected})" if rejected else "")
        + f"; {clock.tick()}")
    return Candidate(effects, result, prediction, rejected, {}, model, slots, regularised)


def _tooth_names(e: Effect, gear: str, teeth: Sequence[int]) -> list[str]:
    """The parameter names of ``teeth`` (1 ... Z) of ``gear`` in the tooth-by-tooth form ``e``."""
    prefix = "kt" if e.name.startswith("tooth_stiffness") else "te"
    return [f"{prefix}{n}_{gear}" for n in teeth]


class Clock:
    """The fits done, the time they took and what is left at most: the progress ``explain`` shows."""

    def __init__(self, planned: int):
        self.start, self.done, self.left = time.perf_counter(), 0, planned

    def plan(self, left: int) -> None:
        """At most ``left`` more fits from here."""
        self.left = left

    def tick(self) -> str:
        self.done += 1
        self.left = max(0, self.left - 1)
        spent = time.perf_counter() - self.start
        each = spent / self.done
        return (f"fit {self.done} done, {spent:.0f} s so far ({each:.0f} s a fit); at most {self.left} more, "
                f"about {_duration(self.left * each)} left at most")


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.1f} min"


def _record_starts(keys: Sequence[tuple], segments: Sequence[Segment]) -> dict:
    """Each record's first sample time (its first window's)."""
    out: dict = {}
    for key, seg in zip(keys, segments):
        out.setdefault(key[0], float(seg.tau[0]))
    return out


def record_label(key) -> str:
    """A record's key (its file and id) as the report names it."""
    if isinstance(key, tuple) and len(key) == 2:
        return f"{Path(str(key[0])).name} record {key[1]}"
    return str(key)


def _order_of(system: FirstOrderSystem | None, e: Effect) -> float:
    c = next((c for c in (system.couplings if system else ()) if c.coordinate == e.coordinate), None)
    return float(c.order or 1) if c is not None else 1.0


def placed(segments: Sequence[Segment], placements: dict, library: dict[str, Effect]) -> list[Segment]:
    """``segments`` with each tooth fault of ``placements`` on its record's tooth (its scanned parameter)."""
    if not placements:
        return list(segments)
    out = []
    for seg in segments:
        values = {library[name].scan: float(teeth[seg.key[0]]) for name, teeth in placements.items()
                  if seg.key and seg.key[0] in teeth}
        out.append(replace(seg, parameters={**seg.parameters, **values}) if values else seg)
    return out


def _too_short(system: FirstOrderSystem, measurements: Measurements, library: dict[str, Effect],
               named: set) -> dict[str, str]:
    """The shaft-order effects a record is too short to show (shorter than one revolution of the gear), with why:
    refused with an error if they were asked for by their own name (``tooth_fault_gear2``, not ``tooth_fault``)."""
    out = {}
    for name, e in library.items():
        if not e.shaft_order:
            continue
        need = revolution_length(e, system)
        short = [r for r in measurements if r.samples * r.step < need * (1 - 1e-9)]
        if short:
            r = short[0]
            gear, teeth = max(e.revolutions, key=lambda item: item[1])
            out[name] = (f"{r.label} covers {r.samples * r.step / (2 * np.pi):.4g} mesh periods (tau "
                         f"{r.samples * r.step:.4g}), shorter than one revolution of {gear}: {teeth} mesh periods "
                         f"(tau {need:.4g}); record at least that long to look for {name}")
            if name in named:
                raise GearsymError(f"cannot look for {name}: {out[name]}")
    return out


def _round(library: dict[str, Effect], current: Candidate, spectrum: Spectrum, system: FirstOrderSystem,
           scores: dict[str, float], refits: int) -> list[str]:
    """The candidates of the next round: every effect without an order or written by hand, and the harmonic
    families at the orders the residual's spectrum suggests (a mesh family's order N is the forcing's N times the
    mesh order) and at each family's order of largest linearised gain; the ``refits`` of largest gain first, if
    that gain is at least ``MIN_SCORE``."""
    out, best = [], {}
    for name, e in library.items():
        if name in current.effects:
            continue
        if not e.order:
            out.append(name)
            continue
        ratio = _mesh_order(system) if e.acts_on == "mesh" else 1
        if e.order * ratio in spectrum.standout:
            out.append(name)
        if scores.get(name, 0.0) > scores.get(best.get(e.family, ""), 0.0):
            best[e.family] = name
    out += [name for name in best.values() if name not in out]
    ranked = sorted(out, key=lambda name: -scores.get(name, 0.0))
    return [name for name in ranked if scores.get(name, 0.0) >= MIN_SCORE][:refits]


def linearised_gains(system: FirstOrderSystem, segments: Sequence[Segment], fit: Fit, library: dict[str, Effect],
                     names: Sequence[str], bias: Sequence[str], options: Integration) -> dict[str, tuple[float, str]]:
    """For each candidate of ``names``: the fraction of the training residual its parameters would remove to first
    order (the score test: the residual regressed on the candidate's exact sensitivity columns, with what the fit
    already moves, its parameters, start states and offsets, projected out), and why it is 0 where a one-parameter
    effect would need the wrong sign (its physical bound) or cannot act on these data."""
    params = [p for name in names for p in library[name].fitted]
    if not params:
        return {}
    y, D, _ = score_columns(system, segments, fit, params, bias, options)
    total = float(y @ y) or 1.0
    gains, at = {}, 0
    for name in names:
        e = library[name]
        cols = D[:, at:at + len(e.fitted)]
        at += len(e.fitted)
        if not np.any(np.linalg.norm(cols, axis=0) > 1e-9 * (np.linalg.norm(y) + 1e-300)):
            gains[name] = (0.0, "it does not act on these data")
            continue
        coef = np.linalg.lstsq(cols, y, rcond=None)[0]
        if len(coef) == 1 and e.fitted[0] in e.bounds:
            low, high, why = e.bounds[e.fitted[0]]
            if not low <= coef[0] <= high:  # the data ask for the unphysical sign
                gains[name] = (0.0, f"it would need {e.fitted[0]} {'<' if coef[0] < low else '>'} "
                                    f"{low if coef[0] < low else high:g}, but {why}")
                continue
        fitted_part = cols @ coef
        gains[name] = (float(fitted_part @ fitted_part) / total, "")
    return gains


def _mesh_order(system: FirstOrderSystem) -> int:
    order = site(system, "mesh").coupling.order
    try:
        return int(order) if order else 1
    except TypeError:
        return 1


def _rejection(result: Fit, effects: Sequence[Effect]) -> str:
    """Why a candidate may not be chosen: a parameter on its physical bound, one the data cannot determine."""
    reasons = []
    for e in effects:
        for p in e.fitted:
            if p in result.at_bound:
                bound, why = result.at_bound[p]
                reasons.append(f"{p} ran into its bound {bound:g} ({why})")
            elif not result.identifiable.get(p, True):
                reasons.append(f"{p} is not identifiable from these data")
    if not result.success:
        reasons.append("the fit did not converge")
    return "; ".join(reasons)


def residual_spectrum(prediction: Prediction, orders: int = SPECTRUM_ORDERS, structured: bool = False) -> Spectrum:
    """The held-out residual's amplitude at the forcing's harmonics 1 ... ``orders`` (least squares over all
    predicted samples, in absolute tau), normalised by each channel's spread and averaged over the channels.

    The held-out residual, not the training one: in training every window's start state absorbs much of what
    the model misses. An order stands out if it is ``STANDOUT_SIGMAS`` standard errors of white noise and a
    fifth of the largest; a ``structured`` residual (not noise) suggests its largest orders even if none does.
    """
    k = np.arange(1, orders + 1)
    tau = prediction.tau
    A = np.hstack([np.ones((tau.size, 1)), np.cos(np.outer(tau, k)), np.sin(np.outer(tau, k))])
    amplitudes, noises = [], []
    for name, r in prediction.residual.items():
        r = r / (np.std(prediction.measured[name]) or 1.0)
        coef, *_ = np.linalg.lstsq(A, r, rcond=None)
        amplitudes.append(np.hypot(coef[1:orders + 1], coef[orders + 1:]))
        noises.append(float(np.std(r - A @ coef)) * np.sqrt(2.0 / max(tau.size, 1)))
    amplitude, noise = np.mean(amplitudes, axis=0), float(np.mean(noises))
    threshold = max(STANDOUT_SIGMAS * noise, STANDOUT_FRACTION * float(amplitude.max(initial=0.0)))
    ranked = [int(o) for o in np.argsort(-amplitude, kind="stable") + 1]
    standout = [o for o in ranked if amplitude[o - 1] > threshold]
    if structured and len(standout) < STANDOUT_ORDERS:
        standout += [o for o in ranked if o not in standout][:STANDOUT_ORDERS - len(standout)]
    return Spectrum(tuple(range(1, orders + 1)), tuple(map(float, amplitude)), noise, tuple(standout[:STANDOUT_ORDERS]))


def acceleration_channels(measurements: Measurements, system: FirstOrderSystem) -> tuple[str, ...]:
    """The channels that measure accelerations alone (``x_ddot``, or a combination such as r1*x1_ddot + x2_ddot,
    in every record): bounded motion has a zero steady mean acceleration, so a constant offset in one is sensor
    bias, fitted by default."""
    return tuple(name for name in measurements.observed
                 if all(_accelerations_only(r.channels[name], system) for r in measurements if name in r.observed))


def _accelerations_only(channel, system: FirstOrderSystem) -> bool:
    """``channel`` is linear and homogeneous in second derivatives, with parameters (no state, rate, time) beside."""
    second = {s for s in channel.free_symbols if s.name.endswith("_ddot")}
    others = {s.name for s in channel.free_symbols - second}
    if not second or not others <= set(system.parameters):
        return False
    return channel.xreplace({s: 0 for s in second}) == 0 and \
        all(not (channel.diff(s).free_symbols & second) for s in second)


def _no_bias() -> str:
    return "--bias none" if on_command_line() else "bias=()"


def check_fit_names(fit: Sequence[str], system: FirstOrderSystem | None = None) -> list[str]:
    """The parameters to fit: at least one, each named once, and (given the ``system``) each a parameter of the model
    as declared (an effect's own parameters are fitted when the effect is tried)."""
    names = [fit] if isinstance(fit, str) else list(fit)
    if not names:
        example = "--fit zeta,B1" if on_command_line() else "fit=['zeta', 'B1']"
        raise GearsymError(f"name the parameters to fit, e.g. {example}")
    twice = [p for i, p in enumerate(names) if p in names[:i]]
    if twice:
        raise GearsymError(f"{caller_name('fit')} names {twice[0]} twice: name each parameter once (a second "
                           "column of the same parameter leaves the fit no unique answer)")
    if system is not None:
        unknown = [p for p in names if p not in system.parameters]
        if unknown:
            raise GearsymError(f"cannot fit {unknown[0]}: {system.name} has no parameter {unknown[0]}."
                               f"{suggest(unknown[0], system.parameters)} Its parameters: "
                               f"{', '.join(system.parameters)} (an effect's own parameters are fitted when the "
                               "effect is tried)")
    return names


def check_harmonics(harmonics: int | None, measurements: Measurements | None = None) -> int:
    """The highest order of the harmonic families: at least 1, at most ``MAX_HARMONICS`` and (with
    ``measurements``) at most what the sparsest record resolves, an order n taking more than 2n samples a forcing
    period. None: ``HARMONICS``, or fewer if the data resolve fewer."""
    resolved = None
    if measurements is not None and len(measurements):
        sparsest = min(r.samples_per_period for r in measurements)
        resolved = max(1, math.ceil(sparsest / 2) - 1)
    if harmonics is None:
        return min(HARMONICS, resolved or HARMONICS)
    order = whole_number(harmonics, caller_name("harmonics"), 1)
    if order > MAX_HARMONICS:
        raise GearsymError(f"{option('harmonics', order)}: at most {MAX_HARMONICS} (each order adds three harmonic "
                           "families, six parameters, to the one compiled model of every candidate)")
    if resolved is not None and order > resolved:
        raise GearsymError(f"{option('harmonics', order)}: these data resolve orders up to {resolved} (an order n "
                           f"takes more than 2n samples a forcing period; the sparsest record has {sparsest:.3g})")
    return order


def _check_one_value_each(measurements: Measurements, fit: Sequence[str]) -> None:
    """A fit estimates one value of each parameter for all records: refuse one the records set differently."""
    for name in fit:
        values = {r.conditions[name] for r in measurements if name in r.conditions}
        if len(values) > 1:
            shown = ", ".join(f"{v:g}" for v in sorted(values))
            raise GearsymError(f"cannot fit {name}: the records set it to different values ({shown}) and a fit "
                               f"estimates one value for all; leave it out of {caller_name('fit')}, or explain one "
                               f"record (or records of one {name}) at a time")


def _lag1(prediction: Prediction) -> float:
    """Lag-1 autocorrelation of the held-out residual, within each predicted period (averaged over channels)."""
    values = []
    for k, r in prediction.residual.items():
        r = r - r.mean()
        pieces = np.array_split(r, prediction.pairs)
        num = sum(float(p[1:] @ p[:-1]) for p in pieces)
        den = sum(float(p @ p) for p in pieces)
        values.append(num / den if den > 0 else 0.0)
    return float(np.mean(values))
