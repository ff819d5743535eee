"""The stiff step: a Rosenbrock method (RODAS4) with the exact Jacobian, and its tangent map.

Real drivetrains are stiff: coupling, shaft and bearing modes far above the mesh frequency force explicit RK4 to
a step set by the fastest mode (h |lambda| <= 2.78), however slowly the motion of interest varies. A Rosenbrock
method is linearly implicit: each stage solves one linear system with W = I/(gamma h) - J(t0, y0), J the exact
Jacobian CasADi already differentiates for the variational equations, and no Newton iteration, so a step is a
fixed sequence of operations, straight-line SX code like the RK4 step. RODAS4 (Hairer & Wanner, *Solving Ordinary
Differential Equations II*, 2nd ed. 1996, IV.7; their code ``rodas.f``) has six stages, order 4, and is L-stable and
stiffly accurate: a mode far faster than the step is damped out in one step instead of making it blow up.

* **Time.** The stage times c_i = 0, 0.386, 0.21, 0.63, 1, 1 are not the RK4 tables' 0, 1/2, 1, and the method
  needs df/dt at the step's start. The stiff loops' tables carry every time-dependent value *and its rate*
  (:func:`with_rates`: the rate is the SymPy derivative of the table's expression, exact) at the half-step
  times, and a stage takes its values from the quintic Hermite polynomial through those three points (values
  and rates): O(h^6), beyond the method's order. df/dt at t0 is df/dT times the tables' exact rates there.
* **The tangent map is the derivative of the discrete step.** The step's map y0 -> y1 is a rational function of
  y0 through f, J and the solves; its Jacobian dy1/dy0 (CasADi's algorithmic differentiation of the step, the
  solves and the Hessian of f included) carries the tangent vectors. So the exponents are those of the discrete
  map, Sum lambda_i equals the mean log-determinant of the step maps, and Newton on a period of steps
  (``gearsym orbits``) sees the exact Jacobian of the map it solves. Within one side of the backlash J does not
  depend on y (g is piecewise linear), and the Hessian terms vanish in the generated code.
* **The linear solves** are an LU factorisation of W without pivoting, written out on SX scalars (a structural
  zero stays out of the code, so a chain's banded W keeps its band): W = I/(gamma h) - J has the positive 1/(gamma h)
  on its diagonal and, for a damped mechanical system, stays positive definite in the leading blocks.
"""
from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np
import sympy as sp

from .casadi_symbols import SX_OPTIONS, LoopSymbols
from .time_tables import SplitRHS
from .rk4 import tabulated_rhs
from .translate import select_max, select_min

#: RODAS4 in the form of Hairer & Wanner's rodas.f (IV.7.2 with the W-transformation): gamma, stage times c, the
#: coefficients a (stage arguments), C (stage couplings, over h) and d (the df/dt term, times h)
GAMMA = 0.25
C_TIMES = (0.0, 0.386, 0.21, 0.63, 1.0, 1.0)
A = ((), (1.544,), (0.9466785280815826, 0.2557011698983284),
     (3.314825187068521, 2.896124015972201, 0.9986419139977817),
     (1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895))
C = ((), (-5.6688,), (-2.430093356833875, -0.2063599157091915),
     (-0.1073529058151375, -9.594562251023355, -20.47028614809616),
     (7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616),
     (8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054))
D = (0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0)
#: the method's order (for the step-halving tests and reports)
ORDER = 4


def with_rates(split: SplitRHS, time: sp.Symbol) -> SplitRHS:
    """``split`` with the time derivative of every table appended as a table of its own (in order): what the
    stiff step reads df/dt and the stage times' values from."""
    rates = tuple((sp.Dummy(f"rate_{i}", real=True), sp.diff(expr, time)) for i, (_, expr) in enumerate(split.tables))
    return replace(split, tables=split.tables + rates)


def _hermite_weights(c: float) -> tuple[np.ndarray, np.ndarray]:
    """Weights (w, u) of the quintic through values V_j and derivatives D_j (per unit theta) at theta = 0, 1/2,
    1: p(c) = sum w_j V_j + sum u_j D_j."""
    nodes = (0.0, 0.5, 1.0)
    rows = [[t**k for k in range(6)] for t in nodes] + [[k * t**(k - 1) if k else 0.0 for k in range(6)]
                                                       for t in nodes]
    coefficients = np.linalg.inv(np.array(rows))  # columns: the monomial coefficients of each basis function
    at = np.array([c**k for k in range(6)]) @ coefficients
    return at[:3], at[3:]


def stage_values(Ta, Tb, Tc, h, m: int, c: float):
    """The tables' values (and their rates, interpolated the same way) at t0 + c h, from (values, rates) at
    t0, t0 + h/2, t0 + h. At c = 0 and 1 the nodes themselves."""
    if c == 0.0:
        return Ta
    if c == 1.0:
        return Tc
    w, u = _hermite_weights(c)
    values = sum(float(w[j]) * T[:m] for j, T in enumerate((Ta, Tb, Tc)))
    values = values + h * sum(float(u[j]) * T[m:] for j, T in enumerate((Ta, Tb, Tc)))
    return ca.vertcat(values, Ta[m:])  # (f reads the values only)


def _lu_solve(W: ca.SX):
    """The solver of W x = b by Doolittle LU without pivoting, on SX scalars; structural zeros stay zeros."""
    n = W.size1()
    a = [[W[i, j] for j in range(n)] for i in range(n)]
    for k in range(n):
        for i in range(k + 1, n):
            if a[i][k].is_zero():
                continue
            a[i][k] = a[i][k] / a[k][k]
            for j in range(k + 1, n):
                if not a[k][j].is_zero():
                    a[i][j] = a[i][j] - a[i][k] * a[k][j]

    def solve(b: ca.SX) -> ca.SX:
        x = [b[i] for i in range(n)]
        for i in range(n):
            for j in range(i):
                if not a[i][j].is_zero():
                    x[i] = x[i] - a[i][j] * x[j]
        for i in reversed(range(n)):
            for j in range(i + 1, n):
                if not a[i][j].is_zero():
                    x[i] = x[i] - a[i][j] * x[j]
            x[i] = x[i] / a[i][i]
        return ca.vertcat(*x)

    return solve


def rosenbrock_state(f, J, y: ca.SX, h, Ta, Tb, Tc, m: int) -> ca.SX:
    """One RODAS4 step of length h from ``y``: f(x, T) and J(x, T) the right-hand side and its Jacobian with the
    tables T (values, then rates) at a time; Ta, Tb, Tc the tables at t0, t0 + h/2, t0 + h."""
    n = y.numel()
    J0 = J(y, Ta)
    empty = h == 0  # (a leg of the located step may have no length: then no step, not 1/(gamma 0))
    h = ca.if_else(empty, 1, h)
    solve = _lu_solve(ca.SX.eye(n) / (GAMMA * h) - J0)
    Ts = ca.SX.sym("Ts", Ta.numel())
    dfdt = ca.substitute(ca.jtimes(f(y, Ts), Ts, ca.vertcat(Ta[m:], ca.SX.zeros(Ta.numel() - m))), Ts, Ta)
    k, u = [], y
    for i, c in enumerate(C_TIMES):
        if i == 5:
            u = u + k[4]
        elif i:
            u = y + sum(A[i][j] * k[j] for j in range(i))
        rhs = f(u, stage_values(Ta, Tb, Tc, h, m, c))
        if i:
            rhs = rhs + sum(C[i][j] * k[j] for j in range(i)) / h
        if D[i]:
            rhs = rhs + (D[i] * h) * dfdt
        k.append(solve(rhs))
    return ca.if_else(empty, y, u + k[5])


def rosenbrock_step(f, J, y: ca.SX, Q, h, Ta, Tb, Tc, m: int):
    """The step and, unless ``Q`` is None, its tangent map applied to Q (the exact Jacobian of the step, from
    ``y``, which must be a symbol: the step's start)."""
    y_next = rosenbrock_state(f, J, y, h, Ta, Tb, Tc, m)
    if Q is None:
        return y_next, None
    return y_next, ca.mtimes(ca.jacobian(y_next, y), Q)


def rosenbrock_functions(sym: LoopSymbols, split: SplitRHS, where: str):
    """``tangent_block``, ``state_block`` (one step each), ``trajectory_step`` and the printed loops' pieces
    (:func:`by_vector`), as :func:`.rk4.rk4_functions` and :func:`.rk4.tangent_by_vector` give them, of the stiff
    step (``split`` with its rates, :func:`with_rates`)."""
    n, m2 = sym.y.numel(), len(split.tables)
    y, ch = sym.y, sym.ch
    h = ch[ch.numel() - 1]
    f_of, J_of = tabulated_rhs(sym, split, where)
    Q = ca.SX.sym("Q", n, n)
    lo, hi = ca.SX.sym("lo", len(sym.observed)), ca.SX.sym("hi", len(sym.observed))
    Tk = ca.SX.sym("Tk", 3 * m2, 1)
    y1 = rosenbrock_state(lambda x, T: f_of(x, T, ch), lambda x, T: J_of(x, T, ch), y, h, Tk[:m2],
                          Tk[m2:2 * m2], Tk[2 * m2:], m2 // 2)
    M = ca.jacobian(y1, y)
    obs = ca.vertcat(*[y1[j] for j in sym.observed])
    lk, hk = select_min(obs, lo), select_max(obs, hi)
    tangent_block = ca.Function("tangent_block", [y, Q, lo, hi, Tk, ch], [y1, ca.mtimes(M, Q), lk, hk], SX_OPTIONS)
    state_block = ca.Function("state_block", [y, lo, hi, Tk, ch], [y1, lk, hk], SX_OPTIONS)
    state_step = ca.Function("trajectory_step", [y, Tk, ch], [y1], SX_OPTIONS)
    entries, vector = by_vector(M, ch)
    state = ca.Function("tangent_state", [y, lo, hi, Tk, ch], [y1, lk, hk, entries], SX_OPTIONS)
    return tangent_block, state_block, state_step, {"tangent_state": state, "tangent_vector": vector}


def by_vector(M: ca.SX, ch: ca.SX) -> tuple[ca.SX, ca.Function]:
    """The step map M in the two pieces of the printed loops' tangent step (as :func:`.rk4.by_vector`): its
    non-constant nonzeros, which the state's piece outputs, and ``tangent_vector``, one tangent vector through
    the map given them (the loop applies it to each vector in turn)."""
    entries, q, Mq, symbols = matrix_by_vector(M)
    return entries, ca.Function("tangent_vector", [q, symbols, ch], [Mq], SX_OPTIONS)


def matrix_by_vector(M: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX, ca.SX]:
    """(M's non-constant nonzeros, a vector q, M q with symbols in place of those nonzeros, the symbols)."""
    entries = [e for e in M.nonzeros() if not e.is_constant()]
    symbols = ca.SX.sym("J", max(1, len(entries)))
    given, k = [], 0
    for e in M.nonzeros():
        if e.is_constant():
            given.append(e)
        else:
            given.append(symbols[k])
            k += 1
    Mg = ca.SX(M.sparsity(), ca.vertcat(*given) if given else ca.SX(0, 1))
    q = ca.SX.sym("q", M.size2())
    return (ca.vertcat(*entries) if entries else ca.SX(0, 1)), q, ca.mtimes(Mg, q), symbols
