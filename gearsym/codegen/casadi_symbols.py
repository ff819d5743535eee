"""The SymPy -> CasADi map of a model's symbols: the one map for the engine's functions and the fit's windows.

:class:`SystemSymbols` are a system's time, state and parameter vector as SX symbols; :class:`LoopSymbols` add
what the loop body sees instead of time and parameters (the tables of time and the constants, with the step).
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..system import FirstOrderSystem
from .time_tables import SplitRHS
from .translate import to_casadi

#: every SX function is written with its common subexpressions removed
SX_OPTIONS = {"cse": True}


@dataclass(frozen=True)
class SystemSymbols:
    """SX symbols for a system's time, state and parameter vector, and the SymPy -> SX map of them: the one
    map from a model's symbols to CasADi's, for the engine's functions and the fit's windows alike."""

    t: ca.SX
    y: ca.SX
    p: ca.SX
    mapping: dict

    @classmethod
    def of(cls, system: FirstOrderSystem) -> "SystemSymbols":
        names = list(system.parameters)
        t, y, p = ca.SX.sym("t"), ca.SX.sym("y", system.dimension), ca.SX.sym("p", len(names))
        mapping = {system.time: t, **{s: y[i] for i, s in enumerate(system.states)}}
        by_name = {name: p[j] for j, name in enumerate(names)}
        for expr in list(system.rhs) + [system.period]:  # parameters by name, whatever their assumptions
            for s in expr.free_symbols:
                if s not in mapping and s.name in by_name:
                    mapping[s] = by_name[s.name]
        return cls(t, y, p, mapping)

    def rhs(self, system: FirstOrderSystem) -> ca.SX:
        """f(t, y, p), the right-hand side in these symbols."""
        return ca.vertcat(*to_casadi(system.rhs, self.mapping, system.name))


class LoopSymbols:
    """The SX symbols of one model and the SymPy -> SX maps of the outer functions and the loop body."""

    def __init__(self, system: FirstOrderSystem, split: SplitRHS):
        m, nc = len(split.tables), len(split.constants)
        base = self.base = SystemSymbols.of(system)
        self.params = list(system.parameters)
        self.observed = system.observed_indices
        self.t, self.y, self.p = base.t, base.y, base.p
        self.T = ca.SX.sym("T", m)
        c = ca.SX.sym("c", nc)
        outer = dict(base.mapping)
        outer.update({s: self.T[i] for i, (s, _) in enumerate(split.tables)})
        outer.update({s: c[i] for i, (s, _) in enumerate(split.constants)})
        self.outer = outer
        # the loop body sees states, table values and constants only; ch = (constants, h)
        self.ch = ca.SX.sym("c", nc + 1)
        self.inner = {**outer, **{s: self.ch[i] for i, (s, _) in enumerate(split.constants)}}
