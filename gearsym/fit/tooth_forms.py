"""The tooth-by-tooth forms of the data loop: a fault of any window shape, as the teeth that stand out.

The named faults (:mod:`.shaft_effects`) each assume a shape: a tooth fault takes its pair's share of the stiffness,
a spall part of its path, spacing errors a transmission error per tooth. A fault whose window is shaped otherwise
(a crack that softens the whole mesh while its tooth is in mesh, two neighbouring teeth, a spall's short window) is
fitted by neither. The general forms give every tooth of both gears of a mesh a parameter of its own, Z1 + Z2 in all,
fitted together, regularised (each with a prior spread, :attr:`Effect.prior`: the data decide where they speak, the
prior where they cannot, e.g. a change shared by every tooth of one gear and taken back by every tooth of the other,
which no record can tell from nothing), with their uncertainties; the fault shows as the teeth that stand out
(:func:`standing_out`):

===============================  ===================================================================================
``tooth_stiffness_<g1>_<g2>``    k(phi) (1 - sum_n q_n W_n(phi)): while tooth n of either gear is in mesh (its window
                                 W_n, the contact ratio's mesh periods, tanh edges 0.1 mesh periods wide), the mesh
                                 stiffness is scaled by 1 - q_n; parameters ``kt<n>_<gear>``, prior spread 0.1
``tooth_profile_<g1>_<g2>``      g(x - e), e = sum_n e_n B_n(phi): a transmission error e_n while tooth n carries the
                                 load (B_n: its mesh period, blended over the double contact, as spacing errors);
                                 parameters ``te<n>_<gear>``, prior spread 0.1 of the mesh coordinate's spread
===============================  ===================================================================================

Teeth are counted from tau = 0 in the model, as the named faults' (:mod:`.tooth_scan`); the report counts them from
each record's start.

**How the fit sees them** (:func:`local_effect`, :class:`Slots`). Written out, a form is Z1 + Z2 windows in the mesh
law, each with a parameter of its own; compiled with a column function per parameter, that cost 139 s for a 9/13 pair
(and a 20/53 pair's 146 windows more). But a fit's window is one forcing period, in which only a few teeth of each
gear are in mesh: the model the fit compiles has, per gear, S *slots* (a window each, at the teeth first, first + 1,
..., first + S - 1, ``first`` a parameter set per fitting window) whose values are the fitted per-tooth parameters of
those teeth, mapped window by window (:class:`gearsym.fit.problem.Problem`'s ``slots``). The report and the derived
model carry the written-out form.
"""
from __future__ import annotations

import numpy as np
import sympy as sp

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..model.shaft_orders import DEFAULT_EDGE, tooth_by_tooth, window
from ..model.stiffness import DEFAULT_CONTACT_RATIO
from ..model.symbols import parameter_symbol
from .effect_types import Change, Effect, Site

#: the general forms, by the prefix of their names
GENERAL_KINDS = ("tooth_stiffness", "tooth_profile")
#: the prior spread of a tooth's stiffness factor (a fraction of the mesh stiffness) and of its profile error (times
#: the mesh coordinate's spread)
STIFFNESS_PRIOR = 0.1
PROFILE_PRIOR = 0.1
#: a tooth stands out if its estimate lies this many standard errors from its gear's median ...
STANDOUT_SIGMAS = 5.0
#: ... and is at least this fraction of the largest departure from the median among all teeth of the mesh
STANDOUT_FRACTION = 0.3
#: edge widths beyond a tooth's window (past the middle of its edge) where it still counts: the tanh edge is down to
#: 5e-5 there
REACH = 2.5
_BOUND = "a tooth's stiffness factor 1 - q stays positive and below twice the mesh's: -0.95 <= q <= 0.95"


def _p(name: str) -> sp.Symbol:
    return parameter_symbol(name)


def stiffness_names(gear: str, teeth: int) -> tuple[str, ...]:
    return tuple(f"kt{n}_{gear}" for n in range(1, teeth + 1))


def profile_names(gear: str, teeth: int) -> tuple[str, ...]:
    return tuple(f"te{n}_{gear}" for n in range(1, teeth + 1))


def tooth_stiffness(gears: tuple[tuple[str, int], ...], coordinate: str) -> Effect:
    """Every tooth's stiffness factor on both gears of the mesh of ``coordinate``."""
    names = {gear: stiffness_names(gear, teeth) for gear, teeth in gears}

    def build(s: Site) -> Change:
        loss = sp.Add(*(_p(name) * window(s.phase, teeth, n - sp.Rational(1, 2), DEFAULT_CONTACT_RATIO, DEFAULT_EDGE)
                        for gear, teeth in gears for n, name in enumerate(names[gear], 1)))
        return Change(law=-loss * s.stiffness * s.backlash / s.omega**2)

    fitted = tuple(p for gear, _ in gears for p in names[gear])
    label = "_".join(g for g, _ in gears)
    return Effect(f"tooth_stiffness_{label}", "every tooth's stiffness factor: the mesh stiffness times 1 - kt<n>_<gear> "
                  f"while tooth n is in mesh ({' + '.join(str(t) for _, t in gears)} parameters, regularised)", fitted,
                  {}, build, bounds={p: (-0.95, 0.95, _BOUND) for p in fitted}, coordinate=coordinate,
                  gears=tuple(gears), prior=STIFFNESS_PRIOR)


def tooth_profile(gears: tuple[tuple[str, int], ...], coordinate: str) -> Effect:
    """Every tooth's profile error on both gears of the mesh of ``coordinate``."""
    names = {gear: profile_names(gear, teeth) for gear, teeth in gears}

    def build(s: Site) -> Change:
        edge = (sp.nsimplify(DEFAULT_CONTACT_RATIO) - 1) / 2
        error = sp.Add(*(tooth_by_tooth(s.phase, teeth, [_p(p) for p in names[gear]], edge) for gear, teeth in gears))
        return Change(contact=s.coupling.contact - error)

    fitted = tuple(p for gear, _ in gears for p in names[gear])
    label = "_".join(g for g, _ in gears)
    return Effect(f"tooth_profile_{label}", "every tooth's profile error: a transmission error te<n>_<gear> while "
                  f"tooth n carries the load ({' + '.join(str(t) for _, t in gears)} parameters, regularised)", fitted,
                  {}, build, coordinate=coordinate, gears=tuple(gears), prior=PROFILE_PRIOR,
                  prior_unit="displacement")


BUILDERS = {"tooth_stiffness": tooth_stiffness, "tooth_profile": tooth_profile}


def general_forms(system, kinds=GENERAL_KINDS) -> dict[str, Effect]:
    """The tooth-by-tooth forms of ``kinds`` on every mesh of ``system`` whose two gears have tooth counts."""
    out = {}
    for c in system.couplings:
        if c.kind == "mesh" and not c.closes_loop and len(c.gears) == 2 and all(g.teeth for g in c.gears):
            gears = tuple((g.gear, int(g.teeth)) for g in c.gears)
            for kind in kinds:
                e = BUILDERS[kind](gears, c.coordinate)
                out[e.name] = e
    return out


def is_general(e: Effect) -> bool:
    return bool(e.gears)


def tooth_values(e: Effect, estimates: dict, stderr: dict) -> dict[str, list[tuple[float, float | None]]]:
    """gear -> [(estimate, standard error), ...] tooth by tooth (counted from tau = 0)."""
    out = {}
    for gear, teeth in e.gears:
        names = stiffness_names(gear, teeth) if e.name.startswith("tooth_stiffness") else profile_names(gear, teeth)
        out[gear] = [(float(estimates[p]), stderr.get(p)) for p in names]
    return out


def standing_out(values: dict[str, list[tuple[float, float | None]]]) -> dict[str, list[int]]:
    """gear -> the teeth (1 ... Z, from tau = 0) whose value departs from the gear's median by at least
    ``STANDOUT_SIGMAS`` standard errors and ``STANDOUT_FRACTION`` of the largest departure in the mesh."""
    medians = {g: float(np.median([v for v, _ in vs])) for g, vs in values.items()}
    largest = max((abs(v - medians[g]) for g, vs in values.items() for v, _ in vs), default=0.0)
    out = {}
    for gear, vs in values.items():
        out[gear] = [n for n, (v, err) in enumerate(vs, 1)
                     if largest > 0 and abs(v - medians[gear]) >= STANDOUT_FRACTION * largest
                     and err is not None and abs(v - medians[gear]) >= STANDOUT_SIGMAS * err]
    return out


# --------------------------------------------------------------------------- the fit's local form
@dataclass(frozen=True)
class Slots:
    """One gear of a tooth-by-tooth form as the fit's compiled model has it: ``slots`` parameters, the windows of
    teeth first, first + 1, ... (``first`` a parameter set per fitting window), standing for the per-tooth
    parameters ``teeth_names`` (1 ... Z). ``order``: the mesh's order (mesh periods per unit tau / 2 pi);
    ``period``: the fitting window's length in tau, two of which a slot set covers (a fit window, and a held-out
    prediction's two)."""

    gear: str
    teeth: int
    first: str
    slots: tuple[str, ...]
    teeth_names: tuple[str, ...]
    order: float
    period: float
    reach: float  # mesh periods from a tooth's in-mesh window's middle to where it no longer counts

    def first_tooth(self, t0: float) -> int:
        """The first tooth (counted from tau = 0, unwrapped) in mesh within two windows from ``t0``."""
        return math.ceil(self.order * t0 / (2 * math.pi) + 0.5 - self.reach)

    def teeth_of(self, first: int) -> np.ndarray:
        """The 0-based index among ``teeth_names`` of each slot's tooth."""
        return (first + np.arange(len(self.slots)) - 1) % self.teeth


def slot_count(order: float, period: float, reach: float) -> int:
    """Slots a gear needs so that every tooth in mesh within two fitting windows has one, its window reaching
    ``reach`` mesh periods from its middle."""
    span = 2 * order * period / (2 * math.pi)
    return math.ceil(span + 2 * reach) + 1


def local_effect(e: Effect, order: float, period: float) -> tuple[Effect, tuple[Slots, ...]]:
    """The form the fit compiles for the tooth-by-tooth form ``e`` (see the module docstring) and its slots."""
    stiffness = e.name.startswith("tooth_stiffness")
    profile_edge = (float(DEFAULT_CONTACT_RATIO) - 1) / 2
    reach = (float(DEFAULT_CONTACT_RATIO) / 2 + REACH * float(DEFAULT_EDGE) if stiffness
             else 0.5 + REACH * profile_edge)
    count = slot_count(order, period, reach)
    stiffness = e.name.startswith("tooth_stiffness")
    prefix = "kt" if stiffness else "te"
    # (a gear of no more teeth than slots has each tooth once: its windows repeat every revolution)
    slots = tuple(Slots(gear, teeth, f"{prefix}first_{gear}",
                        tuple(f"{prefix}slot{j}_{gear}" for j in range(min(count, teeth))),
                        (stiffness_names if stiffness else profile_names)(gear, teeth), order, period, reach)
                  for gear, teeth in e.gears)

    def build(s: Site) -> Change:
        if stiffness:
            loss = sp.Add(*(_p(name) * window(s.phase, sl.teeth, _p(sl.first) + j - sp.Rational(1, 2),
                                              DEFAULT_CONTACT_RATIO, DEFAULT_EDGE)
                            for sl in slots for j, name in enumerate(sl.slots)))
            return Change(law=-loss * s.stiffness * s.backlash / s.omega**2)
        edge = (sp.nsimplify(DEFAULT_CONTACT_RATIO) - 1) / 2
        error = sp.Add(*(_p(name) * window(s.phase, sl.teeth, _p(sl.first) + j - sp.Rational(1, 2), 1, edge)
                         for sl in slots for j, name in enumerate(sl.slots)))
        return Change(contact=s.coupling.contact - error)

    fixed = {**{sl.first: 1.0 for sl in slots}, **{name: 0.0 for sl in slots for name in sl.slots}}
    return replace(e, fitted=(), fixed=fixed, build=build, bounds={}), slots


def place_slots(segments: Sequence, slots: Sequence[Slots], estimates: dict | None = None) -> list:
    """``segments`` with each gear's first tooth set (and, given the per-tooth ``estimates``, its slots' values)."""
    out = []
    for seg in segments:
        values = {}
        for sl in slots:
            first = sl.first_tooth(float(seg.tau[0]))
            values[sl.first] = float(first)
            if estimates is not None:
                for name, k in zip(sl.slots, sl.teeth_of(first)):
                    values[name] = float(estimates.get(sl.teeth_names[k], 0.0))
        out.append(replace(seg, parameters={**seg.parameters, **values}))
    return out
