"""The CasADi functions of one model: right-hand side, exact Jacobian, and the
fixed-step RK4 loops with their variational equations.

Layering (the CasADi pitfall: a loop Function called on SX symbols is inlined,
and 80 000 inlined RK4 steps crash the C compiler):

* SX, straight-line code with common subexpressions removed: ``rhs``,
  ``jacobian``, one RK4 step of the state and its tangent matrix (a *block*),
  the Gram-Schmidt re-orthonormalisation (from ``BY_COLUMN_FROM`` states on, the two functions that carry the
  whole tangent matrix, Gram-Schmidt and the located step's substep, are SX pieces of one column each composed
  in MX, :mod:`.columns`: their unrolled C grows with n^3 and n^2);
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
both substeps (see ``crossing_steps``); the split runs only on crossing steps,
behind a real ``if`` in the C (in the MX loops a CasADi ``Switch``), as calls of
SX pieces (``SPLIT_CALLS``): one mode-RK4 step for every substep.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..errors import ModelError
from ..system import FirstOrderSystem
from .casadi_symbols import SX_OPTIONS, LoopSymbols
from .columns import gram_schmidt_by_column
from .crossing import crossing_steps
from .loops import LoopOptions
from .period_loops import gram_schmidt_function, monodromy, orthonormalised_period, over_period
from .rk4 import rk4_functions, tangent_by_vector
from .rosenbrock import rosenbrock_functions, with_rates
from .stiff_crossing import RosenbrockCrossingStep
from .switching import find_switching
from .tables import table_function
from .time_tables import SplitRHS, split_rhs
from .translate import to_casadi

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
    #: :data:`SPLIT_CALLS`), and ``gram_schmidt``; for a large model, functions of pieces by column (MX) and their
    #: pieces (:data:`.columns.PARTS`)
    steps: dict[str, ca.Function]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.functions)


def build_functions(system: FirstOrderSystem, options: LoopOptions = LoopOptions()) -> ModelFunctions:
    """Every function the engine generates for ``system`` (see the module docstring)."""
    split = split_rhs(system, factored=options.locate_crossings)
    stiff = options.method == "stiff"
    if stiff:  # the stiff step reads the tables' rates too (df/dt and its stage times)
        split = with_rates(split, system.time)
    sym = LoopSymbols(system, split)
    n, m, nc = system.dimension, len(split.tables), len(split.constants)
    N, K = options.steps_per_period, options.block(n)
    where = system.name

    # rhs and Jacobian in the user's terms (time, state, parameters)
    f_user = sym.base.rhs(system)
    rhs = ca.Function("rhs", [sym.t, sym.y, sym.p], [f_user], ["t", "y", "p"], ["dy"], SX_OPTIONS)
    jacobian = ca.Function("jacobian", [sym.t, sym.y, sym.p], [ca.densify(ca.jacobian(f_user, sym.y))],
                           ["t", "y", "p"], ["J"], SX_OPTIONS)

    # what the loops need once per run: constants (then the step h), tables of time
    period_expr, h_expr = to_casadi([system.period, system.period / N], sym.outer, where)
    if ca.depends_on(period_expr, ca.vertcat(sym.t, sym.y)):
        raise ModelError(f"the forcing period {system.period} may depend on parameters only", where)
    const_values = to_casadi([e for _, e in split.constants], sym.outer, where)
    constants = ca.Function("constants", [sym.p], [ca.vertcat(*const_values, h_expr), period_expr], ["p"],
                            ["c", "period"], SX_OPTIONS)
    table_values = to_casadi([e for _, e in split.tables], sym.outer, where)
    table_point = ca.Function("table_point", [sym.t, sym.p], [ca.vertcat(*table_values) if m else ca.SX(0, 1)],
                              ["t", "p"], ["values"], SX_OPTIONS)

    switching = find_switching(system, split) if options.locate_crossings else None
    by_column = options.by_column(n)  # a large model's tangent matrix by column (columns.py): its C stays small
    if stiff and (switching is None or not switching.surfaces):
        tangent_block, state_block, state_step, steps = rosenbrock_functions(sym, split, where)
        steps["state_block"] = state_block
    elif stiff:
        tangent_block, state_block, state_step, steps = crossing_steps(sym, split, switching, where,
                                                                       RosenbrockCrossingStep, by_column)
    elif switching is None or not switching.surfaces:  # nothing switches (Lorenz): the plain loops
        tangent_block, state_block, state_step = rk4_functions(sym, split, K, where)
        steps = {**tangent_by_vector(sym, split, K, where), "state_block": state_block}
        if K > 1:  # the trajectory's steps one at a time
            steps["trajectory_step"] = state_step
    else:
        tangent_block, state_block, state_step, steps = crossing_steps(sym, split, switching, where,
                                                                       by_column=by_column)
    if by_column:
        gram_schmidt, *parts = gram_schmidt_by_column(n)
        steps.update({f.name(): f for f in parts})
    else:
        gram_schmidt = gram_schmidt_function(n)
    steps["gram_schmidt"] = gram_schmidt

    # MX loops over the SX functions
    Ym, Qm, Cm = ca.MX.sym("y", n), ca.MX.sym("Q", n, n), ca.MX.sym("c", nc + 1)
    Tm = ca.MX.sym("T", 3 * m, N)
    obs0 = ca.vertcat(*[Ym[j] for j in sym.observed])

    every, rest = options.orthonormalised(n)
    if every:  # Gram-Schmidt every few steps (LoopOptions.reorthonormalise), the logs summed over the period
        yk, Qn, lk, hk, logr = orthonormalised_period(tangent_block, gram_schmidt, [Ym, Qm, obs0, obs0], Tm, Cm, K,
                                                      every, rest)
    else:
        yk, Qk, lk, hk = over_period(tangent_block, [Ym, Qm, obs0, obs0], Tm, Cm, K, "tangent")
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

    yk, lk, hk = over_period(state_block, [Ym, obs0, obs0], Tm, Cm, K, "state")
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

    monodromy_segment, monodromy_period = monodromy(tangent_block, obs0, Ym, Qm, Cm, m, N, K, system.cycles)

    table = table_function(constants, table_point, len(sym.params), nc, m, N)
    functions = {f.name(): f for f in (rhs, jacobian, constants, table, lyapunov_chunk, lyapunov_period,
                                       orbit_chunk, orbit_period, trajectory, monodromy_segment, monodromy_period)}
    return ModelFunctions(system, options, split, functions, steps)
