"""The few functions an FMU needs beside the engine's C, generated as C by CasADi like the engine's own.

The engine's library already has the right-hand side (model exchange), the constants and the RK4 step with
located crossings (co-simulation). Its tables of time are made for one period at its own step; an FMU steps at
whatever times the importer asks for, so it gets the tables at one time (``gearsym_fmu_table``), built from
the same split of the right-hand side. Besides: the event indicators (``gearsym_fmu_indicators``) and what
the outputs are made of (``gearsym_fmu_outputs``: each mesh's deflection, elastic force, deflection rate and
backlash, each shaft's twist), all in the engine's units, from the system's couplings.
"""
from __future__ import annotations

import re
from pathlib import Path

import casadi as ca
import sympy as sp

from ..model.backlash import g
from ..codegen.casadi_symbols import SystemSymbols
from ..codegen.generate import casadi_source
from ..codegen.time_tables import SplitRHS
from ..codegen.translate import to_casadi
from ..errors import ModelError
from ..system import FirstOrderSystem
from .variables import Layout

#: the C file of these functions in the FMU's sources
SOURCE = "gearsym_fmu_functions.c"
#: their names (exported: the wrapper calls them)
TABLE, INDICATORS, OUTPUTS = "gearsym_fmu_table", "gearsym_fmu_indicators", "gearsym_fmu_outputs"


def indicators(system: FirstOrderSystem, surfaces: tuple[sp.Expr, ...]) -> tuple[sp.Expr, ...]:
    """The event indicators: x and -(x + eta) of every mesh with backlash (x its deflection, from the
    couplings), then any of the engine's switching ``surfaces`` those do not cover (a plain ODE with g
    written by hand). Every surface the engine locates is an indicator."""
    found = [e for c in system.couplings if c.kind == "mesh" and c.backlash != 0
             for e in (c.contact, -(c.contact + c.backlash))]
    for s in surfaces:
        if not any(sp.expand(s - e) == 0 for e in found):
            found.append(s)
    return tuple(found)


def output_expressions(lay: Layout) -> list[sp.Expr]:
    """What the outputs are made of, in the engine's units: per mesh its deflection, then per mesh its elastic
    force k(tau) g(x, eta), its deflection rate, its backlash, then per shaft its twist."""
    m = lay.meshes
    return ([c.contact for c in m] + [c.stiffness * g(c.contact, c.backlash) for c in m] + [c.rate for c in m]
            + [c.backlash for c in m] + [c.contact for c in lay.shafts])


def fmu_functions(lay: Layout, split: SplitRHS) -> list[ca.Function]:
    """The CasADi functions of the FMU (see the module's docstring)."""
    system = lay.system
    sym = SystemSymbols.of(system)
    mapping = _mapping(system, sym, [e for _, e in split.tables] + list(lay.indicators) + output_expressions(lay))
    where = f"{system.name}: FMU"

    def vector(exprs):
        return ca.vertcat(*to_casadi(list(exprs), mapping, where)) if exprs else ca.SX(0, 1)

    return [ca.Function(TABLE, [sym.t, sym.p], [vector([e for _, e in split.tables])], ["t", "p"], ["table"]),
            ca.Function(INDICATORS, [sym.t, sym.y, sym.p], [vector(lay.indicators)], ["t", "y", "p"], ["z"]),
            ca.Function(OUTPUTS, [sym.t, sym.y, sym.p], [vector(output_expressions(lay))], ["t", "y", "p"],
                        ["out"])]


def _mapping(system: FirstOrderSystem, sym: SystemSymbols, exprs) -> dict:
    """The system's map of symbols, with any symbol of ``exprs`` it lacks found by name among the states and
    parameters (whatever its assumptions)."""
    mapping = dict(sym.mapping)
    states = {s.name: sym.y[i] for i, s in enumerate(system.states)}
    params = {name: sym.p[j] for j, name in enumerate(system.parameters)}
    for e in exprs:
        for s in sp.sympify(e, strict=True).free_symbols:
            if s in mapping:
                continue
            if s.name in states:
                mapping[s] = states[s.name]
            elif s.name in params:
                mapping[s] = params[s.name]
            elif s.name == system.time.name:
                mapping[s] = sym.t
            else:
                raise ModelError(f"{s.name} in {e} is no state, parameter or time of the model", system.name)
    return mapping


def write_functions(functions: list[ca.Function], directory: Path) -> Path:
    """The C of ``functions`` as ``directory/`` :data:`SOURCE` (CasADi's code generator: deterministic)."""
    text = casadi_source(SOURCE, functions)
    # CasADi's exported helpers (_casadi_version, ...) have the same names in the engine's C beside it: renamed here
    helpers = sorted(set(re.findall(r"^CASADI_SYMBOL_EXPORT [\w ]+?\b(_casadi_\w+)\(", text, re.M)))
    text = "".join(f"#define {name} gearsym_fmu{name}\n" for name in helpers) + text
    target = Path(directory) / SOURCE
    target.write_text(text)
    return target
