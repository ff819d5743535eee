"""Shaft-order effects of the data loop: a local tooth fault, an eccentric gear and spacing errors, on a named gear.

They are the declaration stage's terms (:mod:`gearsym.model.shaft_orders`, which :mod:`gearsym.model.faults`
adds to a drivetrain), built here for a gear of a mesh of the system (its name and tooth count from the
system's couplings, ``Coupling.gears``), with parameters whose value 0 switches them off:

=====================================  =================================================================
``tooth_fault_<gear>``                  k(tau) -> k(tau) (1 - q_<gear> s_n(phi)): the pair of tooth n loses the
                                        fraction q_<gear> of its stiffness while in mesh (0 <= q < 1); the tooth
                                        ``tooth_<gear>`` (counted from tau = 0) is not fitted but found by a scan
                                        over the gear's teeth (:mod:`.tooth_scan`)
``spall_<gear>``                        k(tau) -> k(tau) (1 - w_<gear> s_n(phi) P_n(phi)): pitting or a spall takes the
                                        fraction w_<gear> of the face width of tooth n's pair over the middle of its
                                        path of contact (P_n: from 30 % to 70 % of it, around the pitch point, where
                                        pitting starts), the tooth ``spall_tooth_<gear>`` found by the same scan
``eccentricity_<gear>``                 g(x - e) with e = e_c_<gear> cos(phi/Z) + e_s_<gear> sin(phi/Z): a
                                        transmission error at the gear's shaft order (eccentricity, run-out),
                                        reported as amplitude and phase
``spacing_errors_<gear>``               g(x - e) with e = s<n>_<gear> while tooth n carries the load (n < Z,
                                        and minus their sum for tooth Z: a constant error is no spacing error);
                                        Z - 1 parameters, so in the library only when named
=====================================  =================================================================

Each needs its gear's revolution: the system they are added to repeats on it (its ``period`` and ``cycles``
grow to the revolution, or the hunting period), and a record shorter than one revolution of the gear cannot
show it (:func:`revolution_length`).
"""
from __future__ import annotations

import math
import re

import sympy as sp

from ..errors import GearsymError
from ..model.shaft_orders import DEFAULT_EDGE, path_window, tooth_by_tooth, tooth_share, window
from ..model.stiffness import DEFAULT_CONTACT_RATIO
from ..model.symbols import parameter_symbol
from ..parameters import Constraint
from ..system import FirstOrderSystem
from .effect_types import Change, Effect, Site

#: the shaft-order families, by the prefix of their names
KINDS = ("tooth_fault", "spall", "eccentricity", "spacing_errors")
#: the kinds in the default library (spacing errors have a parameter per tooth: only when named)
DEFAULT_KINDS = ("tooth_fault", "spall", "eccentricity")
_NAME = re.compile(r"^(?P<kind>tooth_fault|spall|eccentricity|spacing_errors)_(?P<gear>.+)$")
_TAKES = "a tooth fault takes stiffness away from its pair: 0 <= q < 1"
_LOSES = "a spall takes contact width away: 0 <= w < 1"
#: the part of a pair's path of contact a spall of the library covers (fractions of the path, 0 where it enters)
SPALL_PATH = (0.3, 0.7)


def _p(name: str) -> sp.Symbol:
    return parameter_symbol(name)


def tooth_fault(gear: str, teeth: int, coordinate: str) -> Effect:
    q, n = f"q_{gear}", f"tooth_{gear}"

    def build(s: Site) -> Change:
        share = tooth_share(s.phase, teeth, _p(n), DEFAULT_CONTACT_RATIO, DEFAULT_EDGE)
        return Change(law=-_p(q) * share * s.stiffness * s.backlash / s.omega**2)

    return Effect(f"tooth_fault_{gear}", f"a local fault of one tooth of {gear} ({teeth} teeth): its pair loses the "
                  f"fraction {q} of its stiffness while in mesh, k(1 - {q} s_{n}(phi))", (q,), {n: 1.0}, build,
                  bounds={q: (0.0, 0.95, _TAKES)}, coordinate=coordinate, gear=gear, teeth=teeth, scan=n,
                  constraints={q: Constraint(f"the fraction of stiffness a fault of a tooth of {gear} takes from its "
                                             "pair", True, below=1.0),
                               n: Constraint(f"the faulty tooth of {gear} (counted from tau = 0)", whole=(1, teeth))})


def spall(gear: str, teeth: int, coordinate: str) -> Effect:
    w, n = f"ws_{gear}", f"spall_tooth_{gear}"

    def build(s: Site) -> Change:
        share = tooth_share(s.phase, teeth, _p(n), DEFAULT_CONTACT_RATIO, DEFAULT_EDGE)
        part = path_window(s.phase, teeth, _p(n), DEFAULT_CONTACT_RATIO, *SPALL_PATH, DEFAULT_EDGE)
        return Change(law=-_p(w) * share * part * s.stiffness * s.backlash / s.omega**2)

    return Effect(f"spall_{gear}", f"pitting or a spall on one tooth of {gear} ({teeth} teeth): its pair loses the "
                  f"fraction {w} of its face width over {SPALL_PATH[0]:.0%}-{SPALL_PATH[1]:.0%} of its path of contact",
                  (w,), {n: 1.0}, build, bounds={w: (0.0, 0.95, _LOSES)}, coordinate=coordinate, gear=gear,
                  teeth=teeth, scan=n)


def eccentricity(gear: str, teeth: int, coordinate: str) -> Effect:
    a, b = f"e_c_{gear}", f"e_s_{gear}"

    def build(s: Site) -> Change:
        angle = s.phase / teeth
        return Change(contact=s.coupling.contact - (_p(a) * sp.cos(angle) + _p(b) * sp.sin(angle)))

    return Effect(f"eccentricity_{gear}", f"eccentricity or run-out of {gear} ({teeth} teeth): a transmission error "
                  f"{a} cos(phi/{teeth}) + {b} sin(phi/{teeth}) at its shaft order", (a, b), {}, build,
                  pairs=((a, b),), coordinate=coordinate, gear=gear, teeth=teeth)


def spacing_errors(gear: str, teeth: int, coordinate: str) -> Effect:
    names = tuple(f"s{n}_{gear}" for n in range(1, teeth))

    def build(s: Site) -> Change:
        errors = [_p(name) for name in names]
        errors.append(-sp.Add(*errors))
        edge = (sp.nsimplify(DEFAULT_CONTACT_RATIO) - 1) / 2
        return Change(contact=s.coupling.contact - tooth_by_tooth(s.phase, teeth, errors, edge))

    return Effect(f"spacing_errors_{gear}", f"tooth spacing errors of {gear} ({teeth} teeth): a transmission error "
                  f"s<n>_{gear} while tooth n carries the load (tooth {teeth}: minus the sum of the others)", names,
                  {}, build, coordinate=coordinate, gear=gear, teeth=teeth)


BUILDERS = {"tooth_fault": tooth_fault, "spall": spall, "eccentricity": eccentricity, "spacing_errors": spacing_errors}


def geared(system: FirstOrderSystem) -> list[tuple[str, int, str]]:
    """(gear, teeth, mesh coordinate) of every gear with a tooth count in a mesh of ``system`` that has a coordinate
    of its own, in the order of the meshes."""
    out = []
    for c in system.couplings:
        if c.kind == "mesh" and not c.closes_loop:
            out += [(g.gear, g.teeth, c.coordinate) for g in c.gears if g.teeth]
    return out


def shaft_effects(system: FirstOrderSystem, kinds=DEFAULT_KINDS) -> dict[str, Effect]:
    """The shaft-order effects of ``kinds`` on every gear of ``system`` that has a tooth count, by name."""
    out = {}
    for gear, teeth, coordinate in geared(system):
        for kind in kinds:
            e = BUILDERS[kind](gear, teeth, coordinate)
            out[e.name] = e
    return out


def is_shaft_effect(name) -> bool:
    """Whether ``name`` names a shaft-order effect (``tooth_fault_gear2``), whatever the model."""
    return isinstance(name, str) and _NAME.match(name) is not None


def shaft_effect(name: str, system: FirstOrderSystem | None) -> Effect | None:
    """The shaft-order effect called ``name`` (``tooth_fault_gear2``) in ``system``, ``KIND`` for every gear's (a
    list), or None if ``name`` is no shaft-order effect's; an error names the gears there are."""
    match = _NAME.match(str(name))
    if match is None:
        return None
    gears = geared(system) if system is not None else []
    for gear, teeth, coordinate in gears:
        if gear == match["gear"]:
            return BUILDERS[match["kind"]](gear, teeth, coordinate)
    known = ", ".join(g for g, _, _ in gears) or "none"
    raise GearsymError(f"{name}: {match['gear']!r} is not a gear with a tooth count in "
                       f"{system.name if system is not None else 'this model'} (gears with teeth: {known}); give a "
                       "model that declares Gear(..., teeth=Z), or --teeth Z1,Z2 (teeth=(Z1, Z2))")


def revolution_length(e: Effect, system: FirstOrderSystem) -> float:
    """One revolution of the effect's gear (of the larger of its gears) in the system's time: Z mesh periods."""
    c = next(c for c in system.couplings if c.coordinate == e.coordinate)
    return 2 * math.pi * max(teeth for _, teeth in e.revolutions) / float(c.order or 1)


def with_revolution(system: FirstOrderSystem, e: Effect) -> tuple[sp.Expr, int]:
    """The period and cycles of ``system`` once ``e``'s gears' revolutions are added: the least common multiple of
    the system's period and the revolutions, in forcing periods."""
    forcing = system.period / system.cycles
    c = next(c for c in system.couplings if c.coordinate == e.coordinate)
    cycles = system.cycles
    for _, teeth in e.revolutions:
        revolution = 2 * sp.pi * teeth / (c.order or sp.S.One)
        ratio = sp.nsimplify(revolution / forcing)
        if not ratio.is_Rational:
            raise GearsymError(f"{e.name}: the gear's revolution {revolution} is no rational multiple of the forcing "
                               f"period {forcing}")
        cycles = int(sp.ilcm(cycles, sp.Rational(ratio).p))
    return forcing * cycles, cycles


def tooth_window(phase: sp.Expr, teeth: int, tooth) -> sp.Expr:
    """Where the pair of ``tooth`` is in mesh, about 1 (for the reports' figures)."""
    return window(phase, teeth, tooth - sp.Rational(1, 2), DEFAULT_CONTACT_RATIO, DEFAULT_EDGE)
