"""A model linearised about its static state: the linear, time-periodic system whose monodromy matrix over one
period decides the parametric stability of that state (Floquet).

For y' = f(t, y, p) the variational equation about a state y_s is q' = J(t, y_s, p) q, J = df/dy. About the
static state of a gear model (at rest under the mean loads) J is periodic in t through k(tau) and whatever else
varies with the mesh: Hill's equation, or for one mesh without backlash and damping Mathieu's. The system here is
that equation as a :class:`~gearsym.system.FirstOrderSystem` of its own, ``<model>_linearised``: the same
states, right-hand side J(t, y_s, p) y, the model's parameters plus one parameter ``<state>_static`` for each
state J depends on (the point at which it is evaluated, set per point of a chart). It compiles like any model,
its lanes run many parameter points at once, and its tangent map over one period *is* the monodromy matrix of
the linearisation (the state itself is not needed: it starts and stays at 0).

The backlash g(x, eta) is linearised by its slope at the static deflection: 1 on either flank, 0 in the gap
(and 1 at the edge x = 0 of the drive flank, g's slope from the side of contact). That is what a linearisation
can say; a mesh whose teeth separate is not linear, and ``about="orbit"`` linearises about the periodic orbit
instead.

The static state solves the equations averaged over a period (each term that varies with time replaced by its
mean: a harmonic torque by 0, k(tau) by its mean), with every rate at rest. :class:`StaticRecipe` keeps that
problem as a small CasADi function, so that a chart's static states need no SymPy.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import casadi as ca
import sympy as sp
from sympy.simplify.fu import TR8

from ..codegen.build import compile_model
from ..codegen.translate import to_casadi
from ..errors import ModelError
from ..options import Integration
from ..model.symbols import parameter_symbol
from ..system import FirstOrderSystem
from .recipe import STATIC_SUFFIX, CompiledLinearisation, StaticRecipe, anchor_parameter



@dataclass(frozen=True)
class Linearised:
    """A model's linearisation about its static state: ``system`` (the linear system), ``anchors`` (the states
    its Jacobian depends on, each carried by the parameter ``<state>_static``) and the ``static`` recipe."""

    base: str
    system: FirstOrderSystem
    anchors: tuple[str, ...]
    static: StaticRecipe

    @property
    def anchor_parameters(self) -> tuple[str, ...]:
        return tuple(anchor_parameter(s) for s in self.anchors)


def linearise(system: FirstOrderSystem) -> Linearised:
    """The linearisation of ``system`` about its static state (see the module docstring)."""
    states = tuple(system.states)
    jacobian = system.jacobian()
    anchors = tuple(s for s in states if any(s in e.free_symbols for e in jacobian))
    taken = set(system.parameters) | {s.name for s in states}
    clash = [anchor_parameter(s.name) for s in anchors if anchor_parameter(s.name) in taken]
    if clash:
        raise ModelError(f"cannot linearise: the parameter names {', '.join(clash)} are taken", system.name)
    at = {s: parameter_symbol(anchor_parameter(s.name)) for s in anchors}
    J = jacobian.xreplace(at)
    # each entry's terms (a mesh's contribution each) times its state: a term's time-free factors then separate
    # from its k(tau) into a constant (codegen/time_tables.py), so the tables depend on k(tau)'s parameters
    # alone, not on omega: a chart across omega shares them
    rhs = tuple(sp.Add(*(t * states[j] for j in range(len(states)) for t in sp.Add.make_args(J[i, j]) if t != 0))
                for i in range(len(states)))
    recipe = static_recipe(system)
    parameters = {**system.parameters, **{anchor_parameter(s.name): 0.0 for s in anchors}}
    descriptions = {**system.descriptions,
                    **{anchor_parameter(s.name): f"the static value of {s.name}, where the Jacobian is evaluated"
                       for s in anchors}}
    linear = FirstOrderSystem(
        f"{system.name}_linearised", system.time, states, rhs, parameters, system.period, descriptions,
        f"{system.title or system.name}, linearised about its static state", tuple(system.coordinates), {},
        (), dict(system.constraints), system.cycles)
    return Linearised(system.name, linear, tuple(s.name for s in anchors), recipe)


def static_recipe(system: FirstOrderSystem) -> StaticRecipe:
    """The static problem of ``system``: its right-hand side averaged over a period, the rates at rest, each
    remaining row without its parameter factors."""
    states = tuple(system.states)
    rows = [time_mean(f, system) for f in system.rhs]
    resting: dict[sp.Symbol, sp.Expr] = {}
    used: set[int] = set()
    changed = True
    while changed:  # rows c(p) * s: the state s is at rest (a rate, dx/dtau = v)
        changed = False
        for i, row in enumerate(rows):
            if i in used:
                continue
            present = row.free_symbols & set(states)
            if len(present) == 1:
                s = next(iter(present))
                if row.xreplace({s: sp.S.Zero}) == 0 and not (sp.diff(row, s).free_symbols & set(states)):
                    resting[s], changed = sp.S.Zero, True
                    used.add(i)
                    rows = [r.xreplace({s: sp.S.Zero}) for r in rows]
    unknowns = tuple(s for s in states if s not in resting)
    remaining = [normalised(rows[i], states) for i in range(len(rows)) if i not in used]
    if len(remaining) != len(unknowns):
        raise ModelError(f"the static state is not determined: {len(remaining)} equations at rest for "
                         f"{len(unknowns)} states ({', '.join(s.name for s in unknowns)})", system.name)
    meshes = [c for c in system.meshes if c.backlash != 0]
    contacts = [c.contact.xreplace(resting) for c in meshes]
    backlashes = [sp.sympify(c.backlash, strict=True) for c in meshes]
    used_parameters = set()
    for e in (*remaining, *contacts, *backlashes):
        used_parameters |= {s.name for s in e.free_symbols if s.name in system.parameters}
    depends = tuple(name for name in system.parameters if name in used_parameters)
    y, p = ca.SX.sym("y", len(unknowns)), ca.SX.sym("p", len(depends))
    mapping = {s: y[i] for i, s in enumerate(unknowns)}
    by_name = {name: p[j] for j, name in enumerate(depends)}
    for e in (*remaining, *contacts, *backlashes):
        for s in e.free_symbols:
            if s not in mapping and s.name in by_name:
                mapping[s] = by_name[s.name]
    residual = ca.vertcat(*to_casadi(remaining, mapping, system.name)) if remaining else ca.SX(0, 1)
    contact = ca.vertcat(*to_casadi(contacts, mapping, system.name)) if contacts else ca.SX(0, 1)
    eta = ca.vertcat(*to_casadi(backlashes, mapping, system.name)) if backlashes else ca.SX(0, 1)
    function = ca.Function("static", [y, p], [residual, ca.jacobian(residual, y), contact, eta],
                           ["y", "p"], ["residual", "jacobian", "contact", "eta"])
    return StaticRecipe(tuple(s.name for s in states), tuple(s.name for s in unknowns), depends,
                        tuple(c.name for c in meshes), function.serialize())


def time_mean(expr: sp.Expr, system: FirstOrderSystem) -> sp.Expr:
    """The mean of ``expr`` over a period of the system's time, exact for sums of terms each linear in one
    harmonic of time (products of harmonics turned into sums first); a one-line error for anything else."""
    time = system.time
    if time not in expr.free_symbols:
        return expr
    expanded = sp.expand(expr)
    out = []
    for term in sp.Add.make_args(expanded):
        mean = _term_mean(term, time)
        if mean is None:
            again = [_term_mean(t, time) for t in sp.Add.make_args(sp.expand(TR8(term)))]
            if any(m is None for m in again):
                raise ModelError(f"cannot take the mean over a period of {term} (time enters other than through "
                                 "harmonics); the static state needs it: linearise about the periodic orbit "
                                 "instead (about='orbit', --about orbit)", system.name)
            mean = sp.Add(*again)
        out.append(mean)
    return sp.Add(*out)


def _term_mean(term: sp.Expr, time: sp.Symbol) -> sp.Expr | None:
    """0 for a term with one factor cos/sin(a t + b) (a free of t and not 0), the term itself without t; None
    otherwise."""
    timed = [f for f in sp.Mul.make_args(term) if time in f.free_symbols]
    if not timed:
        return term
    if len(timed) != 1:
        return None
    f = timed[0]
    if isinstance(f, (sp.cos, sp.sin)):
        slope = sp.diff(f.args[0], time)
        if time not in slope.free_symbols and slope != 0:
            return sp.S.Zero
    return None


def normalised(row: sp.Expr, states) -> sp.Expr:
    """``row`` without the factors that hold no state (its zeros are the same where they are nonzero)."""
    numerator, _ = sp.fraction(sp.together(row))
    numerator = sp.factor_terms(numerator)
    if numerator.is_Mul:
        kept = [a for a in numerator.args if a.free_symbols & set(states)]
        return sp.Mul(*kept) if kept else numerator
    return numerator


def compile_linearisation(system: FirstOrderSystem, options: Integration | None = None, *,
                          verbose: bool = False) -> CompiledLinearisation:
    """Linearise ``system`` about its static state and compile the linear system (its tables factored: a chart
    across omega never recomputes them; it has no backlash of the state, so nothing to locate)."""
    lin = linearise(system)
    options = replace(options or Integration(), locate_crossings=True)
    model = compile_model(lin.system, options, verbose=verbose)
    return CompiledLinearisation(model, lin.static, lin.anchors, system.name, dict(system.parameters))


__all__ = ["CompiledLinearisation", "Linearised", "STATIC_SUFFIX", "StaticRecipe", "anchor_parameter",
           "compile_linearisation", "linearise", "static_recipe", "time_mean"]
