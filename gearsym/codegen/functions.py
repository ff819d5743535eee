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

Tangent vectors follow the exact variational equations Q' = J(t, y) Q,
integrated by the same RK4 as the state (RK4 of the augmented system), so the
tangent map is the exact derivative of the discrete flow.

Parameters are an input vector ``p`` in ``system.parameters`` order: changing
a value never regenerates or recompiles anything.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..errors import ModelError
from ..system import FirstOrderSystem
from .time_tables import SplitRHS, split_rhs
from .translate import select_max, select_min, to_casadi


@dataclass(frozen=True)
class LoopOptions:
    """Structure of the generated loops (part of the model hash; values of parameters are not)."""

    steps_per_period: int = 200
    chunk_periods: int = 50  # periods per compiled call
    block_steps: int = 0  # RK4 steps unrolled per SX block; 0 chooses

    def __post_init__(self):
        if self.steps_per_period < 1:
            raise ModelError(f"steps per period must be at least 1, not {self.steps_per_period}")
        if self.chunk_periods < 1:
            raise ModelError(f"periods per chunk must be at least 1, not {self.chunk_periods}")

    def block(self, dimension: int) -> int:
        """RK4 steps per SX function call.

        One, measured: the call costs little next to a tangent step, and longer
        straight-line blocks run slower (register pressure) and compile slower.
        """
        target = self.block_steps or 1
        return max(d for d in range(1, target + 1) if self.steps_per_period % d == 0)


@dataclass(frozen=True)
class ModelFunctions:
    """Every CasADi Function of one model, ready to generate or to evaluate in-process."""

    system: FirstOrderSystem
    options: LoopOptions
    split: SplitRHS
    functions: dict[str, ca.Function]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.functions)


def build_functions(system: FirstOrderSystem, options: LoopOptions = LoopOptions()) -> ModelFunctions:
    """Every function the engine generates for ``system`` (see the module docstring)."""
    split = split_rhs(system)
    sym = _Symbols(system, split)
    n, m, nc = system.dimension, len(split.tables), len(split.constants)
    N, K = options.steps_per_period, options.block(n)
    where = system.name

    # rhs and Jacobian in the user's terms (time, state, parameters)
    f_user = ca.vertcat(*to_casadi(system.rhs, sym.outer, where))
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

    tangent_block, state_block, state_step = _rk4_functions(sym, split, K, where)
    gram_schmidt = _gram_schmidt(n)

    # MX loops over the SX functions
    Ym, Qm, Cm = ca.MX.sym("y", n), ca.MX.sym("Q", n, n), ca.MX.sym("c", nc + 1)
    Tm = ca.MX.sym("T", 3 * m, N)
    obs0 = ca.vertcat(*[Ym[j] for j in sym.observed])
    blocks = [Tm[:, b * K:(b + 1) * K] for b in range(N // K)]

    yk, Qk, lk, hk = Ym, Qm, obs0, obs0
    for Tb in blocks:
        yk, Qk, lk, hk = tangent_block(yk, Qk, lk, hk, Tb, Cm)
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

    yk, lk, hk = Ym, obs0, obs0
    for Tb in blocks:
        yk, lk, hk = state_block(yk, lk, hk, Tb, Cm)
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

    table = _table_function(constants, table_point, len(sym.params), nc, m, N)
    functions = {f.name(): f for f in (rhs, jacobian, constants, table, lyapunov_chunk, lyapunov_period,
                                       orbit_chunk, orbit_period, trajectory)}
    return ModelFunctions(system, options, split, functions)


_OPTS = {"cse": True}


class _Symbols:
    """The SX symbols of one model and the SymPy -> SX maps of the outer functions and the loop body."""

    def __init__(self, system: FirstOrderSystem, split: SplitRHS):
        n, m, nc = system.dimension, len(split.tables), len(split.constants)
        self.params = list(system.parameters)
        self.observed = [i for i, s in enumerate(system.states) if s.name in system.observed]
        self.t = ca.SX.sym("t")
        self.y = ca.SX.sym("y", n)
        self.p = ca.SX.sym("p", len(self.params))
        self.T = ca.SX.sym("T", m)
        c = ca.SX.sym("c", nc)
        outer = {system.time: self.t}
        outer.update({s: self.y[i] for i, s in enumerate(system.states)})
        outer.update({s: self.T[i] for i, (s, _) in enumerate(split.tables)})
        outer.update({s: c[i] for i, (s, _) in enumerate(split.constants)})
        by_name = {name: self.p[j] for j, name in enumerate(self.params)}
        for expr in list(system.rhs) + [system.period]:
            for s in expr.free_symbols:
                if s not in outer and s.name in by_name:
                    outer[s] = by_name[s.name]
        self.outer = outer
        # the loop body sees states, table values and constants only; ch = (constants, h)
        self.ch = ca.SX.sym("c", nc + 1)
        self.inner = {**outer, **{s: self.ch[i] for i, (s, _) in enumerate(split.constants)}}


def _rk4_functions(sym: _Symbols, split: SplitRHS, K: int, where: str):
    """K RK4 steps with tangent (``tangent_block``), without (``state_block``), and one plain step."""
    n, m, nc = sym.y.numel(), len(split.tables), sym.ch.numel() - 1
    y, T, ch = sym.y, sym.T, sym.ch
    h = ch[nc]
    f_tab = ca.vertcat(*to_casadi(split.rhs, sym.inner, where))
    f_of = ca.Function("f_tab", [y, T, ch], [f_tab])
    J_of = ca.Function("J_tab", [y, T, ch], [ca.jacobian(f_tab, y)])
    Q = ca.SX.sym("Q", n, n)
    lo = ca.SX.sym("lo", len(sym.observed))
    hi = ca.SX.sym("hi", len(sym.observed))
    Tk = ca.SX.sym("Tk", 3 * m, K)

    def rk4(yk, Qk, Ta, Tb, Tc):  # Ta, Tb, Tc: table values at t, t + h/2, t + h
        k1 = f_of(yk, Ta, ch)
        y2 = yk + h / 2 * k1
        k2 = f_of(y2, Tb, ch)
        y3 = yk + h / 2 * k2
        k3 = f_of(y3, Tb, ch)
        y4 = yk + h * k3
        k4 = f_of(y4, Tc, ch)
        y_next = yk + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if Qk is None:
            return y_next, None
        K1 = ca.mtimes(J_of(yk, Ta, ch), Qk)
        K2 = ca.mtimes(J_of(y2, Tb, ch), Qk + h / 2 * K1)
        K3 = ca.mtimes(J_of(y3, Tb, ch), Qk + h / 2 * K2)
        K4 = ca.mtimes(J_of(y4, Tc, ch), Qk + h * K3)
        return y_next, Qk + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)

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
    state_step = ca.Function("state_step", [y, col, ch], [y_next], _OPTS)
    return tangent_block, state_block, state_step


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
