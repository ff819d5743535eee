"""The RK4 step and its tangent equations: the one fixed-step integrator of gearsym.

:func:`rk4_step` is one step of y' = f and, with it, of the variational equations Q' = J Q (RK4 of the augmented
system, so the tangent map is the exact derivative of the discrete flow); the engine's loops and the fit's
windows both use it. :func:`rk4_functions` makes the plain SX blocks of it, :func:`tangent_by_vector` the same
tangent step split into the state's step and one tangent vector's, which the printed loop applies to each
vector in turn (a loop the C compiler vectorises).
"""
from __future__ import annotations

import casadi as ca

from .casadi_symbols import SX_OPTIONS, LoopSymbols
from .time_tables import SplitRHS
from .translate import select_max, select_min, to_casadi


def tabulated_rhs(sym: LoopSymbols, split: SplitRHS, where: str) -> tuple[ca.Function, ca.Function]:
    """f and its Jacobian in the loop's terms (state, table values at the stage's time, constants and h)."""
    f_tab = ca.vertcat(*to_casadi(split.rhs, sym.inner, where))
    return (ca.Function("f_tab", [sym.y, sym.T, sym.ch], [f_tab]),
            ca.Function("J_tab", [sym.y, sym.T, sym.ch], [ca.jacobian(f_tab, sym.y)]))


def rk4_functions(sym: LoopSymbols, split: SplitRHS, K: int, where: str):
    """K RK4 steps with tangent (``tangent_block``), without (``state_block``), and one plain step."""
    n, m, nc = sym.y.numel(), len(split.tables), sym.ch.numel() - 1
    y, ch = sym.y, sym.ch
    h = ch[nc]
    f_of, J_of = tabulated_rhs(sym, split, where)
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
    tangent_block = ca.Function("tangent_block", [y, Q, lo, hi, Tk, ch], [yb, Qb, lb, hb], SX_OPTIONS)
    yb, _, lb, hb = block(False)
    state_block = ca.Function("state_block", [y, lo, hi, Tk, ch], [yb, lb, hb], SX_OPTIONS)
    col = ca.SX.sym("Ti", 3 * m)
    y_next, _ = rk4(y, None, col[:m], col[m:2 * m], col[2 * m:])
    state_step = ca.Function("trajectory_step", [y, col, ch], [y_next], SX_OPTIONS)
    return tangent_block, state_block, state_step


def tangent_by_vector(sym: LoopSymbols, split: SplitRHS, K: int, where: str) -> dict[str, ca.Function]:
    """``tangent_block`` in two pieces, for the printed loop: ``tangent_state`` (the state's K steps, as
    ``state_block``, and the Jacobian of every RK4 stage: its nonzeros that are not constants) and
    ``tangent_vector`` (one tangent vector's K steps, given those Jacobians), which the loop applies to each
    tangent vector in turn, a loop the C compiler vectorises (:func:`by_vector`)."""
    m, nc = len(split.tables), sym.ch.numel() - 1
    y, ch, h = sym.y, sym.ch, sym.ch[nc]
    f_of, J_of = tabulated_rhs(sym, split, where)
    lo, hi = ca.SX.sym("lo", len(sym.observed)), ca.SX.sym("hi", len(sym.observed))
    Tk = ca.SX.sym("Tk", 3 * m, K)
    columns = [(Tk[:m, i], Tk[m:2 * m, i], Tk[2 * m:, i]) for i in range(K)]
    states, J_all, q, qk, symbols = by_vector(lambda x, T: f_of(x, T, ch), lambda x, T: J_of(x, T, ch), y, h,
                                                columns)
    lk, hk = lo, hi
    for yk in states:
        obs = ca.vertcat(*[yk[j] for j in sym.observed])
        lk, hk = select_min(obs, lk), select_max(obs, hk)
    state = ca.Function("tangent_state", [y, lo, hi, Tk, ch], [states[-1], lk, hk, J_all], SX_OPTIONS)
    vector = ca.Function("tangent_vector", [q, symbols, ch], [qk], SX_OPTIONS)
    return {"tangent_state": state, "tangent_vector": vector}


def by_vector(f, J, y, h, columns: list) -> tuple:
    """RK4 steps of length h from ``y`` (one per ``(Ta, Tb, Tc)`` of ``columns``) split for the printed loops:
    (the state after each step, the nonzeros of every stage's Jacobian that are not constants, a tangent vector
    q, q after the steps given those nonzeros, the symbols that stand for them in it). ``rk4_step`` of the
    tangent matrix computes each of its columns with these operations (``mtimes`` works column by column, and
    the constant entries, which it simplifies, stay constants here), so the pieces give its bits."""
    n = y.numel()
    stages, entries = [], {}  # each stage's Jacobian; its distinct non-constant nonzeros, by node, in order

    def recorded(x, T):
        Jx = J(x, T)
        stages.append(Jx)
        for e in Jx.nonzeros():
            if not e.is_constant():
                entries.setdefault(e.element_hash(), (len(entries), e))
        return Jx

    yk, qk, states = y, ca.SX.sym("q0", n), []  # (a stand-in vector: only the Jacobians are kept)
    for Ta, Tb, Tc in columns:
        yk, qk = rk4_step(f, recorded, yk, qk, h, Ta, Tb, Tc)
        states.append(yk)
    J_all = ca.vertcat(*(e for _, e in entries.values())) if entries else ca.SX(0, 1)

    symbols = ca.SX.sym("J", max(1, len(entries)))
    given = []  # the same matrices with the symbols in place of the computed entries
    for Jx in stages:
        values = [e if e.is_constant() else symbols[entries[e.element_hash()][0]] for e in Jx.nonzeros()]
        given.append(ca.SX(Jx.sparsity(), ca.vertcat(*values) if values else ca.SX(0, 1)))
    replay = iter(given)
    q = ca.SX.sym("q", n)
    qk = q
    for Ta, Tb, Tc in columns:
        _, qk = rk4_step(f, lambda x, T: next(replay), y, qk, h, Ta, Tb, Tc)
    return states, J_all, q, qk, symbols


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
