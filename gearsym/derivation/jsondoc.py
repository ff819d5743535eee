"""The derivation as JSON, for tools (plotting scripts, other languages, tests).

Every expression is given twice: ``str()`` (which ``sympy.sympify`` reads
back) and, where a reader would typeset it, LaTeX. Keys come in a fixed order
and nothing depends on the run, so the output is byte-identical across runs.
Parameter defaults are exact floats (JSON numbers), not rounded.
"""
from __future__ import annotations

import json
from typing import Any

import sympy as sp

from .latex import first_order_rows
from .printing import equation_latex, latex_name, leading_derivative, to_latex
from .records import Derivation, Mechanics


def _eq(d: Derivation, eq: sp.Eq) -> dict[str, str]:
    lhs, rhs = equation_latex(eq, leading_derivative(eq.lhs), d.bare_functions)
    return {"equation": str(eq), "latex": f"{lhs} = {rhs}"}


def _mechanics(d: Derivation, m: Mechanics) -> dict[str, Any]:
    bare = d.bare_functions
    s = str
    return {
        "components": {
            "bodies": [
                {"name": b.name, "kind": b.kind, "inertia": s(b.inertia),
                 "radius": None if b.radius is None else s(b.radius), "angle": s(b.angle)}
                for b in m.bodies
            ],
            "couplings": [
                {"name": c.name, "kind": c.kind, "ends": list(c.ends), "coordinate": c.coordinate,
                 "stiffness": s(c.stiffness), "damping": s(c.damping), "backlash": s(c.backlash),
                 "variation": s(c.variation), "mesh_phase": s(c.mesh_phase)}
                for c in m.couplings
            ],
            "torques": [
                {"name": tq.name, "on": tq.on, "load": tq.load, "terms": [s(term) for term in tq.terms]}
                for tq in m.torques
            ],
        },
        "lagrangian": {"T": s(m.kinetic_energy), "V": s(m.potential_energy), "R": s(m.dissipation)},
        "generalized_forces": [s(q) for q in m.generalized_forces],
        "equations_of_motion": [_eq(d, eq) for eq in m.equations_of_motion],
        "rigid_modes": [[s(e) for e in u] for u in m.rigid_modes],
        "rigid_body_equations": [_eq(d, eq) for eq in m.rigid_body_equations],
        "transform": [[s(m.transform[i, j]) for j in range(m.transform.cols)] for i in range(m.transform.rows)],
        "reduced_equations": [_eq(d, eq) for eq in m.reduced_equations],
        "functions": [
            {"name": f.name, "mesh": f.mesh, "definition": s(f.definition), "expression": s(f.expression),
             "latex": to_latex(f.expression, bare)}
            for f in m.functions
        ],
        "engine_rhs": [s(f) for f in m.engine_rhs],
    }


def derivation_dict(d: Derivation) -> dict[str, Any]:
    """The derivation as plain JSON-ready data."""
    m = d.mechanics
    bare = d.bare_functions
    out: dict[str, Any] = {
        "model": d.model,
        "title": d.title,
        "kind": "drivetrain" if m is not None else "first_order_system",
        "time": d.time.name,
        "states": [s.name for s in d.states],
        "rhs": [str(f) for f in d.rhs],
        "rhs_latex": [f"{lhs} = {rhs}" for lhs, rhs in first_order_rows(d)],
        "parameters": {p.name: {"default": p.default, "description": p.description} for p in d.parameters},
        "equations": [str(eq) for eq in d.equations],
        "equations_latex": [_eq(d, eq)["latex"] for eq in d.equations],
        "coordinates": [] if m is None else [
            {"name": c.name, "velocity": c.velocity, "kind": c.kind, "coupling": c.coupling,
             "definition": str(c.definition), "latex": to_latex(c.definition, bare)}
            for c in m.coordinates
        ],
        "closing": [] if m is None else [  # deflections of couplings that close a loop: combinations of coordinates
            {"name": c.name, "coupling": c.coupling, "definition": str(c.definition),
             "combination": str(c.combination)}
            for c in m.closing
        ],
        "groups": [] if m is None else [
            {"name": gr.name, "definition": str(gr.definition), "latex": to_latex(gr.definition, bare),
             "symbol_latex": latex_name(gr.name), "kind": gr.kind, "description": gr.description, "value": gr.value}
            for gr in m.groups
        ],
        "conditions": [] if m is None else [
            {**_eq(d, c.equation), "description": c.description} for c in m.conditions
        ],
        "period": str(d.period),
        "period_latex": to_latex(d.period),
        "notes": list(d.notes),
    }
    if m is not None:
        out.update(_mechanics(d, m))
    return out


def render_json(d: Derivation) -> str:
    return json.dumps(derivation_dict(d), indent=2, ensure_ascii=False) + "\n"
