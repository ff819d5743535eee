"""Loops over periods in MX: a period of RK4 blocks written out in segments, the monodromy matrix in pieces
for multiple shooting, and the Gram-Schmidt re-orthonormalisation of the tangent vectors after each period.

MX calls the SX step functions instead of inlining them (a loop Function called on SX symbols is inlined, and
80 000 inlined RK4 steps crash the C compiler).
"""
from __future__ import annotations

import casadi as ca

from .casadi_symbols import SX_OPTIONS
from .loops import SHOOTING_SEGMENTS, shooting_segments
from .translate import select_max, select_min


def monodromy(tangent_block, obs0, Ym: ca.MX, Qm: ca.MX, Cm: ca.MX, m: int, N: int, K: int, cycles: int = 1):
    """``monodromy_segment``: one piece of a period (``SHOOTING_SEGMENTS`` of them per forcing period, or the
    largest number below that its blocks divide into), the state and the raw tangent matrix Phi Q0 (no
    Gram-Schmidt: the Jacobian of the map, for Newton) with the observed states' min and max over its
    steps; ``monodromy_period``: the pieces of one period in turn (:mod:`gearsym.periodic`)."""
    S = shooting_segments(N, K, cycles)
    width = N // S
    Ts = ca.MX.sym("T", 3 * m, width)
    yk, Qk, lk, hk = over_period(tangent_block, [Ym, Qm, obs0, obs0], Ts, Cm, K, "shooting")
    names = (["y0", "Q0", "table", "c"], ["strobe", "M", "low", "high"])
    segment = ca.Function("monodromy_segment", [Ym, Qm, Ts, Cm], [yk, Qk, lk, hk], *names)
    Tm = ca.MX.sym("T", 3 * m, N)
    yk, Qk, lk, hk = Ym, Qm, obs0, obs0
    if S > SHOOTING_SEGMENTS:  # a revolution of many mesh periods: the pieces as one accumulated map
        La, Ha = ca.MX.sym("lk", obs0.sparsity()), ca.MX.sym("hk", obs0.sparsity())
        y1, Q1, low, high = segment(Ym, Qm, Ts, Cm)
        carried = ca.Function("monodromy_piece", [Ym, Qm, La, Ha, Ts, Cm],
                              [y1, Q1, select_min(low, La), select_max(high, Ha)])
        yk, Qk, lk, hk = carried.mapaccum("monodromy_pieces", S, 4)(Ym, Qm, obs0, obs0, Tm, Cm)
        yk, Qk, lk, hk = (a[:, -b:] for a, b in ((yk, 1), (Qk, Qm.size2()), (lk, 1), (hk, 1)))
    else:
        for k in range(S):
            yk, Qk, low, high = segment(yk, Qk, Tm[:, k * width:(k + 1) * width], Cm)
            lk, hk = select_min(low, lk), select_max(high, hk)
    period = ca.Function("monodromy_period", [Ym, Qm, Tm, Cm], [yk, Qk, lk, hk], *names)
    return segment, period


#: RK4 steps written out in one function. A longer period calls such a segment repeatedly, so the C (and its
#: compile time) stays the same size whatever ``steps_per_period`` is: 3200 steps written out took 24 s to
#: compile. 50 rather than 200: the same speed and the same bits (measured), 2.4x less C.
SEGMENT_STEPS = 50


def over_period(block, carry: list, T: ca.MX, C: ca.MX, K: int, name: str, group: int = 0) -> list:
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
                           over_period(block, args, Ts, Cs, K, name, per))

    whole, rest = divmod(blocks, per)
    carry = over_period(segment(per), carry, T[:, :whole * per * K], C, per * K, name, per)
    if rest:
        carry = list(segment(rest)(*carry, T[:, whole * per * K:], C))
    return carry


def gram_schmidt_function(n: int) -> ca.Function:
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
    return ca.Function("gram_schmidt", [Q], [ca.horzcat(*cols), ca.vertcat(*logs)], SX_OPTIONS)


def orthonormalised_period(tangent_block, gram_schmidt, carry: list, T: ca.MX, C: ca.MX, K: int, every: int,
                           rest: int) -> list:
    """A period of tangent steps re-orthonormalised every ``every`` blocks (and after the ``rest`` at its end):
    the state, the orthonormal vectors, the sum of each vector's log stretches over the period, the extremes.
    Each piece is a function (the tangent steps of ``every`` blocks, Gram-Schmidt, the logs added), applied along
    the table as :func:`over_period` applies a block."""
    y, Q, lo, hi = carry

    def piece(blocks: int) -> ca.Function:
        args = [ca.MX.sym(name, x.sparsity()) for name, x in (("y", y), ("Q", Q), ("lo", lo), ("hi", hi))]
        logs = ca.MX.sym("logs", y.size1())
        Ts, Cs = ca.MX.sym("T", T.size1(), blocks * K), ca.MX.sym("c", C.sparsity())
        yk, Qk, lk, hk = over_period(tangent_block, args, Ts, Cs, K, "tangent")
        Qn, logr = gram_schmidt(Qk)
        return ca.Function(f"orthonormalised_{blocks * K}", [*args, logs, Ts, Cs], [yk, Qn, lk, hk, logs + logr])

    zero = ca.MX.zeros(y.size1())
    whole = (T.size2() // K // every) * every * K
    out = over_period(piece(every), [y, Q, lo, hi, zero], T[:, :whole], C, every * K, "orthonormalised")
    if rest:
        out = list(piece(rest)(*out, T[:, whole:], C))
    return out
