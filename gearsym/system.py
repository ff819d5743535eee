"""The low-level entry: a first-order ODE dy/dtime = f(time, y, p) given as SymPy expressions.

Every model ends up here: a reduced drivetrain becomes one (see
:meth:`gearsym.reduction.NondimensionalModel.system`), and plain ODEs such as
Lorenz are declared directly with :meth:`FirstOrderSystem.from_equations`.
The compiled engine takes nothing else, so it is one engine for both.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import sympy as sp

from .model.declared import Model
from .errors import ModelError, UnknownParameterError
from .model.expressions import ExprLike, to_expr
from .parameters import Constraint, ParameterChecks
from .model.symbols import parameter_symbol


@dataclass(frozen=True)
class Gearing:
    """One gear of a mesh as the system knows it: its name in the model and its tooth count (None if the model
    declares none). A gear of Z teeth turns once in Z mesh periods, so its shaft order is 1/Z of the mesh's."""

    gear: str
    teeth: int | None = None


@dataclass(frozen=True)
class Coupling:
    """A mesh or shaft of a reduced drivetrain, as its first-order system carries it.

    The reduction knows every coupling; the engine, the effects of the data loop and the reports read
    it here instead of searching the equations. The coupling's *law* in its deflection ``x`` (``contact``)
    is, in the tau-form, ``2 zeta x'/omega + k(tau) g(x, eta)/omega^2`` for a mesh (``beta (kS x/omega^2 +
    cS x'/omega)`` for a shaft); it enters the velocity equation of each row in ``rows`` as
    ``-factor * law``. A coupling that closes a kinematic loop (a planet's second mesh) has no coordinate
    of its own: ``coordinate`` and ``velocity`` name its deflection, which is not a state, and ``contact``
    and ``rate`` are combinations of the coordinates and their rates (x1 + x2 - x3, v1 + v2 - v3).
    """

    name: str  # the component ("mesh", "shaft")
    kind: str  # "mesh" | "shaft"
    coordinate: str  # the state of its relative coordinate (x1), or the name of a loop-closing deflection
    velocity: str  # the state of its rate (v1), or the name of that deflection's rate
    backlash: sp.Expr  # eta; 0 for a linear mesh and for every shaft
    stiffness: sp.Expr  # the mesh stiffness k(tau) as the equations use it (for a shaft its kS)
    order: sp.Expr = sp.S.Zero  # mesh frequency over forcing frequency (0 for shafts)
    rows: tuple[tuple[int, sp.Expr], ...] = ()  # (index in rhs of a velocity equation, factor of the law)
    contact: sp.Expr | None = None  # the argument of g: the coordinate (None), a combination, or shifted by an effect
    rate: sp.Expr | None = None  # the deflection's rate: the velocity (None), or the combination of rates
    gears: tuple[Gearing, ...] = ()  # a mesh's two gears (a, b): names and tooth counts

    def __post_init__(self):
        if self.contact is None:
            object.__setattr__(self, "contact", sp.Symbol(self.coordinate, real=True))
        if self.rate is None:
            object.__setattr__(self, "rate", sp.Symbol(self.velocity, real=True))

    def gear(self, name: str) -> Gearing:
        """The gear of this mesh called ``name``."""
        for gearing in self.gears:
            if gearing.gear == name:
                return gearing
        raise ModelError(f"{name!r} is not a gear of mesh {self.name!r} ({', '.join(g.gear for g in self.gears)})")

    @property
    def closes_loop(self) -> bool:
        """True for a coupling whose deflection is a combination of the coordinates (no state of its own)."""
        return self.rate != sp.Symbol(self.velocity, real=True)


@dataclass(frozen=True)
class FirstOrderSystem(ParameterChecks, Model):
    """dy/d(time) = rhs(time, y, p), with named parameters and their values.

    ``period`` is the period the system repeats on, in ``time`` (2*pi for the gear models: the forcing period):
    the unit of stroboscopic sampling and of tangent-space re-orthonormalisation. ``cycles`` is the number of
    forcing periods in it: 1, or with shaft-order terms (a tooth fault, an eccentric gear) a gear's revolution
    in mesh periods, or the hunting period; the engine keeps its steps per *forcing* period, so a long period
    costs time, not accuracy.
    ``coordinates`` names the states whose vibration amplitude is reported (the
    relative coordinates of a drivetrain); empty means every state. ``initial``
    is the default initial state (states not named start at 0). A reduced
    drivetrain also hands on its ``couplings`` and the ``constraints`` its
    parameters' physical meaning puts on their values.
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
    couplings: tuple[Coupling, ...] = ()
    constraints: Mapping[str, Constraint] = field(default_factory=dict)
    cycles: int = 1
    #: a drivetrain on bearings: each body centre's translation in the states ("pinion_y" -> y_pinion), the
    #: engine's length unit; a measured acceleration of it is the channel a_<name> (a_pinion_y)
    translations: Mapping[str, sp.Expr] = field(default_factory=dict)

    def __post_init__(self):
        if isinstance(self.cycles, bool) or not isinstance(self.cycles, int) or self.cycles < 1:
            raise ModelError(f"cycles (forcing periods per period) must be a whole number of at least 1, got "
                             f"{self.cycles!r}", self.name)
        if not isinstance(self.period, sp.Basic):  # a number (or a formula) given for the period
            object.__setattr__(self, "period", to_expr(self.period, f"{self.name}: period"))
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
        names = {s.name for s in self.states}
        for c in self.couplings:
            used = {c.coordinate, c.velocity} if not c.closes_loop else \
                {s.name for s in c.rate.free_symbols} - set(self.parameters)  # (its coefficients: parameters)
            if not used <= names:
                raise ModelError(f"coupling {c.name!r} acts on {', '.join(sorted(used - names))}, which are not states",
                                 self.name)

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
        """The same system with some parameter values changed (names and values are checked)."""
        for k in values:
            if k not in self.parameters:
                raise UnknownParameterError(k, self.parameters, self.name)
        return replace(self, parameters={**self.parameters, **{k: self.check_value(k, v) for k, v in values.items()}})

    def period_at(self, values: Mapping[str, float] | None = None) -> float:
        """The forcing period (in the system's time) at these parameter values."""
        merged = self.parameter_values(values)
        period = self.period.xreplace({s: merged[s.name] for s in self.period.free_symbols if s.name in merged})
        number = float(period) if period.is_number else math.nan
        if not (math.isfinite(number) and number > 0):
            raise ModelError(f"the forcing period {self.period} is {period} at these parameter values; it must be a "
                             "positive number", self.name)
        return number

    def cycle_at(self, values: Mapping[str, float] | None = None) -> float:
        """One forcing period (a mesh period) at these parameter values: the period over ``cycles``."""
        return self.period_at(values) / self.cycles

    @property
    def meshes(self) -> tuple[Coupling, ...]:
        return tuple(c for c in self.couplings if c.kind == "mesh")

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.states)

    @cached_property
    def contact_watches(self) -> tuple[tuple[str, str, object, object], ...]:
        """(name, coordinate, backlash, offset) of each mesh with backlash whose contact coordinate is observed and
        shifted by parameters only (contact = coordinate + offset; every mesh of the shipped drivetrains), what an
        orbit's extremes are read on: backlash and offset as a number, a parameter's name, or an expression."""
        out = []
        params = set(self.parameters)
        for c in self.couplings:
            if c.kind != "mesh" or c.backlash == 0 or c.coordinate not in self.observed:
                continue
            offset = c.contact - sp.Symbol(c.coordinate, real=True)
            if _moves(offset, params):  # (seen in two numbers: simplify, seconds on a runout's terms, not needed)
                continue
            offset = sp.simplify(offset)
            if {s.name for s in offset.free_symbols} - params:
                continue  # shifted by time or states: no extreme of the coordinate says where it is
            out.append((c.name, c.coordinate, _plain(c.backlash), _plain(offset)))
        return tuple(out)

    @property
    def full(self) -> "FirstOrderSystem":
        """The system itself (the start-up cache's summary of one,
        :class:`~gearsym.codegen.system_summary.SystemSummary`, loads the full system here)."""
        return self

    @property
    def time_name(self) -> str:
        return self.time.name

    def coupling(self, coordinate: str) -> Coupling:
        """The coupling whose relative coordinate is ``coordinate``."""
        for c in self.couplings:
            if c.coordinate == coordinate:
                return c
        known = ", ".join(c.coordinate for c in self.couplings) or "none: not a reduced drivetrain"
        raise ModelError(f"no coupling acts on {coordinate!r} (couplings act on: {known})", self.name)

    @cached_property  # asked at every point of a sweep; a walk over the SymPy trees each time
    def autonomous(self) -> bool:
        """True if time does not appear in the right-hand side (Lorenz); then one Lyapunov exponent is zero."""
        return all(self.time not in f.free_symbols for f in self.rhs)

    @property
    def observed(self) -> tuple[str, ...]:
        """The states whose amplitude is reported: ``coordinates``, or every state."""
        return self.coordinates or tuple(s.name for s in self.states)

    @property
    def observed_indices(self) -> list[int]:
        """Where the :attr:`observed` states are in the state vector (the loops' min/max rows)."""
        return [i for i, s in enumerate(self.states) if s.name in self.observed]

    @property
    def initial_vector(self) -> tuple[float, ...]:
        return tuple(float(self.initial.get(s.name, 0.0)) for s in self.states)

    def jacobian(self) -> sp.Matrix:
        """Exact Jacobian d rhs / d y."""
        return sp.Matrix(self.rhs).jacobian(sp.Matrix(self.states))


def _moves(expr: sp.Expr, fixed: set[str]) -> bool:
    """Whether ``expr`` is seen to change with a symbol whose name is not in ``fixed`` (time, a state): its values
    at two points that differ in those symbols alone differ by far more than rounding. False when that is not
    seen (no such symbol, values that are not finite numbers, equal values): then only simplifying can tell."""
    symbols = sorted(expr.free_symbols, key=lambda s: s.name)
    if all(s.name in fixed for s in symbols):
        return False
    here = {s: sp.Float(0.31 + 0.17 * i) for i, s in enumerate(symbols)}
    there = {s: v if s.name in fixed else v + sp.Float(0.73) for s, v in here.items()}
    try:
        a, b = (complex(expr.xreplace(point).evalf()) for point in (here, there))
    except (TypeError, ValueError, ZeroDivisionError):
        return False
    finite = all(math.isfinite(z.real) and math.isfinite(z.imag) for z in (a, b))
    return finite and abs(a - b) > 1e-6 * max(1.0, abs(a), abs(b))


def _plain(expr: sp.Expr) -> float | str | sp.Expr:
    """A number as a float, a parameter as its name, anything else as the expression."""
    if expr.is_Number:
        return float(expr)
    return expr.name if isinstance(expr, sp.Symbol) else expr
