"""The low-level entry: a first-order ODE dy/dtime = f(time, y, p) given as SymPy expressions.

Every model ends up here: a reduced drivetrain becomes one (see
:meth:`gearsym.reduce.NondimensionalModel.system`), and plain ODEs such as
Lorenz are declared directly with :meth:`FirstOrderSystem.from_equations`.
The compiled engine takes nothing else, so it is one engine for both.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import sympy as sp

from .errors import ModelError, UnknownParameterError
from .model.expressions import ExprLike, to_expr
from .symbols import parameter_symbol


@dataclass(frozen=True)
class FirstOrderSystem:
    """dy/d(time) = rhs(time, y, p), with named parameters and their values.

    ``period`` is the forcing period in ``time`` (2*pi for the gear models):
    the unit of stroboscopic sampling and of tangent-space re-orthonormalisation.
    ``coordinates`` names the states whose vibration amplitude is reported (the
    relative coordinates of a drivetrain); empty means every state. ``initial``
    is the default initial state (states not named start at 0).
    """

    name: str
    time: sp.Symbol
    states: tuple[sp.Symbol, ...]
    rhs: tuple[sp.Expr, ...]
    parameters: Mapping[str, float]
    period: sp.Expr = sp.S.One
    descriptions: Mapping[str, str] = field(default_factory=dict)
    title: str = ""
    coordinates: tuple[str, ...] = ()
    initial: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self):
        if len(self.states) != len(self.rhs):
            raise ModelError(f"{len(self.states)} states but {len(self.rhs)} right-hand sides", self.name)
        if len({s.name for s in self.states}) != len(self.states):
            raise ModelError("state names must be distinct", self.name)
        known = {s.name for s in self.states} | {self.time.name} | set(self.parameters)
        for i, f in enumerate(self.rhs):
            for s in f.free_symbols:
                if s.name not in known:
                    raise UnknownParameterError(s.name, set(self.parameters), f"{self.name}: d{self.states[i].name}/d{self.time.name}")
        bad = set(self.initial) - {s.name for s in self.states}
        if bad:
            raise ModelError(f"the initial state names {sorted(bad)}, which are not states "
                             f"({', '.join(s.name for s in self.states)})", self.name)
        unknown = set(self.coordinates) - {s.name for s in self.states}
        if unknown:
            raise ModelError(f"coordinates {sorted(unknown)} are not states ({', '.join(s.name for s in self.states)})",
                             self.name)
        clash = {s.name for s in self.states} & set(self.parameters)
        if clash:
            raise ModelError(f"names used both as state and parameter: {sorted(clash)}", self.name)

    @classmethod
    def from_equations(
        cls,
        name: str,
        states: Sequence[str],
        rhs: Sequence[ExprLike],
        parameters: Mapping[str, float],
        time: str = "t",
        period: ExprLike = 1,
        descriptions: Mapping[str, str] | None = None,
        title: str = "",
        initial: Mapping[str, float] | None = None,
    ) -> "FirstOrderSystem":
        """Declare an ODE from strings, e.g. Lorenz: states ['x','y','z'], rhs ['sigma*(y-x)', ...]."""
        state_syms = tuple(sp.Symbol(s, real=True) for s in states)
        time_sym = sp.Symbol(time, real=True)
        extra = {s.name: s for s in state_syms} | {time: time_sym}
        exprs = tuple(to_expr(f, f"{name}: d{s}/d{time}", extra) for f, s in zip(rhs, states))
        return cls(name, time_sym, state_syms, exprs, dict(parameters), to_expr(period, name),
                   dict(descriptions or {}), title, initial=dict(initial or {}))

    @property
    def dimension(self) -> int:
        return len(self.states)

    @property
    def parameter_symbols(self) -> tuple[sp.Symbol, ...]:
        return tuple(parameter_symbol(n) for n in self.parameters)

    def with_values(self, **values: float) -> "FirstOrderSystem":
        """The same system with some parameter values changed (names are checked)."""
        for k in values:
            if k not in self.parameters:
                raise UnknownParameterError(k, self.parameters, self.name)
        return replace(self, parameters={**self.parameters, **{k: float(v) for k, v in values.items()}})

    @cached_property  # asked at every point of a sweep; a walk over the SymPy trees each time
    def autonomous(self) -> bool:
        """True if time does not appear in the right-hand side (Lorenz); then one Lyapunov exponent is zero."""
        return all(self.time not in f.free_symbols for f in self.rhs)

    @property
    def observed(self) -> tuple[str, ...]:
        """The states whose amplitude is reported: ``coordinates``, or every state."""
        return self.coordinates or tuple(s.name for s in self.states)

    @property
    def initial_vector(self) -> tuple[float, ...]:
        return tuple(float(self.initial.get(s.name, 0.0)) for s in self.states)

    def jacobian(self) -> sp.Matrix:
        """Exact Jacobian d rhs / d y."""
        return sp.Matrix(self.rhs).jacobian(sp.Matrix(self.states))
