"""The CasADi functions of one model: right-hand side, exact Jacobian, and the
fixed-step RK4 loops with their variational equations.

Layering (the CasADi pitfall: a loop Function called on SX symbols is inlined,
and 80 000 inlined RK4 steps crash the C compiler):

* SX, straight-line code with common subexpressions removed: ``rhs``,
  ``jacobian``, one RK4 step of the state and its tangent matrix (a *block*),
  the Gram-Schmidt re-orthonormalisation;
* MX, which calls those functions instead of inlining them: one forcing
  period calls the block N times and then Gram-Schmidt; a *chunk* calls the
  period 50 times. Shared inputs (tables, constants) reach every call by
  pointer (``mapaccum`` would copy them into each iteration: 16 % of the time,
  measured). A run is a few chunk calls; nothing per step or period is Python.

The compiled library does not run these MX loops: :mod:`.printed` prints them in C around the SX step (the
state in local arrays, no call through pointer arrays per step). They are what the in-process backend
evaluates, and the reference the printed loops are tested against (the same bits without FMA).

Tangent vectors follow the exact variational equations Q' = J(t, y) Q,
integrated by the same RK4 as the state (RK4 of the augmented system), so the
tangent map is the exact derivative of the discrete flow.

Parameters are an input vector ``p`` in ``system.parameters`` order: changing
a value never regenerates or recompiles anything.

``LoopOptions(locate_crossings=True)`` makes every step that crosses a backlash
switching surface split there, so that RK4 sees a smooth right-hand side on
both substeps (see ``_crossing_steps``); the split runs only on crossing steps,
behind a real ``if`` in the C (in the MX loops a CasADi ``Switch``), as calls of
SX pieces (``SPLIT_CALLS``): one mode-RK4 step for every substep.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import sympy as sp

from ..backlash import G, g, g_slope
from ..errors import ModelError
from ..system import FirstOrderSystem
from .time_tables import SplitRHS, split_rhs
from .loops import LoopOptions  # (here before it had a module of its own)
from .translate import select_max, select_min, to_casadi


@dataclass(frozen=True)
class ModelFunctions:
    """Every CasADi Function of one model, ready to generate or to evaluate in-process."""

    system: FirstOrderSystem
    options: LoopOptions
    split: SplitRHS
    functions: dict[str, ca.Function]
    #: the SX pieces the printed loops call (:mod:`.printed`): ``tangent_state``, ``tangent_vector`` (the tangent
    #: step, or with crossings located its try, by vector), ``state_block`` (plain; and ``trajectory_step`` for
    #: blocks of several steps) or ``state_try``, ``{tangent,state}_keep`` and the split's pieces (located,
    #: :data:`SPLIT_CALLS`), and ``gram_schmidt``
    steps: dict[str, ca.Function]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.functions)


def build_functions(system: FirstOrderSystem, options: LoopOptions = LoopOptions()) -> ModelFunctions:
    """Every function the engine generates for ``system`` (see the module docstring)."""
    split = split_rhs(system, factored=options.locate_crossings)
    sym = _Symbols(system, split)
    n, m, nc = system.dimension, len(split.tables), len(split.constants)
    N, K = options.steps_per_period, options.block(n)
    where = system.name

    # rhs and Jacobian in the user's terms (time, state, parameters)
    f_user = sym.base.rhs(system)
    rhs = ca.Function("rhs", [sym.t, sym.y, sym.p], [f_user], ["t", "y", "p"], ["dy"], _OPTS)
    jacobian = ca.Function("jacobian", [sym.t, sym.y, sym.p], [ca.densify(ca.jacobian(f_user, sym.y))],
                           ["t", "y", "p"], ["J"], _OPTS)

    # what the loops need once per run: constants (then the step h), tables of time
    period_expr, h_expr = to_casadi([system.period, system.period / N], sym.outer, where)
    if ca.depends_on(period_expr, ca.vertcat(sym.t, sym.y)):
        raise ModelError(f"the forcing period {system.period} may depend on parameters only", where)
    const_values = to_casadi([e for _, e in split.constants], sym.outer, where)
    constants = ca.Function("constants", [sym.p], [ca.vertcat(*const_values, h_expr), period_expr], ["p"],
                            ["c", "period"], _OPTS)
    table_values = to_casadi([e for _, e in split.tables], sym.outer, where)
    table_point = ca.Function("table_point", [sym.t, sym.p], [ca.vertcat(*table_values) if m else ca.SX(0, 1)],
                              ["t", "p"], ["values"], _OPTS)

    switching = _switching(system, split) if options.locate_crossings else None
    if switching is None or not switching.surfaces:  # nothing switches (Lorenz): the plain loops
        tangent_block, state_block, state_step = _rk4_functions(sym, split, K, where)
        steps = {**_tangent_by_vector(sym, split, K, where), "state_block": state_block}
        if K > 1:  # the trajectory's steps one at a time
            steps["trajectory_step"] = state_step
    else:
        tangent_block, state_block, state_step, steps = _crossing_steps(sym, split, switching, where)
    gram_schmidt = _gram_schmidt(n)
    steps["gram_schmidt"] = gram_schmidt

    # MX loops over the SX functions
    Ym, Qm, Cm = ca.MX.sym("y", n), ca.MX.sym("Q", n, n), ca.MX.sym("c", nc + 1)
    Tm = ca.MX.sym("T", 3 * m, N)
    obs0 = ca.vertcat(*[Ym[j] for j in sym.observed])

    yk, Qk, lk, hk = _over_period(tangent_block, [Ym, Qm, obs0, obs0], Tm, Cm, K, "tangent")
    Qn, logr = gram_schmidt(Qk)
    lyapunov_period = ca.Function("lyapunov_period", [Ym, Qm, Tm, Cm], [yk, Qn, logr, lk, hk],
                                  ["y0", "Q0", "table", "c"], ["strobe", "Q", "log_stretch", "low", "high"])
    yk, Qk, rows = Ym, Qm, []
    for _ in range(options.chunk_periods):
        yk, Qk, logr, lk, hk = lyapunov_period(yk, Qk, Tm, Cm)
        rows.append((yk, logr, lk, hk))
    strobe, logr, low, high = (ca.horzcat(*col) for col in zip(*rows))
    lyapunov_chunk = ca.Function("lyapunov_chunk", [Ym, Qm, Tm, Cm], [strobe, Qk, logr, low, high],
                                 ["y0", "Q0", "table", "c"], ["strobe", "Q", "log_stretch", "low", "high"])

    yk, lk, hk = _over_period(state_block, [Ym, obs0, obs0], Tm, Cm, K, "state")
    orbit_period = ca.Function("orbit_period", [Ym, Tm, Cm], [yk, lk, hk], ["y0", "table", "c"],
                               ["strobe", "low", "high"])
    yk, rows = Ym, []
    for _ in range(options.chunk_periods):
        yk, lk, hk = orbit_period(yk, Tm, Cm)
        rows.append((yk, lk, hk))
    orbit_chunk = ca.Function("orbit_chunk", [Ym, Tm, Cm], [ca.horzcat(*col) for col in zip(*rows)],
                              ["y0", "table", "c"], ["strobe", "low", "high"])

    # every step of one period, for phase portraits
    Yt = state_step.mapaccum("steps", N, 1)(Ym, Tm, Cm)
    trajectory = ca.Function("trajectory", [Ym, Tm, Cm], [Yt], ["y0", "table", "c"], ["states"])

    monodromy_segment, monodromy_period = _monodromy(tangent_block, obs0, Ym, Qm, Cm, m, N, K)

    table = _table_function(constants, table_point, len(sym.params), nc, m, N)
    functions = {f.name(): f for f in (rhs, jacobian, constants, table, lyapunov_chunk, lyapunov_period,
                                       orbit_chunk, orbit_period, trajectory, monodromy_segment, monodromy_period)}
    return ModelFunctions(system, options, split, functions, steps)


#: a period is shot in up to this many pieces (multiple shooting of strongly unstable orbits)
SHOOTING_SEGMENTS = 4


def shooting_segments(N: int, K: int) -> int:
    """The pieces of a period in ``monodromy_period``: ``SHOOTING_SEGMENTS``, or the largest number below
    that the period's N // K blocks divide into."""
    return max(d for d in range(1, SHOOTING_SEGMENTS + 1) if (N // K) % d == 0)


def _monodromy(tangent_block, obs0, Ym: ca.MX, Qm: ca.MX, Cm: ca.MX, m: int, N: int, K: int):
    """``monodromy_segment``: one piece of a period (``SHOOTING_SEGMENTS`` of them, or the largest number
    below that the period's blocks divide into), the state and the raw tangent matrix Phi Q0 (no
    Gram-Schmidt: the Jacobian of the map, for Newton) with the observed states' min and max over its
    steps; ``monodromy_period``: the pieces of one period in turn (:mod:`gearsym.periodic`)."""
    S = shooting_segments(N, K)
    width = N // S
    Ts = ca.MX.sym("T", 3 * m, width)
    yk, Qk, lk, hk = _over_period(tangent_block, [Ym, Qm, obs0, obs0], Ts, Cm, K, "shooting")
    names = (["y0", "Q0", "table", "c"], ["strobe", "M", "low", "high"])
    segment = ca.Function("monodromy_segment", [Ym, Qm, Ts, Cm], [yk, Qk, lk, hk], *names)
    Tm = ca.MX.sym("T", 3 * m, N)
    yk, Qk, lk, hk = Ym, Qm, obs0, obs0
    for k in range(S):
        yk, Qk, low, high = segment(yk, Qk, Tm[:, k * width:(k + 1) * width], Cm)
        lk, hk = select_min(low, lk), select_max(high, hk)
    period = ca.Function("monodromy_period", [Ym, Qm, Tm, Cm], [yk, Qk, lk, hk], *names)
    return segment, period


_OPTS = {"cse": True}

#: RK4 steps written out in one function. A longer period calls such a segment repeatedly, so the C (and its
#: compile time) stays the same size whatever ``steps_per_period`` is: 3200 steps written out took 24 s to
#: compile. 50 rather than 200: the same speed and the same bits (measured), 2.4x less C.
SEGMENT_STEPS = 50


def _over_period(block, carry: list, T: ca.MX, C: ca.MX, K: int, name: str, group: int = 0) -> list:
    """``block(*carry, T[:, K columns], C)`` applied along all columns of the table ``T``: written out up to
    ``group`` blocks (SEGMENT_STEPS steps), beyond that through segment functions of that many blocks (and
    one for the rest), which are themselves grouped the same way: the code grows with log(steps)."""
    blocks, per = T.size2() // K, group or max(2, SEGMENT_STEPS // K)
    if blocks <= per:
        for b in range(blocks):
            carry = list(block(*carry, T[:, b * K:(b + 1) * K], C))
        return carry

    def segment(count: int) -> ca.Function:
        args = [ca.MX.sym(f"x{i}", c.sparsity()) for i, c in enumerate(carry)]
        Ts, Cs = ca.MX.sym("T", T.size1(), count * K), ca.MX.sym("c", C.sparsity())
        return ca.Function(f"{name}_segment_{count * K}", [*args, Ts, Cs],
                           _over_period(block, args, Ts, Cs, K, name, per))

    whole, rest = divmod(blocks, per)
    carry = _over_period(segment(per), carry, T[:, :whole * per * K], C, per * K, name, per)
    if rest:
        carry = list(segment(rest)(*carry, T[:, whole * per * K:], C))
    return carry


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


class _Symbols:
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


def _tabulated_rhs(sym: _Symbols, split: SplitRHS, where: str) -> tuple[ca.Function, ca.Function]:
    """f and its Jacobian in the loop's terms (state, table values at the stage's time, constants and h)."""
    f_tab = ca.vertcat(*to_casadi(split.rhs, sym.inner, where))
    return (ca.Function("f_tab", [sym.y, sym.T, sym.ch], [f_tab]),
            ca.Function("J_tab", [sym.y, sym.T, sym.ch], [ca.jacobian(f_tab, sym.y)]))


def _rk4_functions(sym: _Symbols, split: SplitRHS, K: int, where: str):
    """K RK4 steps with tangent (``tangent_block``), without (``state_block``), and one plain step."""
    n, m, nc = sym.y.numel(), len(split.tables), sym.ch.numel() - 1
    y, ch = sym.y, sym.ch
    h = ch[nc]
    f_of, J_of = _tabulated_rhs(sym, split, where)
    Q = ca.SX.sym("Q", n, n)
    lo = ca.SX.sym("lo", len(sym.observed))
    hi = ca.SX.sym("hi", len(sym.observed))
    Tk = ca.SX.sym("Tk", 3 * m, K)

    def rk4(yk, Qk, Ta, Tb, Tc):  # Ta, Tb, Tc: table values at t, t + h/2, t + h
        return rk4_step(lambda x, T: f_of(x, T, ch), lambda x, T: J_of(x, T, ch), yk, Qk, h, Ta, Tb, Tc)

    def block(with_tangent: bool):
        yk, Qk, lk, hk = y, (Q if with_tangent else None), lo, hi
        for i in range(K):
            col = Tk[:, i]
            yk, Qk = rk4(yk, Qk, col[:m], col[m:2 * m], col[2 * m:])
            obs = ca.vertcat(*[yk[j] for j in sym.observed])
            lk, hk = select_min(obs, lk), select_max(obs, hk)
        return yk, Qk, lk, hk

    yb, Qb, lb, hb = block(True)
    tangent_block = ca.Function("tangent_block", [y, Q, lo, hi, Tk, ch], [yb, Qb, lb, hb], _OPTS)
    yb, _, lb, hb = block(False)
    state_block = ca.Function("state_block", [y, lo, hi, Tk, ch], [yb, lb, hb], _OPTS)
    col = ca.SX.sym("Ti", 3 * m)
    y_next, _ = rk4(y, None, col[:m], col[m:2 * m], col[2 * m:])
    state_step = ca.Function("trajectory_step", [y, col, ch], [y_next], _OPTS)
    return tangent_block, state_block, state_step


def _tangent_by_vector(sym: _Symbols, split: SplitRHS, K: int, where: str) -> dict[str, ca.Function]:
    """``tangent_block`` in two pieces, for the printed loop: ``tangent_state`` (the state's K steps, as
    ``state_block``, and the Jacobian of every RK4 stage: its nonzeros that are not constants) and
    ``tangent_vector`` (one tangent vector's K steps, given those Jacobians), which the loop applies to each
    tangent vector in turn, a loop the C compiler vectorises (:func:`_by_vector`)."""
    m, nc = len(split.tables), sym.ch.numel() - 1
    y, ch, h = sym.y, sym.ch, sym.ch[nc]
    f_of, J_of = _tabulated_rhs(sym, split, where)
    lo, hi = ca.SX.sym("lo", len(sym.observed)), ca.SX.sym("hi", len(sym.observed))
    Tk = ca.SX.sym("Tk", 3 * m, K)
    columns = [(Tk[:m, i], Tk[m:2 * m, i], Tk[2 * m:, i]) for i in range(K)]
    states, J_all, q, qk, symbols = _by_vector(lambda x, T: f_of(x, T, ch), lambda x, T: J_of(x, T, ch), y, h,
                                                columns)
    lk, hk = lo, hi
    for yk in states:
        obs = ca.vertcat(*[yk[j] for j in sym.observed])
        lk, hk = select_min(obs, lk), select_max(obs, hk)
    state = ca.Function("tangent_state", [y, lo, hi, Tk, ch], [states[-1], lk, hk, J_all], _OPTS)
    vector = ca.Function("tangent_vector", [q, symbols, ch], [qk], _OPTS)
    return {"tangent_state": state, "tangent_vector": vector}


def _by_vector(f, J, y, h, columns: list) -> tuple:
    """RK4 steps of length h from ``y`` (one per ``(Ta, Tb, Tc)`` of ``columns``) split for the printed loops:
    (the state after each step, the nonzeros of every stage's Jacobian that are not constants, a tangent vector
    q, q after the steps given those nonzeros, the symbols that stand for them in it). ``rk4_step`` of the
    tangent matrix computes each of its columns with these operations (``mtimes`` works column by column, and
    the constant entries, which it simplifies, stay constants here), so the pieces give its bits."""
    n = y.numel()
    stages, entries = [], []  # each stage's Jacobian; its distinct non-constant nonzeros

    def recorded(x, T):
        Jx = J(x, T)
        stages.append(Jx)
        entries.extend(e for e in Jx.nonzeros() if not e.is_constant() and _position(entries, e) is None)
        return Jx

    yk, qk, states = y, ca.SX.sym("q0", n), []  # (a stand-in vector: only the Jacobians are kept)
    for Ta, Tb, Tc in columns:
        yk, qk = rk4_step(f, recorded, yk, qk, h, Ta, Tb, Tc)
        states.append(yk)
    J_all = ca.vertcat(*entries) if entries else ca.SX(0, 1)

    symbols = ca.SX.sym("J", max(1, len(entries)))
    given = []  # the same matrices with the symbols in place of the computed entries
    for Jx in stages:
        values = [e if e.is_constant() else symbols[_position(entries, e)] for e in Jx.nonzeros()]
        given.append(ca.SX(Jx.sparsity(), ca.vertcat(*values) if values else ca.SX(0, 1)))
    replay = iter(given)
    q = ca.SX.sym("q", n)
    qk = q
    for Ta, Tb, Tc in columns:
        _, qk = rk4_step(f, lambda x, T: next(replay), y, qk, h, Ta, Tb, Tc)
    return states, J_all, q, qk, symbols


def _position(entries: list, e) -> int | None:
    """Where the SX node ``e`` itself (not an equal expression) is in ``entries``."""
    return next((i for i, x in enumerate(entries) if ca.is_equal(x, e, 0)), None)


def rk4_step(f, J, yk, Qk, h, Ta, Tb, Tc):
    """One RK4 step of length h of y' = f(y, T) and, unless ``Qk`` is None, of Q' = J(y, T) Q: the one RK4 of
    gearsym (the engine's loops and the fit's windows). Ta, Tb, Tc: what time-dependent values f needs at the
    start, middle and end of the step (the engine's tables, or the time itself)."""
    k1 = f(yk, Ta)
    y2 = yk + h / 2 * k1
    k2 = f(y2, Tb)
    y3 = yk + h / 2 * k2
    k3 = f(y3, Tb)
    y4 = yk + h * k3
    k4 = f(y4, Tc)
    y_next = yk + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    if Qk is None:
        return y_next, None
    K1 = ca.mtimes(J(yk, Ta), Qk)
    K2 = ca.mtimes(J(y2, Tb), Qk + h / 2 * K1)
    K3 = ca.mtimes(J(y3, Tb), Qk + h / 2 * K2)
    K4 = ca.mtimes(J(y4, Tc), Qk + h * K3)
    return y_next, Qk + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)


@dataclass(frozen=True)
class _Switching:
    """The switching surfaces of a model's backlash, in the loop's symbols (states, tables, constants).

    Every application g(x, eta) (likewise g_slope, G) has two surfaces, s = x and s = -(x + eta), oriented
    so that the side [s >= 0] is the indicator of its branch: x >= 0 (one flank in contact) and x <= -eta
    (the other). ``rhs`` is ``split.rhs`` with each indicator replaced by a symbol of ``sides``: with the
    sides held fixed it is the smooth extension of one branch across its surfaces.
    """

    surfaces: tuple[sp.Expr, ...]
    sides: tuple[sp.Dummy, ...]
    rhs: tuple[sp.Expr, ...]


_OTHER_SWITCHES = (sp.Piecewise, sp.Heaviside, sp.Min, sp.Max, sp.Abs, sp.sign, sp.floor, sp.ceiling)


def _flank_of_backlash(e: sp.Expr):
    """The g(x, eta) of ``e`` if ``e`` is min(g, 0) (the coast flank: x + eta for x <= -eta) or max(g, 0)
    (the drive flank: x for x >= 0), else None."""
    if isinstance(e, (sp.Min, sp.Max)) and len(e.args) == 2 and sp.S.Zero in e.args:
        inner = next(a for a in e.args if a != 0)
        if isinstance(inner, g):
            return inner
    return None


def _switching(system: FirstOrderSystem, split: SplitRHS) -> _Switching:
    """The backlash switching surfaces of ``split.rhs``, derived from the expressions, in a fixed order
    (SymPy's canonical argument order) so that the same model always gives the same C."""
    states = set(system.states)
    surfaces: list[sp.Expr] = []
    sides: list[sp.Dummy] = []

    def side(s: sp.Expr) -> sp.Dummy:
        if s not in surfaces:
            surfaces.append(s)
            sides.append(sp.Dummy(f"side_{len(sides)}", real=True))
        return sides[surfaces.index(s)]

    def freeze(e: sp.Expr) -> sp.Expr:
        if isinstance(e, (g, g_slope, G)):
            x, eta = e.args
            if any(isinstance(a, (g, g_slope, G)) for arg in e.args for a in sp.preorder_traversal(arg)):
                raise ModelError(f"locate_crossings: nested backlash in {e} is not supported", system.name)
            on, off = side(x), side(-(x + eta))
            if isinstance(e, g):  # on x + off (x + eta), with one product on the path from x (~10 % per try)
                return (on + off) * x + off * eta
            if isinstance(e, g_slope):
                return on + off
            return on * x**2 / 2 + off * (x + eta) ** 2 / 2
        flank = _flank_of_backlash(e)
        if flank is not None:  # min(g, 0) or max(g, 0): one flank of g, switching on g's own surfaces
            x, eta = flank.args
            return side(x) * x if isinstance(e, sp.Max) else side(-(x + eta)) * (x + eta)
        if isinstance(e, _OTHER_SWITCHES) and e.free_symbols & states:
            raise ModelError(
                f"locating crossings handles the backlash g(x, eta) (and min/max(g, 0)) only; {e} switches on the "
                "state too and its crossings would not be located: use the paper's plain scheme "
                "(Integration.paper(), --plain)", system.name)
        if not e.args or isinstance(e, sp.Symbol):
            return e
        return e.func(*(freeze(a) for a in e.args))

    rhs = tuple(freeze(f) for f in split.rhs)
    return _Switching(tuple(surfaces), tuple(sides), rhs)


def _crossing_steps(sym: _Symbols, split: SplitRHS, switching: _Switching, where: str):
    """``tangent_block``, ``state_block`` and ``state_step`` (one step each) that split a step at a crossing,
    and the SX pieces they call, by name (the printed loops call them directly, :mod:`.printed`).

    The right-hand side is continuous across a backlash surface but its slope jumps, so plain RK4 over a
    crossing step is only first order for the tangent map (and the exponents). Here each step is:

    1. *try* (SX, every step): RK4 y0 -> y1 of the smooth extension of the branch at y0 (its sides, mode A,
       frozen: a stage that overshoots a surface stays on A's formula), and a flag: has the cubic Hermite
       of some surface's s over the step (values and slopes h ds/dt at both ends) a zero in it? The test
       is its Bernstein coefficients s0, s0 + d0/3, s1 - d1/3, s1 all on the start's side (then, by the
       convex hull, no zero): cheap, and it also sees an excursion across a surface and back within the
       step (a *dip*, which comparing the sides at y0 and y1 would miss).
    2. a CasADi ``Switch`` (a C ``if``): not flagged, keep y1; flagged, the *split* (calls of SX pieces,
       :data:`SPLIT_CALLS`):

       * the earliest zero theta_1 of the cubic of mode A's extension (``_first_zero``: bracketed between
         the cubic's extrema, then Halley kept inside the bracket), the earliest surface winning; RK4 of A
         over theta_1 h; then the same for mode B (A with the crossed surface(s) flipped) over the rest of
         the step, from the crossing, whose own zero there is not counted again: theta_2, the way out of a
         dip (or a second surface); RK4 of B up to it and of mode C over the rest. Each substep sees one
         smooth right-hand side, the tangent Q along: 4th order again. No zero: RK4 of A over the whole
         step, which is the kept try, so the choice between the two branches of the ``Switch`` never
         makes the step jump: the map of a period is a continuous function of its start (Newton on
         P(y) - y needs that; a plain step over a dip, or a Newton that could leave the sign change, made
         it jump by up to 1e-3 near a grazing at 200 steps, measured).
       * the tables at the substeps' stage times come from the quadratic through Ta, Tb, Tc (t, t + h/2,
         t + h): O(h^3) in the coefficients over O(1) split steps per period, 4th order overall.

    No saltation matrix: f is continuous across the surface (g is), so the tangent map is continuous
    there; only J jumps, and each substep integrates J of its own mode. A third zero in one step is
    integrated on the extension of the mode before it (first order there). The min/max of the observed
    states are taken after the step, as in the plain loops.
    """
    step = _CrossingStep(sym, split, switching, where)
    pieces = {f.name(): f for f in step.pieces()}
    # try, then Switch(keep | split), emitted straight into the caller's MX graph (a Function around the two
    # calls would copy its inputs once more at every step)
    tangent_try, state_try = pieces["tangent_try"], pieces["state_try"]
    tangent_switch = ca.Function.if_else("tangent_switch", split_function("tangent", pieces), pieces["tangent_keep"])
    state_switch = ca.Function.if_else("state_switch", split_function("state", pieces), pieces["state_keep"])

    def tangent_block(yk, Qk, lk, hk, Tk, c):
        y_try, Q_try, crossing = tangent_try(yk, Qk, Tk, c)
        return tangent_switch(crossing, yk, Qk, lk, hk, y_try, Q_try, Tk, c)

    def state_block(yk, lk, hk, Tk, c):  # the state alone: the same stepping (orbit loops and trajectory)
        y_try, crossing = state_try(yk, Tk, c)
        return state_switch(crossing, yk, lk, hk, y_try, Tk, c)

    # the printed loops' tangent try is the state's, then each tangent vector's (:meth:`_CrossingStep.tried_by_vector`)
    printed = {name: f for name, f in pieces.items() if name != "tangent_try"}
    return tangent_block, state_block, step.single(state_try, state_switch), printed


#: the split of a located step (:meth:`_CrossingStep.pieces`) as calls of SX pieces, (piece, inputs, outputs):
#: the one description of both the MX function (:func:`split_function`) and the printed C (:mod:`.printed`), so
#: that the C holds the crossing's root search once and the mode-RK4 step once with tangent and once without,
#: not once per substep. ``{kind}`` is tangent or state; the state's split leaves out the tangent matrices (the
#: names that start with Q). A *leg* is a substep: the sides held fixed, its length, and the tables at its
#: start, middle and end (:meth:`_CrossingStep.leg`); the first zero is searched on ``leg_try`` (mode A over the
#: whole step: the try), the second on ``leg_ext`` (mode B from the first to the step's end).
SPLIT_CALLS = (
    ("split_start", ("y", "T", "c"), ("leg_try", "t0", "mode_a")),
    ("crossing_ends", ("y", "yt", "leg_try", "mode_a", "c"), ("ends1",)),
    ("first_zero", ("ends1",), ("zeros1",)),  # per surface: one column each (SPLIT_PER_SURFACE)
    ("crossing_earliest", ("zeros1", "leg_try"), ("theta1", "mode_b")),
    ("split_legs", ("theta1", "mode_b", "leg_try", "t0", "T", "c"), ("leg_a", "leg_ext", "t1")),
    ("{kind}_mode_step", ("y", "Q", "leg_a", "c"), ("yb", "Qb")),
    ("state_mode_step", ("yb", "leg_ext", "c"), ("ye",)),
    ("crossing_ends", ("yb", "ye", "leg_ext", "mode_a", "c"), ("ends2",)),
    ("first_zero", ("ends2",), ("zeros2",)),
    ("crossing_earliest", ("zeros2", "leg_ext"), ("theta2", "mode_c")),
    ("split_legs", ("theta2", "mode_c", "leg_ext", "t1", "T", "c"), ("leg_b", "leg_c", "t2")),
    ("{kind}_mode_step", ("yb", "Qb", "leg_b", "c"), ("yc", "Qc")),
    ("{kind}_mode_step", ("yc", "Qc", "leg_c", "c"), ("yn", "Qn")),
    ("{kind}_keep", ("y", "Q", "lo", "hi", "yn", "Qn", "T", "c"), ("y1", "Q1", "lo1", "hi1")),  # the extremes
)
#: the pieces called once per surface, on a column each of their inputs and outputs
SPLIT_PER_SURFACE = ("first_zero",)
#: the split's inputs and outputs: those of ``{kind}_keep``
SPLIT_INPUTS, SPLIT_OUTPUTS = ("y", "Q", "lo", "hi", "yt", "Qt", "T", "c"), ("y1", "Q1", "lo1", "hi1")


def split_names(kind: str, names: tuple[str, ...]) -> tuple[str, ...]:
    """``names`` as the split of ``kind`` has them (the state's without the tangent matrices)."""
    return tuple(v for v in names if kind == "tangent" or not v.startswith("Q"))


def split_calls(kind: str) -> list[tuple[str, tuple[str, ...], tuple[str, ...]]]:
    """:data:`SPLIT_CALLS` of ``kind``."""
    return [(f.format(kind=kind), split_names(kind, i), split_names(kind, o)) for f, i, o in SPLIT_CALLS]


def split_function(kind: str, pieces: dict[str, ca.Function]) -> ca.Function:
    """``{kind}_split``: the MX function of :data:`SPLIT_CALLS` (inputs and outputs those of ``{kind}_keep``)."""
    keep = pieces[f"{kind}_keep"]
    inputs, outputs = split_names(kind, SPLIT_INPUTS), split_names(kind, SPLIT_OUTPUTS)
    values = {v: ca.MX.sym(v, keep.sparsity_in(i)) for i, v in enumerate(inputs)}
    for piece, ins, outs in split_calls(kind):
        f = pieces[piece]
        if piece in SPLIT_PER_SURFACE:
            f = f.map(values[ins[0]].size2())
        values.update(zip(outs, f.call([values[v] for v in ins])))
    return ca.Function(f"{kind}_split", [values[v] for v in inputs], [values[v] for v in outputs], inputs, outputs)


class _CrossingStep:
    """The pieces of a crossing-located RK4 step (see :func:`_crossing_steps`): the frozen-mode right-hand
    side and Jacobian, the surfaces and their rates, in the loop's symbols."""

    def __init__(self, sym: _Symbols, split: SplitRHS, switching: _Switching, where: str):
        n, m, nc = sym.y.numel(), len(split.tables), sym.ch.numel() - 1
        self.sym, self.n, self.m, self.nc = sym, n, m, nc
        y, T, ch = sym.y, sym.T, sym.ch
        self.h = ch[nc]
        self.f_of, self.J_of = _tabulated_rhs(sym, split, where)
        self.surfaces = len(switching.surfaces)
        sides = ca.SX.sym("side", self.surfaces)
        frozen = {**sym.inner, **{d: sides[i] for i, d in enumerate(switching.sides)}}
        fz = ca.vertcat(*to_casadi(switching.rhs, frozen, where))
        self.fz_of = ca.Function("f_mode", [y, T, ch, sides], [fz])
        self.Jz_of = ca.Function("J_mode", [y, T, ch, sides], [ca.jacobian(fz, y)])
        s_expr = ca.vertcat(*to_casadi(switching.surfaces, sym.inner, where))
        self.s_of = ca.Function("s", [y, T, ch], [s_expr])
        ydot, Tdot = ca.SX.sym("ydot", n), ca.SX.sym("Tdot", m)
        self.sdot_of = ca.Function("s_dot", [y, T, ch, ydot, Tdot],
                                   [ca.jtimes(s_expr, ca.vertcat(y, T), ca.vertcat(ydot, Tdot))])
        self.col = ca.SX.sym("Ti", 3 * m)
        self.Ta, self.Tb, self.Tc = self.col[:m], self.col[m:2 * m], self.col[2 * m:]
        self.Q = ca.SX.sym("Q", n, n)
        self.y1 = ca.SX.sym("y1", n)
        self.Q1 = ca.SX.sym("Q1", n, n)
        self.lo = ca.SX.sym("lo", len(sym.observed))
        self.hi = ca.SX.sym("hi", len(sym.observed))

    @staticmethod
    def side(s):
        return s >= 0

    def f_mode(self, mode):
        ch = self.sym.ch
        return lambda x, Tx: self.fz_of(x, Tx, ch, mode)

    def J_mode(self, mode):
        ch = self.sym.ch
        return lambda x, Tx: self.Jz_of(x, Tx, ch, mode)

    def hermite(self, y0, y1, mode, h, Ta, Tb, Tc):
        """s at both ends of a step of length ``h`` from ``y0`` to ``y1`` (mode frozen) and their slopes
        h ds/dt, the tables' rates from their quadratic over the step."""
        ch, f = self.sym.ch, self.f_mode(mode)
        s0, s1 = self.s_of(y0, Ta, ch), self.s_of(y1, Tc, ch)
        d0 = self.sdot_of(y0, Ta, ch, h * f(y0, Ta), 4 * Tb - 3 * Ta - Tc)
        d1 = self.sdot_of(y1, Tc, ch, h * f(y1, Tc), Ta - 4 * Tb + 3 * Tc)
        return s0, d0, s1, d1

    def tried(self, with_tangent: bool):
        """The step on the smooth extension of the branch at its start (the sides at y0 frozen: a stage that
        overshoots a surface stays on the start's branch), and whether the cubic Hermite of some surface's
        s over it has a zero in the step: a crossing, or an excursion across and back (a *dip*)."""
        y, Ta, Tb, Tc = self.sym.y, self.Ta, self.Tb, self.Tc
        mode = self.side(self.s_of(y, Ta, self.sym.ch))
        yn, Qn = rk4_step(self.f_mode(mode), self.J_mode(mode), y, self.Q if with_tangent else None, self.h,
                          Ta, Tb, Tc)
        return yn, Qn, self.crossed(yn, mode)

    def crossed(self, yn, mode):
        """The try's flag: has the cubic Hermite of some surface's s over the step to ``yn`` a zero in it?"""
        y, Ta, Tb, Tc = self.sym.y, self.Ta, self.Tb, self.Tc
        s0, d0, s1, d1 = self.hermite(y, yn, mode, self.h, Ta, Tb, Tc)
        sign = 2 * mode - 1
        # the cubic's Bernstein coefficients all on the start's side: no zero in the step (convex hull)
        clear = [sign * b > 0 for b in (s1, s0 + d0 / 3, s1 - d1 / 3)]
        return ca.sum1(ca.logic_not(ca.logic_and(ca.logic_and(clear[0], clear[1]), clear[2]))) > 0

    def tried_by_vector(self) -> list[ca.Function]:
        """The tangent try in two pieces for the printed loop, as the plain step's (:func:`_by_vector`):
        ``tangent_state`` (the state's try, its flag and each stage's Jacobian nonzeros) and ``tangent_vector``
        (one tangent vector's try given them); with ``state_keep`` they compute ``tangent_try`` and
        ``tangent_keep``, operation for operation."""
        y, ch, Ta = self.sym.y, self.sym.ch, self.Ta
        mode = self.side(self.s_of(y, Ta, ch))
        states, J_all, q, qn, symbols = _by_vector(self.f_mode(mode), self.J_mode(mode), y, self.h,
                                                    [(Ta, self.Tb, self.Tc)])
        return [ca.Function("tangent_state", [y, self.col, ch], [states[0], self.crossed(states[0], mode), J_all],
                            _OPTS),
                ca.Function("tangent_vector", [q, symbols, ch], [qn], _OPTS)]

    def table_at(self, theta):
        """The quadratic through Ta, Tb, Tc, at t + theta h."""
        Ta, Tb, Tc = self.Ta, self.Tb, self.Tc
        return Ta + theta * (4 * Tb - 3 * Ta - Tc) + theta * theta * (2 * Ta - 4 * Tb + 2 * Tc)

    def earliest(self, found, theta, mode):
        """(theta, the mode after it): the earliest of the surfaces' zeros (``found`` and ``theta`` per
        surface; 1: none), and ``mode`` with the surface(s) crossed there flipped."""
        theta = ca.if_else(found, theta, 2)
        first = theta[0]
        for i in range(1, self.surfaces):
            first = ca.if_else(theta[i] < first, theta[i], first)
        flip = ca.logic_and(found, theta <= first)
        return ca.if_else(first > 1, 1, first), ca.if_else(flip, 1 - mode, mode)

    def leg(self, mode, length, T0, Tm, T1):
        """A substep as one vector: the sides held fixed, its length, the tables at its start, middle, end."""
        return ca.vertcat(mode, length, T0, Tm, T1)

    def unpack(self, leg):
        """(mode, length, T0, Tm, T1) of a :meth:`leg`."""
        S, m = self.surfaces, self.m
        return leg[:S], leg[S], leg[S + 1:S + 1 + m], leg[S + 1 + m:S + 1 + 2 * m], leg[S + 1 + 2 * m:]

    def mode_step(self, with_tangent: bool) -> ca.Function:
        """``{tangent,state}_mode_step``: one RK4 step along a leg (its sides held fixed), with or without the
        tangent matrix: the substeps of the split (:data:`SPLIT_CALLS`)."""
        y, ch = self.sym.y, self.sym.ch
        leg = ca.SX.sym("leg", self.surfaces + 1 + 3 * self.m)
        mode, length, T0, Tm, T1 = self.unpack(leg)
        Q = self.Q if with_tangent else None  # (the same RK4 as the try's)
        yn, Qn = rk4_step(self.f_mode(mode), self.J_mode(mode), y, Q, length, T0, Tm, T1)
        if with_tangent:
            return ca.Function("tangent_mode_step", [y, Q, leg, ch], [yn, Qn], _OPTS)
        return ca.Function("state_mode_step", [y, leg, ch], [yn], _OPTS)

    def split_start(self) -> ca.Function:
        """``split_start``: the try's leg (mode A, the sides at the step's start, over the whole step), the
        step's start (0) and mode A. The located step (:data:`SPLIT_CALLS`): up to two crossings in the step (a
        crossing, or a dip's way in and out), RK4 of mode A up to the first (``leg_a``), of mode B up to the
        second (``leg_b``), of mode C over the rest (``leg_c``); each on its own smooth branch."""
        y, ch = self.sym.y, self.sym.ch
        mode_a = self.side(self.s_of(y, self.Ta, ch))
        leg = self.leg(mode_a, self.h, self.Ta, self.Tb, self.Tc)
        return ca.Function("split_start", [y, self.col, ch], [leg, ca.SX.zeros(1), mode_a], _OPTS)

    def crossing(self) -> list[ca.Function]:
        """``crossing_ends``: the ends of each surface's cubic on a leg from y0 (its end y_end on the leg's
        extension), a column (s0, d0, s1, d1, side, fresh) per surface; fresh: the surfaces whose side differs
        from ``before`` (just crossed), whose zero at the leg's start is not counted. ``first_zero``: a
        surface's (found, theta), called per surface. ``crossing_earliest``: the earliest, and the mode after it."""
        S = self.surfaces
        y0, y_end, leg, before = (ca.SX.sym(v, k) for v, k in (("y0", self.n), ("y_end", self.n),
                                                               ("leg", S + 1 + 3 * self.m), ("before", S)))
        mode, length, T0, Tm, T1 = self.unpack(leg)
        ends = ca.horzcat(*self.hermite(y0, y_end, mode, length, T0, Tm, T1), mode, mode != before).T
        one = ca.SX.sym("ends", ends.size1())
        zeros = ca.SX.sym("zeros", 2, S)
        return [ca.Function("crossing_ends", [y0, y_end, leg, before, self.sym.ch], [ends], _OPTS),
                ca.Function("first_zero", [one], [ca.vertcat(*_first_zero(*ca.vertsplit(one)))], _OPTS),
                ca.Function("crossing_earliest", [zeros, leg], list(self.earliest(zeros[0, :].T, zeros[1, :].T, mode)),
                            _OPTS)]

    def split_legs(self) -> ca.Function:
        """``split_legs``: on a leg from t (a fraction of the step) to the step's end, the leg up to its zero
        at theta (a fraction of the leg) and the rest of the step (mode ``after``), and where the zero is."""
        leg, t, theta, after = (ca.SX.sym(v, k) for v, k in (("leg", self.surfaces + 1 + 3 * self.m), ("t", 1),
                                                             ("theta", 1), ("after", self.surfaces)))
        mode, _, T0, _, _ = self.unpack(leg)
        h, t_next = self.h, t + theta * (1 - t)
        T_next = self.table_at(t_next)
        leg_to = self.leg(mode, (t_next - t) * h, T0, self.table_at((t + t_next) / 2), T_next)
        leg_rest = self.leg(after, (1 - t_next) * h, T_next, self.table_at((1 + t_next) / 2), self.Tc)
        return ca.Function("split_legs", [theta, after, leg, t, self.col, self.sym.ch], [leg_to, leg_rest, t_next],
                           _OPTS)

    def extremes(self, yn):
        obs = ca.vertcat(*[yn[j] for j in self.sym.observed])
        return select_min(obs, self.lo), select_max(obs, self.hi)

    def switched(self, kind: str, with_tangent: bool) -> tuple[ca.Function, ca.Function]:
        """``{kind}_try`` (the plain step and its crossing flag) and ``{kind}_keep`` (keep the try), with or
        without tangent vectors."""
        y, ch, col = self.sym.y, self.sym.ch, self.col
        yn, Qn, flag = self.tried(with_tangent)
        if with_tangent:
            tried = ca.Function(f"{kind}_try", [y, self.Q, col, ch], [yn, Qn, flag], _OPTS)
            inputs, kept = [y, self.Q, self.lo, self.hi, self.y1, self.Q1, col, ch], [self.y1, self.Q1]
        else:
            tried = ca.Function(f"{kind}_try", [y, col, ch], [yn, flag], _OPTS)
            inputs, kept = [y, self.lo, self.hi, self.y1, col, ch], [self.y1]
        return tried, ca.Function(f"{kind}_keep", inputs, [*kept, *self.extremes(self.y1)], _OPTS)

    def pieces(self) -> list[ca.Function]:
        """The SX pieces of the located steps (:data:`SPLIT_CALLS`), in a fixed order."""
        return [*self.switched("tangent", True), *self.switched("state", False), self.split_start(),
                *self.crossing(), self.split_legs(), self.mode_step(True), self.mode_step(False),
                *self.tried_by_vector()]

    def single(self, state_try: ca.Function, state_switch: ca.Function) -> ca.Function:
        """One located step of the state (phase portraits), as an MX function (the extremes unused)."""
        Ym, Ti, Cm = ca.MX.sym("y", self.n), ca.MX.sym("Ti", 3 * self.m), ca.MX.sym("c", self.nc + 1)
        y_try, crossing = state_try(Ym, Ti, Cm)
        none = ca.MX.zeros(self.lo.sparsity())
        return ca.Function("state_step", [Ym, Ti, Cm], [state_switch(crossing, Ym, none, none, y_try, Ti, Cm)[0]])


#: Halley iterations (Newton with the cubic's curvature: third order) on r from the secant, kept inside the
#: bracket. Fixed, so that theta stays a continuous function of the ends. On every crossing step of long
#: orbits (one_stage, flexible_shaft, two_stage at omega 0.6-2.2) 4 reach a 30-iteration reference to
#: rounding (|dtheta| <= 1e-15; Newton needed 6). Near a grazing (two zeros sqrt(delta) apart: the
#: convergence is linear there) no fixed count does: on random such cubics 8 leave |dtheta| <= 1e-13 for
#: delta >= 1e-5 and < 6e-5 below (the former 8 Newton iterations: up to 7e-3). That is what makes the
#: steps' map smooth enough to continue periodic orbits: the Fig. 3 branches are the same for 8 to 24
#: iterations, while with 5 (and the former Newton) the D = 0 period-1 branch stopped at omega = 0.21.
_HALLEY_ITERATIONS = 8


def _first_zero(s0, d0, s1, d1, mode, fresh):
    """Per surface: (found, theta) of the earliest zero in (0, 1] of the cubic Hermite r of s over a step
    (values s0, s1 and slopes d0, d1 = h ds/dt at its ends), seen from the side ``mode`` of the start.
    ``fresh`` (0/1 per surface): the step starts on that surface (s0 = 0, just crossed): r(theta)/theta is
    searched instead, so that the zero at the start is not found again.

    The cubic is monotone between its extrema, so the first of the points (its interior extrema in
    order, then 1) where r is on the other side closes a bracket with a single zero; Halley's iteration
    from the secant, kept inside the bracket (else bisecting it), finds it. Every piece is a continuous
    function of the ends, which keeps the located step continuous in its start (see ``_crossing_steps``)."""
    sign = 2 * mode - 1  # +1: the start is on the side s >= 0

    # r in powers of t, its coefficients chosen once: each iteration is then Horner sums (the Hermite
    # form evaluated both the cubic and the deflated one at every point)
    c0 = ca.if_else(fresh, d0, s0)
    c1 = ca.if_else(fresh, -2 * d0 + 3 * s1 - d1, d0)
    c2 = ca.if_else(fresh, d0 - 2 * s1 + d1, -3 * s0 - 2 * d0 + 3 * s1 - d1)
    c3 = ca.if_else(fresh, 0, 2 * s0 + d0 - 2 * s1 + d1)

    def r(t):
        return ((c3 * t + c2) * t + c1) * t + c0

    def dr(t):
        return (3 * c3 * t + 2 * c2) * t + c1

    # interior extrema: the roots of r' = a t^2 + b t + c (linear for the deflated cubic)
    a, b, c = 3 * c3, 2 * c2, c1
    disc = b * b - 4 * a * c
    root = ca.sqrt(ca.if_else(disc > 0, disc, 0))
    q = -(b + ca.if_else(b >= 0, root, -root)) / 2  # the stable pair of roots: q/a and c/q
    e1 = ca.if_else(a == 0, ca.if_else(b == 0, 1, -c / ca.if_else(b == 0, 1, b)), q / ca.if_else(a == 0, 1, a))
    e2 = ca.if_else(q == 0, e1, c / ca.if_else(q == 0, 1, q))
    e1 = ca.if_else(disc < 0, 1, e1)
    e2 = ca.if_else(disc < 0, 1, e2)
    e1 = ca.if_else(ca.logic_and(e1 > 0, e1 < 1), e1, 1)
    e2 = ca.if_else(ca.logic_and(e2 > 0, e2 < 1), e2, 1)
    first, second = ca.fmin(e1, e2), ca.fmax(e1, e2)

    def on(value):
        return sign * value > 0

    r1, r2, r3 = r(first), r(second), s1  # r(1) = s1 for both forms
    low = ca.if_else(on(r1), ca.if_else(on(r2), second, first), 0)
    high = ca.if_else(on(r1), ca.if_else(on(r2), 1, second), first)
    found = ca.logic_not(ca.logic_and(ca.logic_and(on(r1), on(r2)), on(r3)))
    r_low, r_high = r(low), r(high)
    theta = low + (high - low) * r_low / ca.if_else(r_low == r_high, 1, r_low - r_high)  # the secant
    theta = ca.if_else(ca.logic_and(theta > low, theta <= high), theta, (low + high) / 2)
    for _ in range(_HALLEY_ITERATIONS):
        p, dp, ddp = r(theta), dr(theta), 6 * c3 * theta + 2 * c2
        before = on(p)  # still on the start's side: the zero is later
        low, high = ca.if_else(before, theta, low), ca.if_else(before, high, theta)
        halley = 2 * dp * dp - p * ddp
        step = 2 * p * dp / ca.if_else(halley == 0, 1, halley)
        inside = ca.logic_and(theta - step >= low, theta - step <= high)
        theta = ca.if_else(p == 0, theta, ca.if_else(inside, theta - step, (low + high) / 2))
    return found, theta


def _gram_schmidt(n: int) -> ca.Function:
    """Modified Gram-Schmidt: orthonormal columns and the log of each column's stretch."""
    Q = ca.SX.sym("Q", n, n)
    cols, logs = [], []
    for j in range(n):
        v = Q[:, j]
        for q in cols:
            v = v - ca.dot(q, v) * q
        norm = ca.norm_2(v)
        cols.append(v / norm)
        logs.append(ca.log(norm))
    return ca.Function("gram_schmidt", [Q], [ca.horzcat(*cols), ca.vertcat(*logs)], _OPTS)


def _table_function(constants: ca.Function, table_point: ca.Function, n_params: int, nc: int, m: int,
                    N: int) -> ca.Function:
    """The tables at the 2N+1 half-step times of the period starting at t0, one column per step.

    Second output, ``probe``: the table values at t0 + 0.37 T and t0 + 1.37 T, which must agree
    (the loops repeat one period), checked at every run's parameter values at no extra call.
    """
    t0, p = ca.MX.sym("t0"), ca.MX.sym("p", n_params)
    if m:
        c, period = constants(p)
        h = c[nc]
        times = t0 + ca.DM(list(range(2 * N + 1))).T * (h / 2)
        vals = table_point.map(2 * N + 1)(times, p)
        tab = ca.vertcat(vals[:, 0:2 * N:2], vals[:, 1:2 * N:2], vals[:, 2:2 * N + 1:2])
        probe = ca.horzcat(table_point(t0 + 0.37 * period, p), table_point(t0 + 1.37 * period, p))
    else:
        tab, probe = ca.MX(0, N), ca.MX(0, 2)
    return ca.Function("table", [t0, p], [tab, probe], ["t0", "p"], ["table", "probe"])
