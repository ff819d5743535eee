"""Coefficient groups, conditions and the nondimensional form in tau = omega t.

From a :class:`~gearsym.reduction.reduction.Reduction` (row i holds
``-factor_ic * law_c`` and forcing terms), this module names the groups the
paper names and writes Eqs. 2, 6 and 9:

* a mesh's own-row factor m (r1^2/I1 + r2^2/I2 for a pair) is absorbed into
  its stiffness and damping: ``k(tau) g = m kZ g`` (Eq. 4), ``2 zeta = m cZ`` (Eq. 3);
  in the other rows it leaves ``beta = factor / m`` (the paper's beta3);
* a shaft's factor in every row is a group ``beta`` multiplying ``kS x``
  (the paper's beta1, beta2);
* the forcing of each row, grouped by harmonic, gives B0, B1, D, ...;
  the constant forcing of a shaft declared forced=False must vanish: the torque-balance
  condition of Eq. 10;
* time is measured in units of 1/omega_n, omega_n^2 = m kZ of the first mesh,
  so that its mean stiffness is 1 (the paper's convention; a condition too).

Groups are numbered shafts first, then meshes, as in the paper's Eq. 10.
"""
from __future__ import annotations

import functools
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Optional

import sympy as sp
from sympy.core.function import AppliedUndef

from ..model.backlash import g
from ..errors import ModelError, UnknownParameterError
from ..model.drivetrain import Drivetrain
from ..model.resolved_components import ResolvedCoupling
from ..model.roles import parameter_roles
from ..model.expressions import ExprLike, parameter_names, to_expr
from ..model.stiffness import check_periodic
from ..model.linear_algebra import outside_span, simplified
from ..model.evaluation import PointValues
from ..model.replacing import Replacer
from ..model.translations import CARRIER_SPEED
from ..model.symbols import RESERVED, omega, parameter_symbol, phi, t, tau
from ..system import Constraint, Coupling, FirstOrderSystem, Gearing
from .coordinates import combination_solver
from .reduction import Reduction, reduce_drivetrain, with_geometry


@dataclass(frozen=True)
class Group:
    """A coefficient group: a new symbol standing for a combination of component parameters.

    ``free`` groups (zeta, B0, ...) are parameters of the nondimensional model
    with their own values; ``derived`` groups (beta) are evaluated from their
    definition, so the inertias and radii behind them stay declared parameters.
    """

    name: str
    definition: sp.Expr
    kind: str  # "free" | "derived"
    description: str
    role: str  # "coupling" (beta), "damping" (zeta), "stiffness" (K), "forcing" (B0, B1, D)

    @property
    def symbol(self) -> sp.Symbol:
        return parameter_symbol(self.name)


@dataclass(frozen=True)
class Condition:
    """An equation the reduction requires or assumes, with the reason."""

    equation: sp.Eq
    description: str
    kind: str  # "time_unit" | "torque_balance"


@dataclass(frozen=True)
class StiffnessFunction:
    """The nondimensional mesh stiffness k(tau) of one mesh."""

    name: str
    mesh: str
    definition: sp.Expr  # m * kZ(t): the group, in the declared parameters
    expression: sp.Expr  # its value as a function of tau (replaceable)
    period: sp.Expr  # 2 pi / mesh order: a replacement must keep it

    @property
    def applied(self) -> sp.Expr:
        return sp.Function(self.name, real=True)(tau)


@dataclass
class NondimensionalModel:
    """A drivetrain reduced to relative coordinates and written in tau = omega t."""

    reduction: Reduction
    groups: list[Group] = field(default_factory=list)
    conditions: list[Condition] = field(default_factory=list)
    functions: list[StiffnessFunction] = field(default_factory=list)
    row_lhs: list[sp.Expr] = field(default_factory=list)  # per coordinate: the sum of its terms besides x''
    row_rhs: list[sp.Expr] = field(default_factory=list)  # per coordinate: its forcing numerator (over omega^2)
    coupling_rows: dict[str, tuple[tuple[int, sp.Expr], ...]] = field(default_factory=dict)  # coupling -> (row, factor)

    @property
    def name(self) -> str:
        return self.reduction.drivetrain.name

    @property
    def drivetrain(self) -> Drivetrain:
        return self.reduction.drivetrain

    @property
    def coordinates(self):
        return self.reduction.coordinates

    def group(self, name: str) -> Group:
        for gr in self.groups:
            if gr.name == name:
                return gr
        raise UnknownParameterError(name, [gr.name for gr in self.groups], f"{self.name} groups")

    # ------------------------------------------------------------- equations
    @cached_property
    def equations(self) -> list[sp.Eq]:
        """Second-order equations in tau, in the paper's layout (x'' + ... = (...)/omega^2)."""
        out = []
        for c, lhs, rhs in zip(self.coordinates, self.row_lhs, self.row_rhs):
            out.append(sp.Eq(sp.diff(c.of(tau), tau, 2) + lhs, rhs / omega**2 if rhs != 0 else sp.S.Zero,
                             evaluate=False))
        return out

    @cached_property
    def states(self) -> tuple[sp.Symbol, ...]:
        out = []
        for c in self.coordinates:
            out += [sp.Symbol(c.name, real=True), sp.Symbol(c.velocity_name, real=True)]
        return tuple(out)

    @cached_property
    def _to_state_symbols(self) -> Replacer:
        """x'(tau) -> v and x(tau) -> x (a rate first: the whole derivative, not its function)."""
        return Replacer({**{sp.Derivative(c.of(tau), tau): sp.Symbol(c.velocity_name, real=True)
                            for c in self.coordinates},
                         **{c.of(tau): sp.Symbol(c.name, real=True) for c in self.coordinates}})

    @cached_property
    def rhs(self) -> tuple[sp.Expr, ...]:
        """First-order right-hand side d(x, v)/dtau, with groups and k(tau) as symbols."""
        out = []
        for c, lhs, rhs in zip(self.coordinates, self.row_lhs, self.row_rhs):  # (the equations' x'' = rhs - lhs)
            out.append(sp.Symbol(c.velocity_name, real=True))
            out.append(self._to_state_symbols((rhs / omega**2 if rhs != 0 else sp.S.Zero) - lhs))
        return tuple(out)

    @cached_property
    def forcing_period(self) -> sp.Expr:
        """The forcing period in tau: one mesh period of the first mesh (2 pi / its order; 2 pi without a mesh).
        Steps are counted per forcing period, so that a mesh of another order (a second stage) costs periods,
        not accuracy."""
        return self.reduction.resolved.forcing_period

    @cached_property
    def period(self) -> sp.Expr:
        """The period the model repeats on, in tau (the resolved drivetrain's: every mesh's order, the torques'
        harmonics and with shaft-order terms, a tooth fault or an eccentric gear, theirs): the forcing period for
        a single pair, the common period of the meshes of a multi-stage box (61 mesh periods of a 23/61 first
        stage), a gear's revolution or the hunting period. Every analysis runs on it."""
        return self.reduction.resolved.period

    @property
    def cycles(self) -> int:
        """Forcing periods (mesh periods of the first mesh) in one :attr:`period`: 1 for a single pair."""
        return self.reduction.resolved.cycles

    # ------------------------------------------------------------- parameters
    @cached_property
    def parameter_names(self) -> list[str]:
        """Parameters of the nondimensional model: omega, free groups, then the rest by name."""
        # (the names of the right-hand side with its stiffness functions and derived groups written out, without
        # writing them out: substituting into a large model's rows costs seconds)
        symbols = set().union(*(f.free_symbols for f in self.rhs))
        applied = set().union(*(f.atoms(AppliedUndef) for f in self.rhs))
        for sf in self.functions:
            if sf.applied in applied:
                symbols |= sf.expression.free_symbols
        derived = {gr.symbol: gr.definition for gr in self.groups if gr.kind == "derived" and gr.symbol in symbols}
        symbols = (symbols - set(derived)).union(*(d.free_symbols for d in derived.values()))
        expr_syms = {s.name for s in symbols if s.name not in RESERVED}
        expr_syms -= {s.name for s in self.states}
        free = [gr.name for gr in self.groups if gr.kind == "free" and gr.name in expr_syms]
        rest = sorted(expr_syms - set(free) - {"omega"})
        return ["omega"] + free + rest

    def _absorbing(self, name: str) -> list[str]:
        """Groups and functions that absorb the component parameter ``name``."""
        out = [gr.name for gr in self.groups if gr.kind == "free" and name in parameter_names(gr.definition)]
        for f in self.functions:
            # the definition holds kZ(t) as a function; the mean stiffness kZ is a symbol of the mesh
            names = parameter_names(f.definition) | parameter_names(self._mesh(f).stiffness)
            names |= {type(a).__name__ for a in f.definition.atoms(AppliedUndef)}
            if name in names:
                out.append(f.name)
        return out

    def _mesh(self, f: StiffnessFunction) -> ResolvedCoupling:
        return next(rc for rc in self.reduction.resolved.couplings if rc.name == f.mesh)

    @property
    def defaults(self) -> dict[str, float]:
        """Declared default of every parameter; errors name what is missing or unknown."""
        return self._defaults_except(())

    @property
    def declared_defaults(self) -> dict[str, float]:
        """The parameters' declared defaults, checked; those without one are left out (no error)."""
        return self._defaults_except(self.parameter_names, strict=False)

    def _defaults_except(self, given, strict: bool = True) -> dict[str, float]:
        """Declared defaults of the parameters; with ``strict``, an error names those that have none and are
        not ``given`` (values passed instead)."""
        declared = self.drivetrain.defaults
        fnames = {f.name for f in self.functions}
        allowed = set(self.parameter_names) | fnames
        for name in declared:
            if name in allowed:
                continue
            absorbed = self._absorbing(name)
            if absorbed:
                raise ModelError(
                    f"{name!r} is not a parameter of the reduced model: it only enters through "
                    f"{', '.join(absorbed)}; set those instead",
                    f"{self.name}: set_defaults",
                )
            raise UnknownParameterError(name, allowed, f"{self.name}: set_defaults")
        out = {name: self._number(name, declared[name], "default") for name in self.parameter_names
               if name in declared}
        missing = [name for name in self.parameter_names if name not in declared and name not in given]
        if missing and strict:
            hints = []
            for name in missing:
                gr = next((gr for gr in self.groups if gr.name == name), None)
                hints.append(f"{name} ({gr.description}: {gr.definition})" if gr else name)
            raise ModelError(
                "parameters without a default value: " + "; ".join(hints)
                + f". Add them with model.set_defaults({missing[0]}=...) or pass them as values",
                self.name,
            )
        return out

    @cached_property
    def _constraints(self) -> dict[str, Constraint]:
        """name -> what it is and which values it may take, for parameters that have a physical sign or range."""
        rd = self.reduction.resolved
        out: dict[str, Constraint] = {"omega": Constraint("the forcing frequency", False)}
        for rb in rd.bodies:
            for value, what in ((rb.inertia, "an inertia"), (rb.radius, "a radius")):
                if isinstance(value, sp.Symbol):
                    out[value.name] = Constraint(what, False)
        for rb in rd.translations:
            if isinstance(rb.inertia, sp.Symbol):
                out[rb.inertia.name] = Constraint("a mass", False)
        for rc in rd.couplings:
            for value, what in ((rc.backlash, "a backlash"), (rc.damping, "a damping"), (rc.stiffness, "a stiffness")):
                if isinstance(value, sp.Symbol):
                    out.setdefault(value.name, Constraint(what, True))
        for gr in self.groups:
            if gr.role == "damping":
                out[gr.name] = Constraint("a damping ratio", True)
            elif gr.role == "stiffness":
                out[gr.name] = Constraint("a relative mesh stiffness", False)
        for term in self.drivetrain.shaft_terms:  # (a tooth fault's depth: a fraction below 1)
            out.update(term.constraints())
        return out

    def check_value(self, name: str, value: ExprLike) -> float:
        """``value`` as a float, if it is a number with the sign parameter ``name`` must have."""
        return self._number(name, value, "value")

    def _number(self, name: str, value: ExprLike, what: str) -> float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):  # sweeps: no parsing per point
            number = float(value)
        else:
            expr = to_expr(value, f"{what} of {name}")
            if not expr.is_number:
                raise ModelError(f"the {what} must be a number, got {value!r}", f"parameter {name!r}")
            number = float(expr)
        constraint = self._constraints.get(name)
        must = constraint.violation(number) if constraint else None
        if must:
            raise ModelError(f"is {constraint.meaning} and {must}, got {number:g}", f"parameter {name!r}")
        return number

    def stiffness_formula(self, f: StiffnessFunction, value: ExprLike) -> sp.Expr:
        """A formula for the stiffness function ``f`` as a function of tau. It is written in tau (the forcing
        phase, omega t) or phi (the mesh's phase, its order times tau plus its phase: the variable a declared
        stiffness variation is written in); t (time in 1/omega_n) is refused, since k(tau) must keep its period
        whatever omega is."""
        where = f"stiffness function {f.name} (mesh {f.mesh!r})"
        expr = to_expr(value, where)
        if t in expr.free_symbols:
            raise ModelError(f"{f.name}={_quoted(value)} uses t, but a mesh stiffness is a function of tau (the "
                             f"forcing phase omega t) or phi (the mesh phase, {self._mesh_phase(f)}): e.g. "
                             f"{f.name}=1+0.2*cos(tau)", where)
        expr = expr.xreplace({phi: self._mesh_phase(f)})
        used_states = sorted({st.name for st in self.states} & {sym.name for sym in expr.free_symbols})
        if used_states:
            raise ModelError(f"a mesh stiffness is a function of tau and parameters, but {value!r} uses the "
                             f"state(s) {', '.join(used_states)}; rename the parameter", where)
        check_periodic(expr, tau, where, period=f.period)
        return expr

    def _mesh_phase(self, f: StiffnessFunction) -> sp.Expr:
        """phi of the mesh of ``f`` in tau: its order times tau plus its phase."""
        return sp.expand(self._mesh(f).mesh_phase.subs(t, tau / omega))

    def _substituted_rhs(self, functions: Optional[Mapping[str, sp.Expr]]) -> list[sp.Expr]:
        fsub = {}
        for sf in self.functions:
            expr = sf.expression if functions is None or sf.name not in functions else functions[sf.name]
            fsub[sf.applied] = expr
        gsub = {gr.symbol: gr.definition for gr in self.groups if gr.kind == "derived"}
        # (one pass: the functions' expressions with the groups already written out)
        groups = Replacer(gsub)
        both = Replacer({**{k: groups(v) for k, v in fsub.items()}, **gsub})
        return [both(f) for f in self.rhs]

    def system(self, *, initial: Optional[Mapping[str, float]] = None, **settings: ExprLike) -> FirstOrderSystem:
        """The first-order system for the engine.

        ``settings`` override parameter values (``omega=1.2``) or replace a mesh
        stiffness function by a formula in tau (``k="1 + a*cos(tau)"``, then
        ``a=0.3`` gives the new parameter its value). A default for a function
        name in ``set_defaults`` replaces it the same way. ``initial`` is the default initial state in the
        engine's units (a scaling gives it for a model with physical values); else the declared one.
        """
        rhs, names, functions = self._engine(settings)
        defaults = self._defaults_except(set(settings) | (set(self.parameter_names) - set(names)))
        params = {}
        for name in names:
            if name in settings:
                params[name] = self._number(name, settings[name], "value")
            elif name in defaults:
                params[name] = defaults[name]
            else:
                raise ModelError(f"parameter {name!r} of a replaced stiffness function needs a value: pass {name}=...", self.name)
        descriptions = dict(self.drivetrain.descriptions)
        for gr in self.groups:
            descriptions.setdefault(gr.name, gr.description)
        for name, role in parameter_roles(self.reduction.resolved).items():  # (what the model does not describe)
            descriptions.setdefault(name, role)
        constraints = {name: c for name, c in self._constraints.items() if name in params}
        return FirstOrderSystem(self.name, tau, self.states, rhs, params, self.period, descriptions,
                                self.drivetrain.title, tuple(c.name for c in self.coordinates),
                                self._initial(initial), self._system_couplings(functions), constraints,
                                cycles=self.cycles, translations=self.translations)

    @cached_property
    def translations(self) -> dict[str, sp.Expr]:
        """Each translation of a body centre on a bearing in the states (``pinion_y`` -> y_pinion), where the
        coordinates determine it (a planet's tangential translation moves with the rigid-body rotation: none)."""
        red = self.reduction
        rd = red.resolved
        out = {}
        if not rd.translations:
            return out
        by_row = {}
        for c in red.coordinates:
            row = [e for e in red.transform.row(red.coordinates.index(c))]
            nonzero = [i for i, e in enumerate(row) if e != 0]
            if len(nonzero) == 1 and row[nonzero[0]] == 1:
                by_row[nonzero[0]] = sp.Symbol(c.name, real=True)
        # (in the geometry's symbols, where the algebra is rational, when the transform is theirs with the numbers in:
        # then the weights' numbers go in at the end)
        geometry = rd.geometry
        transform = red.transform.xreplace({v: k for k, v in geometry.items()}) if geometry else red.transform
        if geometry and transform.xreplace(geometry) != red.transform:
            transform, geometry = red.transform, {}
        pending = [d for d in rd.translations if d.index not in by_row]
        targets = [sp.Matrix([[1 if j == d.index else 0 for j in range(transform.cols)]]) for d in pending]
        free = dict(zip((d.index for d in pending), outside_span(transform, targets))) if pending else {}
        determined = [d for d in pending if not free[d.index]]  # (the others: not determined by the coordinates)
        solved = dict(zip((d.index for d in determined), combination_solver(transform).many(
            [targets[pending.index(d)] for d in determined]))) if determined else {}
        for d in rd.translations:
            name = d.label.replace(".", "_")
            if d.index in by_row:
                out[name] = by_row[d.index]
            elif d.index in solved:
                weights = [w.xreplace(geometry) if geometry else w for w in solved[d.index]]
                out[name] = sp.Add(*(w * sp.Symbol(c.name, real=True) for w, c in zip(weights, red.coordinates)))
        return out

    def _initial(self, initial: Optional[Mapping[str, float]]) -> dict[str, float]:
        """The initial state in the engine's units: ``initial``, or the declared numbers (a physical value needs
        the model's scaling to become one)."""
        declared = self.drivetrain.initial_state if initial is None else dict(initial)
        for name, value in declared.items():
            if not isinstance(value, (int, float)):
                raise ModelError(f"the initial state {name} = {value} is a physical value: make the system from the "
                                 "model's physical values (gearsym.load or gearsym.scaling(...).system())", self.name)
        return {name: float(value) for name, value in declared.items()}

    def engine_equations(self, **settings: ExprLike) -> tuple[tuple[sp.Expr, ...], list[str]]:
        """The right-hand side :meth:`system` gives the engine (k(tau) written out, derived groups expanded)
        and its parameters in order; symbolic, so no parameter needs a value. ``settings`` are checked
        names; those naming a stiffness function replace it."""
        rhs, names, _ = self._engine(settings)
        return rhs, names

    def _engine(self, settings: Mapping[str, ExprLike]) -> tuple[tuple[sp.Expr, ...], list[str], dict]:
        """:meth:`engine_equations`, and the stiffness functions written into them."""
        declared = self.drivetrain.defaults
        functions = {f.name: self.stiffness_formula(f, declared[f.name]) for f in self.functions if f.name in declared}
        for f in self.functions:
            if f.name in settings:
                functions[f.name] = self.stiffness_formula(f, settings[f.name])
        rhs = tuple(self._substituted_rhs(functions))
        used = set()
        for expr in rhs:
            used |= parameter_names(expr)
        used -= {s.name for s in self.states}
        fnames = {f.name for f in self.functions}
        for key in settings:
            if key not in fnames and key not in used and key not in self.parameter_names:
                raise UnknownParameterError(key, set(self.parameter_names) | fnames | used, self.name)
        names = [n for n in self.parameter_names if n in used or n == "omega"]
        return tuple(rhs), names + sorted(used - set(names)), functions

    def _system_couplings(self, functions: Mapping[str, sp.Expr]) -> tuple[Coupling, ...]:
        """Every coupling as the first-order system carries it, in the system's own terms (stiffness
        functions and derived groups written out, as in its right-hand side)."""
        derived = {gr.symbol: gr.definition for gr in self.groups if gr.kind == "derived"}
        own = {f.mesh: functions.get(f.name, f.expression) for f in self.functions}
        out = []
        for c in self.reduction.deflections:
            rc = c.coupling
            stiffness = own[rc.name] if rc.kind == "mesh" else rc.stiffness
            rows = tuple((2 * r + 1, factor.xreplace(derived)) for r, factor in self.coupling_rows[rc.name])
            contact, rate = c.in_states()
            error = transmission_error(rc)
            out.append(Coupling(rc.name, rc.kind, c.name, c.velocity_name, rc.backlash, stiffness.xreplace(derived),
                                rc.order, rows, None if c.independent and error == 0 else contact - error,
                                None if c.independent else rate, gears_of(rc)))
        return tuple(out)


def transmission_error(rc: ResolvedCoupling) -> sp.Expr:
    """A mesh's transmission error from shaft-order terms, in tau (0 without)."""
    if rc.kind != "mesh" or rc.error == 0:
        return sp.S.Zero
    return rc.error.subs(phi, sp.expand(rc.mesh_phase.subs(t, tau / omega)))


def gears_of(rc: ResolvedCoupling) -> tuple[Gearing, ...]:
    """The two gears of a mesh, with their tooth counts (none for a shaft)."""
    if rc.kind != "mesh":
        return ()
    return tuple(Gearing(end.body.name, end.body.tooth_count) for end in (rc.a, rc.b))


# ============================================================================ construction
#: the geometry's symbols of the drivetrain being assembled (symbol -> what it stands for), for _equal
_GEOMETRY: dict = {}


def _generic_number(name: str) -> sp.Rational:
    """A fixed generic value for the parameter ``name`` (the same in every process)."""
    code = zlib.crc32(name.encode())
    return sp.Rational(11 + code % 89, 11 + (code // 89) % 83)


def fingerprint(expr: sp.Expr) -> sp.Float:
    """``expr`` at generic values of its parameters, with the geometry's numbers: two definitions that differ
    differ here (for almost all values)."""
    leaves = {}
    for s in expr.free_symbols:
        atom = _GEOMETRY.get(s)
        leaves[s] = _generic_number(s.name) if atom is None else \
            atom.xreplace({a: _generic_number(a.name) for a in atom.free_symbols})
    try:  # (evaluated as it stands, each subexpression once: rebuilding it with the numbers in cost seconds)
        return sp.Float(PointValues(leaves, 40)(expr), 30)
    except KeyError:  # (a function of time, say: SymPy's evaluation says what it can)
        return sp.N(expr.xreplace(_GEOMETRY).xreplace(leaves), 30)


def _equal(a: sp.Expr, b: sp.Expr) -> bool:
    """Whether two group definitions (rational functions of the parameters) are the same: different at generic
    values is enough to tell them apart, and equal ones are confirmed exactly (with the geometry's numbers, whose
    relations may make two different-looking definitions equal)."""
    difference = a - b
    try:
        number = fingerprint(difference)
    except ZeroDivisionError:
        number = None
    if number is not None and number.is_number and abs(number) > sp.Float(10) ** -20 * (
            1 + abs(fingerprint(a))):
        return False
    if _GEOMETRY and difference.free_symbols & set(_GEOMETRY):
        return simplified(difference.xreplace(_GEOMETRY)) == 0
    return sp.cancel(difference) == 0


def _coordinate_suffix(red: Reduction, row: int) -> str:
    return "" if row == 0 else f"_{red.coordinates[row].name}"


class _Assembly:
    """The groups, conditions, stiffness functions and rows of a NondimensionalModel as they are named,
    in the order the paper names them: shafts, then meshes, then the forcing of each row."""

    def __init__(self, red: Reduction):
        self.red = red
        n = len(red.coordinates)
        self.groups: list[Group] = []
        self.conditions: list[Condition] = []
        self.functions: list[StiffnessFunction] = []
        self.lhs = [sp.S.Zero] * n  # sum of the terms besides x'' in each row
        self.rhs = [sp.S.Zero] * n  # forcing numerators (over omega^2)
        self.coupling_rows: dict[str, list[tuple[int, sp.Expr]]] = {}  # coupling -> (row, factor of its law)
        self._betas: dict[sp.Expr, sp.Expr] = {}
        self._beta_keys: dict = {}  # generic value (15 digits) -> [(definition, group symbol)]
        self._forcing: list[tuple[tuple, Group]] = []  # ((order, phase), group) of the forcing groups named

    def add_group(self, gr: Group) -> Group:
        """Add a group; one named like a group already added (meshes that declare the same damping_group, say)
        is that group if its definition is the same, and an error otherwise."""
        for known in self.groups:
            if known.name == gr.name:
                if known.kind != gr.kind or not _equal(known.definition, gr.definition):
                    raise ModelError(f"two groups are named {gr.name!r} but differ: {known.definition} "
                                     f"({known.description}) and {gr.definition} ({gr.description}); give them "
                                     "distinct names", self.red.drivetrain.name)
                return known
        self.groups.append(gr)
        return gr

    def beta(self, definition: sp.Expr, description: str) -> sp.Expr:
        """The group standing for ``definition`` (one per distinct value), or the number itself."""
        if definition.is_number:
            return definition
        key = fingerprint(definition)
        key = sp.Float(key, 15) if key.is_number else definition  # (candidates: the same value at generic values)
        for known, sym in self._beta_keys.get(key, ()):
            if _equal(known, definition):
                return sym
        gr = Group(f"beta_{len(self._betas) + 1}", definition, "derived", description, "coupling")
        self.groups.append(gr)
        self._betas[definition] = gr.symbol
        self._beta_keys.setdefault(key, []).append((definition, gr.symbol))
        return gr.symbol

    def own_factor(self, rc: ResolvedCoupling) -> sp.Expr:
        """The factor of a coupling's law in its own row; for one that closes a loop (no row of its own) the
        same quantity, C_c M^-1 C_c^T (r_a^2/I_a + r_b^2/I_b + ... along its line of action)."""
        red = self.red
        own = red.deflection_of(rc)
        if own.independent:
            row = red.coordinates.index(own)
            return next(ct.factor for ct in red.row_terms(row) if ct.coupling is rc)
        inertias = [rb.inertia for rb in red.resolved.dofs]
        return sp.factor(sp.Add(*(e**2 / i for e, i in zip(rc.row, inertias))))

    def add_shaft(self, rc: ResolvedCoupling) -> None:
        """beta * (kS x + cS x') in every row the shaft (or bearing: a linear spring too) reaches."""
        red = self.red
        x = red.deflection_of(rc).contact(tau)
        for ct in (ct for ct in red.coupling_terms if ct.coupling is rc):
            b = self.beta(sp.expand(ct.factor), f"coupling of {rc.kind} {rc.name!r} into {red.coordinates[ct.row].name}")
            self.lhs[ct.row] += b * rc.stiffness * x / omega**2 + b * rc.damping * sp.diff(x, tau) / omega
            self.coupling_rows.setdefault(rc.name, []).append((ct.row, b))

    def mesh_law(self, rc: ResolvedCoupling, reference: ResolvedCoupling) -> sp.Expr:
        """The mesh's terms in its own row, ``2 zeta x'/omega + k(tau) g(x, eta)/omega^2``: the own-row
        factor m is absorbed into its stiffness and damping, naming k(tau), zeta (and K for a second mesh)."""
        red = self.red
        cx = red.deflection_of(rc)
        suffix = "" if rc is reference else f"_{cx.name}"
        m = sp.expand(self.own_factor(rc))
        x = cx.contact(tau)
        comp = rc.component
        fname = comp.function or ("k" if rc is reference else f"k{suffix}")
        phase = sp.expand(rc.mesh_phase.subs(t, tau / omega))
        varied = rc.variation_at(phase)
        if rc is not reference and _equal(m * rc.stiffness, self.own_factor(reference) * reference.stiffness):
            expression = varied  # as stiff as the first mesh (another planet's): 1 by the time-unit condition
        elif rc is reference:
            self.conditions.append(Condition(
                sp.Eq(m * rc.stiffness, 1),
                f"time unit: t is measured in units of 1/omega_n, omega_n^2 being the left-hand side (the mean "
                f"stiffness of mesh {rc.name!r} per unit effective mass), so {fname}(tau) has the mean of the "
                "declared stiffness variation (the paper's convention)",
                "time_unit",
            ))
            expression = varied
        else:
            K = self.add_group(Group(comp.stiffness_group or f"K{suffix}", m * rc.stiffness, "free",
                                     f"mean stiffness of mesh {rc.name!r} relative to the first mesh", "stiffness"))
            expression = K.symbol * varied
        repeats = functools.reduce(sp.gcd, (rc.order, *rc.shaft_frequencies)) if rc.loss != 0 else rc.order
        kfun = StiffnessFunction(fname, rc.name, m * red.resolved.stiffness_at(rc).subs(t, tau / omega),
                                 expression, 2 * sp.pi / repeats)
        self.functions.append(kfun)
        terms = kfun.applied * g(x - transmission_error(rc), rc.backlash) / omega**2
        if rc.damping != 0:
            zeta = self.add_group(Group(comp.damping_group or f"zeta{suffix}", m * rc.damping / 2, "free",
                                        f"damping ratio of mesh {rc.name!r}", "damping"))
            terms = 2 * zeta.symbol * sp.diff(x, tau) / omega + terms
        return terms

    def add_mesh_rows(self, rc: ResolvedCoupling, law: sp.Expr) -> None:
        """The law in its own row; in the other rows, times beta = factor / m (the paper's beta3)."""
        red = self.red
        m = self.own_factor(rc)
        for ct in (ct for ct in red.coupling_terms if ct.coupling is rc):
            if ct.factor == m and red.coordinates[ct.row] is red.deflection_of(rc):
                self.lhs[ct.row] += law
                self.coupling_rows.setdefault(rc.name, []).append((ct.row, sp.S.One))
            else:
                b = self.beta(sp.expand(ct.factor) / sp.expand(m),
                              f"share of mesh {rc.name!r} force in {red.coordinates[ct.row].name}")
                self.lhs[ct.row] += sp.expand(b * law)
                self.coupling_rows.setdefault(rc.name, []).append((ct.row, b))

    def add_frame(self, ratio: sp.Expr) -> None:
        """The turning frame's forces of each row in tau: with Omega_c = ratio * omega (the carrier's speed over
        the forcing frequency, from the tooth counts), ``2 Omega_c x'`` becomes ``2 ratio x'(tau)`` and
        ``Omega_c^2 x`` becomes ``ratio^2 x``: the frame's terms do not depend on omega in tau."""
        red = self.red
        speed = sp.Symbol(CARRIER_SPEED, real=True)
        # every term is Omega_c x' or Omega_c^2 x: omega^2 in tau, which the division by omega^2 takes out; so
        # omega is left out of the substitution instead (the rows stay unexpanded: see _frame_rows)
        in_tau = Replacer({**{sp.Derivative(c.of(t), t): sp.diff(c.of(tau), tau) for c in red.coordinates},
                           **{c.of(t): c.of(tau) for c in red.coordinates}, speed: ratio})
        for row, force in enumerate(red.frame_rows):
            self.lhs[row] -= in_tau(force)

    def add_forcing(self, row: int) -> None:
        """The forcing of one row, grouped by harmonic into B0, B1, D, ...; an unforced shaft's constant
        forcing becomes the torque-balance condition (Eq. 10)."""
        red = self.red
        cx = red.coordinates[row]
        by_key: dict = {}
        for ft in red.row_forcing(row):
            by_key.setdefault(ft.key, []).append(ft)
        used_names: set[str] = {gr.name for gr in self.groups}
        for (order, phase), terms in by_key.items():
            definition = sp.expand(sp.Add(*(ft.coefficient for ft in terms)))
            if definition == 0:
                continue
            if order == 0 and cx.kind == "shaft" and not getattr(cx.coupling.component, "forced", True):
                self.conditions.append(Condition(
                    sp.Eq(0, definition),
                    f"torque balance: no constant torque may load the twist {cx.name} of shaft "
                    f"{cx.coupling.name!r} (declare Shaft(..., forced=True) to keep it as forcing)",
                    "torque_balance",
                ))
                continue
            timefn = sp.S.One if order == 0 else sp.cos(order * tau + phase)
            same = next((gr for key, gr in self._forcing if key == (order, phase) and _equal(gr.definition, definition)),
                        None)  # rows forced alike (a planetary set's sun meshes) share one group
            if same is None:
                name = self._forcing_name(row, order, phase, terms, used_names)
                used_names.add(name)
                what = "constant forcing" if order == 0 else f"forcing amplitude of {timefn}"
                same = Group(name, definition, "free", f"{what} of {cx.name}", "forcing")
                self.groups.append(same)
                self._forcing.append(((order, phase), same))
            self.rhs[row] += same.symbol * timefn

    def _forcing_name(self, row: int, order, phase, terms, used_names: set[str]) -> str:
        red = self.red
        cx = red.coordinates[row]
        hints = sorted({ft.source.group for ft in terms if ft.source.group})
        torques = ", ".join(sorted({repr(ft.source.torque.name) for ft in terms}))
        if len(hints) > 1:
            raise ModelError(
                f"harmonics of the same order and phase are named differently ({', '.join(hints)}); "
                "they add up into one group, so give them one name", f"Torque {torques}",
            )
        base = "B0" if order == 0 else (hints[0] if hints else f"B{order}")
        name = base + _coordinate_suffix(red, row)
        if name in used_names and not hints and order > 0:
            # an unnamed second harmonic of the same order: name it after its phase
            tag = phase.name if isinstance(phase, sp.Symbol) else str(len(used_names))
            name = f"B{order}_{tag}" + _coordinate_suffix(red, row)
        if name in used_names:
            timefn = sp.S.One if order == 0 else sp.cos(order * tau + phase)
            raise ModelError(
                f"the forcing group of {cx.name} from {timefn} would be named {name!r}, "
                "which another group already has; give the harmonic a distinct Harmonic(..., group=...) name",
                f"Torque {torques}",
            )
        return name


def nondimensionalize(red: Reduction) -> NondimensionalModel:
    """Name the coefficient groups of ``red`` and write its equations in tau (the geometry's symbols of gears on
    bearings put back at the end: :func:`with_geometry`)."""
    global _GEOMETRY
    _GEOMETRY = dict(red.resolved.geometry)
    try:
        return _nondimensionalize(red)
    finally:
        _GEOMETRY = {}


def _nondimensionalize(red: Reduction) -> NondimensionalModel:
    build = _Assembly(red)
    meshes = [rc for rc in red.resolved.couplings if rc.kind == "mesh"]
    for rc in red.resolved.couplings:
        if rc.kind != "mesh":
            build.add_shaft(rc)
    laws = {rc.name: build.mesh_law(rc, meshes[0]) for rc in meshes}
    taken = set()
    for rc in red.resolved.couplings:
        taken |= parameter_names(rc.stiffness) | parameter_names(rc.damping) | parameter_names(rc.backlash)
    for rb in red.resolved.dofs:
        taken |= parameter_names(rb.inertia)
    for f in build.functions:
        if f.name in taken:
            raise ModelError(f"the stiffness function of mesh {f.mesh!r} would be named {f.name!r}, which is a "
                             "parameter of the model too; name it otherwise: Mesh(..., function='k_...')",
                             red.drivetrain.name)
    for rc in meshes:
        build.add_mesh_rows(rc, laws[rc.name])
    for row in range(len(red.coordinates)):
        build.add_forcing(row)
    if red.frame_rows:
        build.add_frame(red.resolved.carrier_speed_ratio())
    groups = sorted(build.groups, key=lambda gr: gr.kind == "derived")  # stable: free groups first, betas in order
    rows = {name: tuple(rows) for name, rows in build.coupling_rows.items()}
    geometry = red.resolved.geometry
    if not geometry:
        return NondimensionalModel(red, groups, build.conditions, build.functions, build.lhs, build.rhs, rows)

    sub = Replacer(geometry)
    return NondimensionalModel(
        with_geometry(red), [replace(gr, definition=sub(gr.definition)) for gr in groups],
        [replace(c, equation=sp.Eq(simplified(sub(c.equation.lhs)), sub(c.equation.rhs))) for c in build.conditions],
        [replace(f, definition=f.definition.xreplace(geometry)) for f in build.functions],
        [sub(e) for e in build.lhs], [sub(e) for e in build.rhs],
        {name: tuple((r, sub(f)) for r, f in pairs) for name, pairs in rows.items()})


def reduce(model: Drivetrain) -> NondimensionalModel:
    """Derive the equations of motion, reduce them and write the nondimensional form.

    The result is cached on the drivetrain until it changes (add, set_defaults, describe).
    """
    cached = model.__dict__.get("_reduced")
    if cached is not None and cached[0] == model.version:
        return cached[1]
    nd = nondimensionalize(reduce_drivetrain(model, numbers=False))
    model.__dict__["_reduced"] = (model.version, nd)
    return nd


def _quoted(value: ExprLike) -> str:
    return repr(value) if isinstance(value, str) else str(value)
