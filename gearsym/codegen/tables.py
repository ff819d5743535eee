"""The tables of time of one run: every RK4 stage's values of the time-dependent parts over one period."""
from __future__ import annotations

import casadi as ca



def table_function(constants: ca.Function, table_point: ca.Function, n_params: int, nc: int, m: int,
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
