"""Physical effects a drivetrain model may lack, each a term the symbolic model can declare, in its general form.

An effect acts where its physics acts, read from the couplings the reduction hands on with the
system (:class:`~gearsym.system.Coupling`), never from the equations' text:

* on a **coupling's force** (a mesh or a shaft). The coupling's law in its own coordinate x (rate
  v), in the tau-form ``2 zeta v/omega + k(tau) g(x, eta)/omega^2`` for a mesh, enters the velocity
  equation of each of its rows as ``-factor * law``. An effect changes the law by a term, or shifts
  the contact x -> x - e(tau), and so acts in *every* row that force enters, with that row's factor
  (the flexible shaft's mesh force also drives v2, through beta_3);
* on the **driving torque**: where the mean torque B0 enters, with the same factor (df/dB0);
* on the **acceleration of the mesh coordinate**, its own row only: a term the user writes
  (:func:`term_effect`, ``gearsym explain --add-term``) or the data propose.

Every effect adds parameters whose value 0 switches it off:

===========================  ======================================================================
coulomb_friction             law + mu_c v/sqrt(v^2 + eps_c^2)/omega^2: tooth friction, sign(v) regularised
nonlinear_damping            law + c_nl v sqrt(v^2 + eps_nl^2): damping growing with the speed, v|v|
                             made smooth (located crossings refuse Abs of the state, and a smooth term
                             keeps the derived model on the default scheme and RK4 at its order)
cubic_stiffness              law + k(tau) k3 g^3/omega^2: contact hardening
hertzian_contact             law + k(tau) k_hz g (g^2 + eps_hz^2)^(1/4)/omega^2: the g^(3/2) of Hertz
                             contact, its |g| made smooth likewise
coast_side_stiffness         law + c_coast k(tau) min(g, 0)/omega^2: another stiffness on the x <= -eta flank
shaft_damping                a shaft's law + c_sh v/omega (models with shafts)
mesh_stiffness_harmonic_N    k(phi) + k_cN cos(N phi) + k_sN sin(N phi): an additive Fourier term of the
                             mesh stiffness of any order N (phi: the mesh phase, the mesh order times tau)
torque_harmonic_N            the torque + B_cN cos(N tau) + B_sN sin(N tau)
transmission_error_N         g(x - e, eta), e = e_cN cos(N phi) + e_sN sin(N phi): a profile error
===========================  ======================================================================

Signs are physics, kept as bounds in the fit (:attr:`Effect.bounds`): friction and damping
dissipate (mu_c, c_nl, c_sh >= 0), a stiffness is positive (k3, k_hz >= 0, and the coast flank's
(1 + c_coast) k(tau)). Each harmonic's (cos, sin) pair is reported as an amplitude >= 0 and a phase in
(-pi, pi]: A cos(N phi + theta) (:attr:`Effect.pairs`).

:func:`augment` returns a new :class:`~gearsym.system.FirstOrderSystem` with the terms added (named
``one_stage_with_cubic_stiffness``); :func:`effect_terms` gives what each adds to each equation.
"""
from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import sympy as sp

from ..model.backlash import g
from ..errors import GearsymError, ModelError, suggest
from ..model.expressions import to_expr
from ..model.symbols import parameter_symbol
from ..system import FirstOrderSystem
from .effect_types import Change, Effect, Site, site
from .shaft_effects import KINDS as SHAFT_KINDS, shaft_effect, with_revolution
from .tooth_forms import GENERAL_KINDS

INF = math.inf


def _p(name: str) -> sp.Symbol:
    return parameter_symbol(name)


def _coulomb(s: Site) -> Change:
    v, eps = s.v, _p("eps_c")
    return Change(law=_p("mu_c") * v / sp.sqrt(v**2 + eps**2) / s.omega**2)


def _nonlinear_damping(s: Site) -> Change:
    v = s.v
    return Change(law=_p("c_nl") * v * sp.sqrt(v**2 + _p("eps_nl") ** 2))


def _cubic(s: Site) -> Change:
    return Change(law=s.stiffness * _p("k3") * s.backlash**3 / s.omega**2)


def _hertzian(s: Site) -> Change:
    gx = s.backlash
    return Change(law=s.stiffness * _p("k_hz") * gx * (gx**2 + _p("eps_hz") ** 2) ** sp.Rational(1, 4) / s.omega**2)


def _coast(s: Site) -> Change:
    return Change(law=_p("c_coast") * s.stiffness * sp.Min(s.backlash, 0) / s.omega**2)


def _shaft_damping(s: Site) -> Change:
    return Change(law=_p("c_sh") * s.v / s.omega)


_DISSIPATES = "a damping or friction dissipates: its force opposes the motion"
_STIFF = "a stiffness is positive"

EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect("coulomb_friction", "tooth friction opposing the sliding velocity, sign(v) regularised over eps_c",
           ("mu_c",), {"eps_c": 0.05}, _coulomb, bounds={"mu_c": (0.0, INF, _DISSIPATES)}),
    Effect("nonlinear_damping", "damping growing with the speed: c_nl v|v|, smoothed as c_nl v sqrt(v^2 + eps_nl^2)",
           ("c_nl",), {"eps_nl": 0.01}, _nonlinear_damping, bounds={"c_nl": (0.0, INF, _DISSIPATES)}),
    Effect("cubic_stiffness", "contact hardening: mesh force k(tau) (g + k3 g^3)", ("k3",), {}, _cubic,
           bounds={"k3": (0.0, INF, _STIFF + " (contact hardens)")}),
    Effect("hertzian_contact", "Hertz contact: mesh force k(tau) (g + k_hz g |g|^(1/2)), |g| smoothed over eps_hz",
           ("k_hz",), {"eps_hz": 0.01}, _hertzian, bounds={"k_hz": (0.0, INF, _STIFF)}),
    Effect("coast_side_stiffness", "another stiffness on the coast flank: + c_coast k(tau) min(g, 0)",
           ("c_coast",), {}, _coast, bounds={"c_coast": (-1.0, INF, _STIFF + ": the coast flank's (1 + c_coast) k")}),
    Effect("shaft_damping", "damping of a shaft: its law + c_sh v/omega", ("c_sh",), {}, _shaft_damping,
           acts_on="shaft", bounds={"c_sh": (0.0, INF, _DISSIPATES)}),
)}


def _stiffness_harmonic(n: int) -> Effect:
    a, b = f"k_c{n}", f"k_s{n}"

    def build(s: Site) -> Change:
        added = _p(a) * sp.cos(n * s.phase) + _p(b) * sp.sin(n * s.phase)
        return Change(law=added * s.backlash / s.omega**2)

    return Effect(f"mesh_stiffness_harmonic_{n}", f"order-{n} Fourier term of the mesh stiffness: k(phi) + {a} "
                  f"cos({n} phi) + {b} sin({n} phi)", (a, b), {}, build, pairs=((a, b),), order=n)


def _torque_harmonic(n: int) -> Effect:
    a, b = f"B_c{n}", f"B_s{n}"

    def build(s: Site) -> Change:
        return Change(torque=_p(a) * sp.cos(n * s.time) + _p(b) * sp.sin(n * s.time))

    return Effect(f"torque_harmonic_{n}", f"order-{n} harmonic of the driving torque: + {a} cos({n} tau) + {b} "
                  f"sin({n} tau)", (a, b), {}, build, acts_on="torque", pairs=((a, b),), order=n)


def _transmission_error(n: int) -> Effect:
    a, b = f"e_c{n}", f"e_s{n}"

    def build(s: Site) -> Change:
        e = _p(a) * sp.cos(n * s.phase) + _p(b) * sp.sin(n * s.phase)
        return Change(contact=s.coupling.contact - e)

    return Effect(f"transmission_error_{n}", f"order-{n} transmission error e = {a} cos({n} phi) + {b} sin({n} phi): "
                  "g(x - e)", (a, b), {}, build, pairs=((a, b),), order=n)


#: effects of any order N, named FAMILY_N
FAMILIES: dict[str, Callable[[int], Effect]] = {
    "mesh_stiffness_harmonic": _stiffness_harmonic,
    "torque_harmonic": _torque_harmonic,
    "transmission_error": _transmission_error,
}
_ORDERED = re.compile(r"^(?P<family>[a-z_]+?)_(?P<order>[0-9]+)$")


def effect(name: str | Effect, system: FirstOrderSystem | None = None) -> Effect:
    """The effect called ``name``: one of :data:`EFFECTS`, a family of :data:`FAMILIES` with its order, or a
    shaft-order effect on a gear of ``system`` (``tooth_fault_gear2``, :mod:`.shaft_effects`)."""
    if isinstance(name, Effect):
        return name
    if name in EFFECTS:
        return EFFECTS[name]
    shaft = shaft_effect(name, system)
    if shaft is not None:
        return shaft
    match = _ORDERED.match(str(name))
    if match and match["family"] in FAMILIES:
        order = int(match["order"])
        if order < 1:
            raise GearsymError(f"{name}: the order of a harmonic is 1 or more")
        return FAMILIES[match["family"]](order)
    if name in FAMILIES:
        raise GearsymError(f"{name} needs its order: {name}_2 is the second harmonic (any order 1, 2, ...)")
    known = library_names()
    raise GearsymError(f"unknown effect {name!r}.{suggest(str(name), known)} Effects: {', '.join(known)}")


def library_names() -> list[str]:
    """Every effect's name as the user writes it (families with _N, shaft-order effects with _GEAR)."""
    return [*EFFECTS, *(f"{f}_N" for f in FAMILIES), *(f"{k}_GEAR" for k in SHAFT_KINDS), *GENERAL_KINDS]


def applies_to(system: FirstOrderSystem, e: Effect, coordinate: str | None = None) -> bool:
    """Whether ``system`` has where ``e`` acts (a shaft for shaft damping, B0 for a torque harmonic)."""
    try:
        site(system, e.acts_on, coordinate)
    except ModelError:
        return False
    return True


def augment(system: FirstOrderSystem, effects: Sequence[str | Effect], coordinate: str | None = None,
            values: Mapping[str, float] | None = None, name: str | None = None) -> FirstOrderSystem:
    """``system`` with the effects' terms added; their parameters start at 0 (off) or ``values``.
    ``name``: the new system's (default ``<model>_with_<effect>_and_<effect>``)."""
    chosen = [effect(e, system) for e in effects]
    if not chosen:
        if values:
            raise GearsymError("values given for effects, but no effect named")
        return system
    if len({e.name for e in chosen}) != len(chosen):
        raise GearsymError("an effect is named twice")
    out = system
    for e in chosen:
        clash = set(e.parameters) & set(out.parameters)
        if clash:
            raise ModelError(f"effect {e.name}: the model already has parameters {sorted(clash)}", system.name)
        out = _apply(out, e, coordinate)
    parameters = dict(out.parameters)
    out = replace(out, constraints={**out.constraints, **{k: c for e in chosen for k, c in e.constraints.items()}})
    for key, value in (values or {}).items():
        if key not in parameters:
            raise GearsymError(f"{key} is not a parameter of {system.name} or of the effects "
                               f"{', '.join(e.name for e in chosen)}")
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise GearsymError(f"{key}={value!r}: an effect's parameter takes a number") from None
        parameters[key] = out.check_value(key, number)  # (a tooth fault's depth below 1, its tooth a tooth)
    descriptions = {**system.descriptions, **{p: f"{e.name}: {e.description}" for e in chosen for p in e.parameters}}
    for e in chosen:
        if e.shaft_order:  # the system now repeats on the gear's revolution (or the hunting period)
            period, cycles = with_revolution(out, e)
            out = replace(out, period=period, cycles=cycles)
    return replace(out, name=name or _name(system.name, [e.name for e in chosen]), parameters=parameters,
                   descriptions=descriptions, title=f"{system.title or system.name}, with "
                                                    f"{', '.join(e.name for e in chosen)}")


def _name(base: str, effects: list[str]) -> str:
    """``<model>_with_<a>_and_<b>``: a C identifier (the model may be compiled), shortened when long."""
    name = f"{base}_with_{'_and_'.join(effects)}"
    if len(name) <= 80:
        return name
    return f"{base}_with_{len(effects)}_effects_{hashlib.sha256(name.encode()).hexdigest()[:10]}"


def _apply(system: FirstOrderSystem, e: Effect, coordinate: str | None) -> FirstOrderSystem:
    s = site(system, e.acts_on, e.coordinate or coordinate)
    change = e.build(s)
    rhs, couplings = list(system.rhs), list(system.couplings)
    if change.contact is not None:
        old, new = s.backlash, g(change.contact, s.coupling.backlash)
        if s.coupling.backlash != 0:
            rhs = [f.xreplace({old: new}) for f in rhs]
        else:  # g(x, 0) = x is already evaluated away: the shift enters as a change of the law
            change = replace(change, law=change.law + s.stiffness * (new - old) / s.omega**2)
        i = couplings.index(s.coupling)
        couplings[i] = replace(s.coupling, contact=change.contact)
    for row, factor in s.rows:
        if s.kind == "torque":
            rhs[row] = rhs[row] + factor * change.torque
        else:
            rhs[row] = rhs[row] - factor * change.law
    if change.own != 0:
        rhs[s.own_row] = rhs[s.own_row] + change.own
    return replace(system, rhs=tuple(rhs), parameters={**system.parameters, **e.parameters},
                   couplings=tuple(couplings))


def effect_terms(system: FirstOrderSystem, effects: Sequence[str | Effect], coordinate: str | None = None
                 ) -> dict[str, dict[str, sp.Expr]]:
    """What each effect adds to each equation of ``system``: effect name -> {state: term of d state/dtau}."""
    out = {}
    for e in (effect(name, system) for name in effects):
        augmented = _apply(system, e, coordinate)
        out[e.name] = {s.name: new - old for s, new, old in zip(system.states, augmented.rhs, system.rhs)
                       if new != old}
    return out


def bounds_of(effects: Sequence[str | Effect], system: FirstOrderSystem | None = None
              ) -> dict[str, tuple[float, float, str]]:
    """The physical bounds of the effects' parameters, by parameter name."""
    return {k: v for e in (effect(name, system) for name in effects) for k, v in e.bounds.items()}


def term_effect(formula: str, system: FirstOrderSystem, index: int = 1, coordinate: str | None = None) -> Effect:
    """A term written by hand (or proposed by the data), as an effect: ``c_termI * (formula)`` added to dv/dtau of
    the mesh coordinate (its own row). ``formula`` goes through the safe parser only; it may use the states,
    the time, ``g`` (the mesh's g(x, eta)) and the model's parameters."""
    mesh = site(system, "mesh", coordinate)
    where = f"term {formula!r}"
    names = {s.name: s for s in system.states}
    names[system.time.name] = system.time
    if "g" in system.parameters or "g" in names:
        raise GearsymError(f"{where}: the model names something g, which a term uses for the backlash g(x, eta)")
    names["g"] = mesh.backlash
    expr = to_expr(formula, where, names)
    unknown = sorted(s.name for s in expr.free_symbols
                     if s not in set(system.states) | {system.time} and s.name not in system.parameters)
    if unknown:
        raise GearsymError(f"{where}: unknown name {unknown[0]}.{suggest(unknown[0], list(names))} A term may use the "
                           f"states ({', '.join(system.state_names)}), {system.time.name}, g (the mesh's g(x, eta)) "
                           "and the model's parameters")
    return own_term(f"term_{index}", f"c_term{index}", expr, f"a term added by hand: c_term{index} * ({formula})")


def own_term(name: str, coefficient: str, expr: sp.Expr, description: str) -> Effect:
    """An effect adding ``coefficient * expr`` to dv/dtau of the mesh coordinate (its own row only)."""

    def build(s: Site) -> Change:
        return Change(own=_p(coefficient) * expr)

    return Effect(name, description, (coefficient,), {}, build, term=expr)


def term_text(expr: sp.Expr, system: FirstOrderSystem) -> str:
    """A term as the user writes it for :func:`term_effect`: SymPy's string, with the mesh's g(x, eta) as g."""
    backlashes = {b: sp.Symbol("g") for b in expr.atoms(g)}
    return sp.sstr(expr.xreplace(backlashes))


__all__ = ["Change", "EFFECTS", "Effect", "FAMILIES", "Site", "applies_to", "augment", "bounds_of", "effect",
           "effect_terms", "library_names", "own_term", "site", "term_effect", "term_text"]
