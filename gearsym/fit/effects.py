"""Physical effects a mesh model may lack, each a term the symbolic model can declare.

An effect acts on one mesh coordinate x (velocity v = dx/dtau) of a first-order
system in the paper's tau-form, where the mesh force enters the acceleration as

    dv/dtau = ... - k(tau) g(x, eta) / omega^2 + ...

The mesh term comes from the couplings the reduction hands on with the system
(:class:`~gearsym.system.Coupling`), and each effect is built from it, so the
effects follow whatever k(tau) the model declares. Every effect adds parameters whose value 0 switches it off:

=========================  ===============================================================
coulomb_friction           tooth friction, a force opposing the sliding velocity:
                           - mu_c * v / sqrt(v^2 + eps_c^2) / omega^2 (sign(v), regularised)
cubic_stiffness            contact hardening: the mesh force k g becomes k (g + k3 g^3)
mesh_stiffness_harmonic    a second harmonic of the mesh stiffness:
                           k(tau) (1 + a_h cos 2tau + b_h sin 2tau)
transmission_error         a periodic profile error e(tau) = e_c cos tau + e_s sin tau shifts
                           the contact: g(x, eta) becomes g(x - e(tau), eta)
coast_side_stiffness       another stiffness on the coast flank (x <= -eta):
                           the mesh force k g gains c_coast k min(g, 0)
=========================  ===============================================================

:func:`augment` returns a new :class:`~gearsym.system.FirstOrderSystem` with the
terms added (named ``one_stage_with_cubic_stiffness``); :func:`effect_terms` gives the
terms themselves, for the derivation shown in reports.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import sympy as sp

from ..backlash import g
from ..errors import GearsymError, ModelError, suggest
from ..symbols import parameter_symbol
from ..system import FirstOrderSystem


@dataclass(frozen=True)
class MeshTerm:
    """Where an effect acts: the coordinate, its velocity equation and the mesh force in it."""

    system: FirstOrderSystem
    x: sp.Symbol
    v: sp.Symbol
    row: int  # index of dv/dtau in the rhs
    backlash: sp.Expr  # g(x, eta)
    coefficient: sp.Expr  # of g in dv/dtau: -k(tau)/omega^2
    omega: sp.Expr  # the frequency the tau-form divides by

    def parameter(self, name: str) -> sp.Symbol:
        return parameter_symbol(name)


@dataclass(frozen=True)
class Effect:
    """One candidate effect: its parameters (0 = off, the others fixed), and its term in dv/dtau."""

    name: str
    description: str
    fitted: tuple[str, ...]  # parameters a fit estimates (all 0: the effect is off)
    fixed: Mapping[str, float]  # parameters it needs but does not fit (e.g. a regularisation width)
    build: Callable[[MeshTerm], tuple[sp.Expr, sp.Expr | None]]  # -> (added term, new backlash or None)

    @property
    def parameters(self) -> dict[str, float]:
        return {**{p: 0.0 for p in self.fitted}, **self.fixed}


def _coulomb(m: MeshTerm):
    mu, eps = m.parameter("mu_c"), m.parameter("eps_c")
    return -mu * m.v / sp.sqrt(m.v**2 + eps**2) / m.omega**2, None


def _cubic(m: MeshTerm):
    return m.coefficient * m.parameter("k3") * m.backlash**3, None


def _harmonic(m: MeshTerm):
    tau = m.system.time
    a, b = m.parameter("a_h"), m.parameter("b_h")
    return m.coefficient * (a * sp.cos(2 * tau) + b * sp.sin(2 * tau)) * m.backlash, None


def _transmission_error(m: MeshTerm):
    tau = m.system.time
    e = m.parameter("e_c") * sp.cos(tau) + m.parameter("e_s") * sp.sin(tau)
    x, eta = m.backlash.args
    return sp.S.Zero, g(x - e, eta)


def _coast(m: MeshTerm):
    return m.coefficient * m.parameter("c_coast") * sp.Min(m.backlash, 0), None


EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect("coulomb_friction", "tooth friction opposing the sliding velocity, sign(v) regularised over eps_c",
           ("mu_c",), {"eps_c": 0.05}, _coulomb),
    Effect("cubic_stiffness", "contact hardening: mesh force k(tau) (g + k3 g^3)", ("k3",), {}, _cubic),
    Effect("mesh_stiffness_harmonic", "second harmonic of the mesh stiffness: k(tau) (1 + a_h cos 2tau + b_h sin 2tau)",
           ("a_h", "b_h"), {}, _harmonic),
    Effect("transmission_error", "periodic transmission error e(tau) = e_c cos tau + e_s sin tau: g(x - e(tau))",
           ("e_c", "e_s"), {}, _transmission_error),
    Effect("coast_side_stiffness", "another stiffness on the coast flank: + c_coast k(tau) min(g, 0)",
           ("c_coast",), {}, _coast),
)}


def effect(name: str | Effect) -> Effect:
    if isinstance(name, Effect):
        return name
    try:
        return EFFECTS[name]
    except KeyError:
        raise GearsymError(f"unknown effect {name!r}.{suggest(name, EFFECTS)} Effects: {', '.join(EFFECTS)}") from None


def mesh_term(system: FirstOrderSystem, coordinate: str | None = None) -> MeshTerm:
    """The mesh force -k(tau) g(x, eta)/omega^2 of ``coordinate`` (default: the first mesh with backlash),
    read from the couplings the reduction handed on with the system."""
    # a mesh that closes a kinematic loop has no coordinate (no row) of its own to add an effect to
    meshes = [c for c in system.couplings if c.kind == "mesh" and c.backlash != 0 and not c.closes_loop]
    chosen = [c for c in meshes if coordinate in (None, c.coordinate)]
    if not chosen:
        where = f"coordinate {coordinate!r}" if coordinate else "any coordinate"
        known = f" (meshes with backlash act on {', '.join(c.coordinate for c in meshes)})" if meshes else ""
        raise ModelError(f"no mesh force g(x, eta) acting on {where}{known}; the effects act on a backlash mesh "
                         "of a reduced drivetrain", system.name)
    mesh = chosen[0]
    omega = parameter_symbol("omega")
    if omega.name not in system.parameters:
        raise ModelError("the effects library needs the paper's tau-form (a parameter omega)", system.name)
    names = system.state_names
    row = names.index(mesh.velocity)  # its own row, where the law enters with factor 1
    x, v = system.states[names.index(mesh.coordinate)], system.states[row]
    return MeshTerm(system, x, v, row, g(mesh.contact, mesh.backlash), -mesh.stiffness / omega**2, omega)


def effect_terms(system: FirstOrderSystem, effects: Sequence[str | Effect], coordinate: str | None = None
                 ) -> dict[str, sp.Expr]:
    """The change each effect makes to dv/dtau (as an expression), by effect name."""
    m = mesh_term(system, coordinate)
    out = {}
    for e in map(effect, effects):
        added, backlash = e.build(m)
        if backlash is not None:
            added = added + m.coefficient * (backlash - m.backlash)
        out[e.name] = added
    return out


def augment(system: FirstOrderSystem, effects: Sequence[str | Effect], coordinate: str | None = None,
            values: Mapping[str, float] | None = None) -> FirstOrderSystem:
    """``system`` with the effects' terms added; their parameters start at 0 (off) or ``values``."""
    chosen = [effect(e) for e in effects]
    if not chosen:
        return system
    if len({e.name for e in chosen}) != len(chosen):
        raise GearsymError("an effect is named twice")
    m = mesh_term(system, coordinate)
    rhs = list(system.rhs)
    f = rhs[m.row]
    parameters = dict(system.parameters)
    couplings = list(system.couplings)
    for e in chosen:
        added, backlash = e.build(m)
        if backlash is not None:
            f = f.subs(m.backlash, backlash)
            i = next(i for i, c in enumerate(couplings) if c.coordinate == m.x.name)
            couplings[i] = replace(couplings[i], contact=backlash.args[0])  # the contact the mesh now has
        f = f + added
        clash = set(e.parameters) & set(system.parameters)
        if clash:
            raise ModelError(f"effect {e.name}: the model already has parameters {sorted(clash)}", system.name)
        parameters.update(e.parameters)
    rhs[m.row] = f
    for name, value in (values or {}).items():
        if name not in parameters:
            raise GearsymError(f"{name} is not a parameter of {system.name} or of the effects "
                               f"{', '.join(e.name for e in chosen)}")
        parameters[name] = float(value)
    descriptions = {**system.descriptions, **{p: f"{e.name}: {e.description}" for e in chosen for p in e.parameters}}
    name = f"{system.name}_with_{'_and_'.join(e.name for e in chosen)}"  # a C identifier: the model may be compiled
    return replace(system, name=name, rhs=tuple(rhs), parameters=parameters, descriptions=descriptions,
                   title=f"{system.title or system.name}, with {', '.join(e.name for e in chosen)}",
                   couplings=tuple(couplings))
