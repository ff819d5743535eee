"""The CasADi functions of one model: right-hand side, exact Jacobian, and the
fixed-step RK4 loops with their variational equations.

Layering (the CasADi pitfall: a loop Function called on SX symbols is inlined,
and 80 000 inlined RK4 steps crash the C compiler):

* SX, straight-line code with common subexpressions removed: ``rhs``,
  ``jacobian``, a *block* of a few RK4 steps of the state and its tangent
  matrix, the Gram-Schmidt re-orthonormalisation;
* MX, loops that stay loops in C: one forcing period is ``mapaccum`` over the
  blocks plus Gram-Schmidt, and a *chunk* of periods is ``mapaccum`` over
  periods. A run is a few chunk calls; nothing per step or period is Python.

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
    split = split_rhs(system)
    n, m, nc = system.dimension, len(split.tables), len(split.constants)
    params = list(system.parameters)
    observed = [i for i, s in enumerate(system.states) if s.name in system.observed]
    N = options.steps_per_period
    K = options.block(n)
    where = system.name
    opts = {"cse": True}

    t = ca.SX.sym("t")
    y = ca.SX.sym("y", n)
    p = ca.SX.sym("p", len(params))
    T = ca.SX.sym("T", m)
    c = ca.SX.sym("c", nc)
    symbols = {system.time: t}
    symbols.update({s: y[i] for i, s in enumerate(system.states)})
    symbols.update({sym: T[i] for i, (sym, _) in enumerate(split.tables)})
    symbols.update({sym: c[i] for i, (sym, _) in enumerate(split.constants)})
    by_name = {name: p[j] for j, name in enumerate(params)}
    for expr in list(system.rhs) + [system.period]:
        for s in expr.free_symbols:
            if s not in symbols and s.name in by_name:
                symbols[s] = by_name[s.name]

    # rhs and Jacobian in the user's terms (time, state, parameters)
    f_user = ca.vertcat(*to_casadi(system.rhs, symbols, where))
    rhs = ca.Function("rhs", [t, y, p], [f_user], ["t", "y", "p"], ["dy"], opts)
    jacobian = ca.Function("jacobian", [t, y, p], [ca.densify(ca.jacobian(f_user, y))], ["t", "y", "p"], ["J"], opts)

    # what the loops need once per run: constants (and the step), tables of time
    period_expr, h_expr = to_casadi([system.period, system.period / N], symbols, where)
    if ca.depends_on(period_expr, ca.vertcat(t, y)):
        raise ModelError(f"the forcing period {system.period} may depend on parameters only", where)
    const_values = to_casadi([e for _, e in split.constants], symbols, where)
    constants = ca.Function("constants", [p], [ca.vertcat(*const_values, h_expr), period_expr], ["p"],
                            ["c", "period"], opts)
    table_values = to_casadi([e for _, e in split.tables], symbols, where)
    table_point = ca.Function("table_point", [t, p], [ca.vertcat(*table_values) if m else ca.SX(0, 1)], opts)

    # the loop body sees states, table values and constants only
    ch = ca.SX.sym("c", nc + 1)  # constants, then the step h
    h = ch[nc]
    inner = {**symbols, **{sym: ch[i] for i, (sym, _) in enumerate(split.constants)}}
    f_tab = ca.vertcat(*to_casadi(split.rhs, inner, where))
    f_of = ca.Function("f_tab", [y, T, ch], [f_tab])
    J_of = ca.Function("J_tab", [y, T, ch], [ca.jacobian(f_tab, y)])

    Q = ca.SX.sym("Q", n, n)
    lo = ca.SX.sym("lo", len(observed))
    hi = ca.SX.sym("hi", len(observed))
    Tk = ca.SX.sym("Tk", 3 * m, K)

    def rk4(yk, Qk, Ta, Tb, Tc):
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
            obs = ca.vertcat(*[yk[j] for j in observed])
            lk, hk = select_min(obs, lk), select_max(obs, hk)
        return yk, Qk, lk, hk

    yb, Qb, lb, hb = block(True)
    tangent_block = ca.Function("tangent_block", [y, Q, lo, hi, Tk, ch], [yb, Qb, lb, hb], opts)
    yb, _, lb, hb = block(False)
    state_block = ca.Function("state_block", [y, lo, hi, Tk, ch], [yb, lb, hb], opts)
    col = ca.SX.sym("Ti", 3 * m)
    y_next, _ = rk4(y, None, col[:m], col[m:2 * m], col[2 * m:])
    state_step = ca.Function("state_step", [y, col, ch], [y_next], opts)

    # modified Gram-Schmidt: orthonormal columns and the log of each stretch
    cols, logs = [], []
    for j in range(n):
        v = Q[:, j]
        for q in cols:
            v = v - ca.dot(q, v) * q
        norm = ca.norm_2(v)
        cols.append(v / norm)
        logs.append(ca.log(norm))
    gram_schmidt = ca.Function("gram_schmidt", [Q], [ca.horzcat(*cols), ca.vertcat(*logs)], opts)

    # --- MX loops: calls, not inlined code, and shared inputs passed by pointer
    blocks, C = N // K, options.chunk_periods
    Ym, Qm, Cm = ca.MX.sym("y", n), ca.MX.sym("Q", n, n), ca.MX.sym("c", nc + 1)
    Tm = ca.MX.sym("T", 3 * m, N)
    obs0 = ca.vertcat(*[Ym[j] for j in observed])

    yk, Qk, lk, hk = Ym, Qm, obs0, obs0
    for b in range(blocks):
        yk, Qk, lk, hk = tangent_block(yk, Qk, lk, hk, Tm[:, b * K:(b + 1) * K], Cm)
    Qn, logr = gram_schmidt(Qk)
    period = ca.Function("lyapunov_period", [Ym, Qm, Tm, Cm], [yk, Qn, logr, lk, hk],
                         ["y0", "Q0", "table", "c"], ["strobe", "Q", "log_stretch", "low", "high"])
    lyapunov_period = period
    yk, Qk, outs = Ym, Qm, []
    for _ in range(C):
        yk, Qk, logr, lk, hk = period(yk, Qk, Tm, Cm)
        outs.append((yk, logr, lk, hk))
    lyapunov_chunk = ca.Function(
        "lyapunov_chunk", [Ym, Qm, Tm, Cm], [ca.horzcat(*col) for col in zip(*outs)][:1] + [Qk] +
        [ca.horzcat(*col) for col in zip(*outs)][1:],
        ["y0", "Q0", "table", "c"], ["strobe", "Q", "log_stretch", "low", "high"])

    yk, lk, hk = Ym, obs0, obs0
    for b in range(blocks):
        yk, lk, hk = state_block(yk, lk, hk, Tm[:, b * K:(b + 1) * K], Cm)
    period = ca.Function("orbit_period", [Ym, Tm, Cm], [yk, lk, hk], ["y0", "table", "c"], ["strobe", "low", "high"])
    orbit_period = period
    yk, outs = Ym, []
    for _ in range(C):
        yk, lk, hk = period(yk, Tm, Cm)
        outs.append((yk, lk, hk))
    orbit_chunk = ca.Function("orbit_chunk", [Ym, Tm, Cm], [ca.horzcat(*col) for col in zip(*outs)],
                              ["y0", "table", "c"], ["strobe", "low", "high"])

    # every step of one period, for phase portraits
    Yt = state_step.mapaccum("steps", N, 1)(Ym, Tm, Cm)
    trajectory = ca.Function("trajectory", [Ym, Tm, Cm], [Yt], ["y0", "table", "c"], ["states"])

    # the tables at the 2N+1 half-step times of the period starting at t0
    t0, Pm = ca.MX.sym("t0"), ca.MX.sym("p", len(params))
    if m:
        hm = constants(Pm)[0][nc]
        times = t0 + ca.DM(list(range(2 * N + 1))).T * (hm / 2)
        vals = table_point.map(2 * N + 1)(times, Pm)
        tab = ca.vertcat(vals[:, 0:2 * N:2], vals[:, 1:2 * N:2], vals[:, 2:2 * N + 1:2])
    else:
        tab = ca.MX(0, N)
    table = ca.Function("table", [t0, Pm], [tab], ["t0", "p"], ["table"])

    functions = {f.name(): f for f in (rhs, jacobian, constants, table, lyapunov_chunk, lyapunov_period,
                                       orbit_chunk, orbit_period, trajectory)}
    return ModelFunctions(system, options, split, functions)
