"""Plain-text derivation for a terminal (``gearsym derive MODEL``).

SymPy's Unicode pretty printer, wrapped at a fixed width so that the output
does not depend on the terminal. The default shows what a user of the model
needs (coordinates, nondimensional equations, groups, conditions, stiffness
functions, parameters); ``full=True`` adds every step from the components on.
"""
from __future__ import annotations

import textwrap

import sympy as sp

from .printing import TEXT_COLUMNS, equation_text, number, to_text
from .records import Derivation, Mechanics

_INDENT = "  "


def _indent(block: str) -> str:
    return "\n".join((_INDENT + line).rstrip() for line in block.splitlines())


def _section(title: str, body: list[str]) -> list[str]:
    return ["", title, "-" * len(title), *body]


def _equations(equations) -> list[str]:
    return [_indent(equation_text(eq)) for eq in equations]


def _prose(text: str, indent: str = _INDENT * 2) -> str:
    return textwrap.fill(text, TEXT_COLUMNS, initial_indent=indent, subsequent_indent=indent,
                         break_long_words=False, break_on_hyphens=False)


def _mechanics_sections(m: Mechanics) -> list[str]:
    out: list[str] = []
    rows = [f"{b.name}: {b.kind}, inertia {b.inertia}" + (f", base radius {b.radius}" if b.radius is not None else "")
            + f", angle {b.angle}" for b in m.bodies]
    for c in m.couplings:
        line = f"{c.name}: {c.kind} {c.ends[0]} -> {c.ends[1]}, stiffness {c.stiffness}, damping {c.damping}"
        if c.kind == "mesh":
            line += f", backlash {c.backlash}, mesh phase phi = {c.mesh_phase}"
        rows.append(line + f", coordinate {c.coordinate}")
    for tq in m.torques:
        rows.append(f"{tq.name}: torque on {tq.on} ({'load' if tq.load else 'drive'}), enters as {tq.total}")
    out += _section("Components", [_INDENT + r for r in rows])
    stiff = [_indent(to_text(c.stiffness_in_time)) for c in m.couplings if c.stiffness_in_time is not None]
    if stiff:
        out += _section("Mesh stiffness in time (phi: mesh phase)", stiff)
    out += _section("Lagrangian", [
        _indent(to_text(sp.Eq(sp.Symbol(n), e)))
        for n, e in (("T", m.kinetic_energy), ("V", m.potential_energy), ("R", m.dissipation))
    ])
    out += _section("Generalized forces", [
        _indent(to_text(sp.Eq(sp.Symbol(f"Q_{i + 1}"), q))) for i, q in enumerate(m.generalized_forces)
    ])
    out += _section("Equations of motion", _equations(m.equations_of_motion))
    out += _section("Rigid-body modes (in the angles " + ", ".join(str(a) for a in m.angles) + ")", [
        _indent(f"u{k + 1} = {to_text(u.T)}") for k, u in enumerate(m.rigid_modes)
    ] + _equations(m.rigid_body_equations))
    out += _section("Transform q = T psi", [_indent(to_text(m.transform))])
    out += _section("Reduced equations in t", _equations(m.reduced_equations))
    return out


def render_text(d: Derivation, full: bool = False) -> str:
    out = [d.model if d.title == d.model else f"{d.model}: {d.title}"]
    if d.description:
        out.append(d.description)
    m = d.mechanics
    if m is not None and full:
        out += _mechanics_sections(m)
    if m is not None:
        coordinates = []
        for c in m.coordinates:
            coordinates += [_indent(to_text(sp.Eq(sp.Symbol(c.name), c.definition))),
                            _prose(f"{c.kind} {c.coupling!r}; velocity state {c.velocity}")]
        out += _section("Relative coordinates", coordinates)
        out += _section(f"Nondimensional equations ({d.time} = omega t)", _equations(m.equations))
        groups = []
        for gr in m.groups:
            value = f" (value at the defaults: {number(gr.value)})" if gr.value is not None else ""
            groups += [_indent(to_text(sp.Eq(gr.symbol, gr.definition))), _prose(f"[{gr.kind}] {gr.description}{value}")]
        out += _section("Coefficient groups", groups)
        if m.conditions:
            conditions = []
            for c in m.conditions:
                conditions += [_indent(to_text(c.equation)), _prose(c.description)]
            out += _section("Conditions", conditions)
        functions = []
        for f in m.functions:
            functions += [_indent(to_text(sp.Eq(f.applied, f.definition))), _indent(to_text(sp.Eq(f.applied, f.expression)))]
        out += _section("Mesh stiffness functions", functions)
    if m is None or full:
        out += _section(f"First-order system in {d.time}", [
            _indent(equation_text(eq)) for eq in d.first_order_equations
        ])
    width = max((len(p.name) for p in d.parameters), default=0)
    out += _section("Parameters (default, description)", [
        f"{_INDENT}{p.name.ljust(width)}  {number(p.default) if p.default is not None else 'no default':>14}  "
        f"{p.description}".rstrip() for p in d.parameters
    ])
    out += ["", f"Period in {d.time}: {d.period}"]
    if full and d.notes:
        out += _section("Notes on the paper", [_prose(f"- {n}", _INDENT).replace("\n" + _INDENT, "\n" + _INDENT * 2)
                                               for n in d.notes])
    return "\n".join(out) + "\n"
