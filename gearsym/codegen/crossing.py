"""The located crossing step: a step that crosses a backlash surface is split there, its zero found by a
cubic Hermite root search, so that RK4 sees a smooth right-hand side on both substeps (4th order exponents).

The split runs only on crossing steps, behind a real ``if`` in the C (in the MX loops a CasADi ``Switch``), as
calls of SX pieces (:data:`SPLIT_CALLS`): one mode-RK4 step for every substep, one root search per surface.
"""
from __future__ import annotations


import casadi as ca

from .casadi_symbols import SX_OPTIONS, LoopSymbols
from .columns import mode_step_by_column
from .rk4 import by_vector, rk4_step, tabulated_rhs
from .switching import Switching
from .time_tables import SplitRHS
from .translate import select_max, select_min, to_casadi


def crossing_steps(sym: LoopSymbols, split: SplitRHS, switching: Switching, where: str, kind: type | None = None,
                   by_column: bool = False):
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

    ``by_column``: the substep with the tangent matrix (``tangent_mode_step``) is made of pieces by column
    (:mod:`.columns`: a large model's C stays small).
    """
    # (kind: the stiff step's, stiff_crossing.py)
    step = (kind or CrossingStep)(sym, split, switching, where, by_column)
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

    # the printed loops' tangent try is the state's, then each tangent vector's (:meth:`CrossingStep.tried_by_vector`)
    printed = {name: f for name, f in pieces.items() if name != "tangent_try"}
    return tangent_block, state_block, step.single(state_try, state_switch), printed


#: the split of a located step (:meth:`CrossingStep.pieces`) as calls of SX pieces, (piece, inputs, outputs):
#: the one description of both the MX function (:func:`split_function`) and the printed C (:mod:`.printed`), so
#: that the C holds the crossing's root search once and the mode-RK4 step once with tangent and once without,
#: not once per substep. ``{kind}`` is tangent or state; the state's split leaves out the tangent matrices (the
#: names that start with Q). A *leg* is a substep: the sides held fixed, its length, and the tables at its
#: start, middle and end (:meth:`CrossingStep.leg`); the first zero is searched on ``leg_try`` (mode A over the
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


class CrossingStep:
    """The pieces of a crossing-located RK4 step (see :func:`crossing_steps`): the frozen-mode right-hand
    side and Jacobian, the surfaces and their rates, in the loop's symbols."""

    def __init__(self, sym: LoopSymbols, split: SplitRHS, switching: Switching, where: str, by_column: bool = False):
        n, m, nc = sym.y.numel(), len(split.tables), sym.ch.numel() - 1
        self.by_column = by_column  # the substep with the tangent matrix made of pieces by column (columns.py)
        self.sym, self.n, self.m, self.nc = sym, n, m, nc
        y, T, ch = sym.y, sym.T, sym.ch
        self.h = ch[nc]
        self.f_of, self.J_of = tabulated_rhs(sym, split, where)
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
        """The tangent try in two pieces for the printed loop, as the plain step's (:func:`by_vector`):
        ``tangent_state`` (the state's try, its flag and each stage's Jacobian nonzeros) and ``tangent_vector``
        (one tangent vector's try given them); with ``state_keep`` they compute ``tangent_try`` and
        ``tangent_keep``, operation for operation."""
        y, ch, Ta = self.sym.y, self.sym.ch, self.Ta
        mode = self.side(self.s_of(y, Ta, ch))
        states, J_all, q, qn, symbols = by_vector(self.f_mode(mode), self.J_mode(mode), y, self.h,
                                                    [(Ta, self.Tb, self.Tc)])
        return [ca.Function("tangent_state", [y, self.col, ch], [states[0], self.crossed(states[0], mode), J_all],
                            SX_OPTIONS),
                ca.Function("tangent_vector", [q, symbols, ch], [qn], SX_OPTIONS)]

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
            return ca.Function("tangent_mode_step", [y, Q, leg, ch], [yn, Qn], SX_OPTIONS)
        return ca.Function("state_mode_step", [y, leg, ch], [yn], SX_OPTIONS)

    def mode_step_by_column(self) -> list[ca.Function]:
        """``tangent_mode_step`` made of pieces by column (:func:`.columns.mode_step_by_column`), then the pieces:
        ``tangent_mode_state`` (the state's substep along a leg and its stages' Jacobians, as :func:`by_vector`
        splits the plain step) and ``tangent_mode_vector`` (one column's substep given them)."""
        y, ch = self.sym.y, self.sym.ch
        leg = ca.SX.sym("leg", self.surfaces + 1 + 3 * self.m)
        mode, length, T0, Tm, T1 = self.unpack(leg)
        yn, jacobians, q, qn, symbols = self.mode_by_vector(mode, length, T0, Tm, T1)
        state = ca.Function("tangent_mode_state", [y, leg, ch], [yn, jacobians], SX_OPTIONS)
        vector = ca.Function("tangent_mode_vector", [q, symbols, leg, ch], [qn], SX_OPTIONS)
        return [mode_step_by_column(state, vector), state, vector]

    def mode_by_vector(self, mode, length, T0, Tm, T1):
        """(the state after a substep of the sides ``mode`` from y, its stages' Jacobians' nonzeros, a tangent
        vector q, q after the substep given them, the symbols that stand for them in it)."""
        states, jacobians, q, qn, symbols = by_vector(self.f_mode(mode), self.J_mode(mode), self.sym.y, length,
                                                      [(T0, Tm, T1)])
        return states[0], jacobians, q, qn, symbols

    def split_start(self) -> ca.Function:
        """``split_start``: the try's leg (mode A, the sides at the step's start, over the whole step), the
        step's start (0) and mode A. The located step (:data:`SPLIT_CALLS`): up to two crossings in the step (a
        crossing, or a dip's way in and out), RK4 of mode A up to the first (``leg_a``), of mode B up to the
        second (``leg_b``), of mode C over the rest (``leg_c``); each on its own smooth branch."""
        y, ch = self.sym.y, self.sym.ch
        mode_a = self.side(self.s_of(y, self.Ta, ch))
        leg = self.leg(mode_a, self.h, self.Ta, self.Tb, self.Tc)
        return ca.Function("split_start", [y, self.col, ch], [leg, ca.SX.zeros(1), mode_a], SX_OPTIONS)

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
        return [ca.Function("crossing_ends", [y0, y_end, leg, before, self.sym.ch], [ends], SX_OPTIONS),
                ca.Function("first_zero", [one], [ca.vertcat(*_first_zero(*ca.vertsplit(one)))], SX_OPTIONS),
                ca.Function("crossing_earliest", [zeros, leg], list(self.earliest(zeros[0, :].T, zeros[1, :].T, mode)),
                            SX_OPTIONS)]

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
                           SX_OPTIONS)

    def extremes(self, yn):
        obs = ca.vertcat(*[yn[j] for j in self.sym.observed])
        return select_min(obs, self.lo), select_max(obs, self.hi)

    def switched(self, kind: str, with_tangent: bool) -> tuple[ca.Function, ca.Function]:
        """``{kind}_try`` (the plain step and its crossing flag) and ``{kind}_keep`` (keep the try), with or
        without tangent vectors."""
        y, ch, col = self.sym.y, self.sym.ch, self.col
        yn, Qn, flag = self.tried(with_tangent)
        if with_tangent:
            tried = ca.Function(f"{kind}_try", [y, self.Q, col, ch], [yn, Qn, flag], SX_OPTIONS)
            inputs, kept = [y, self.Q, self.lo, self.hi, self.y1, self.Q1, col, ch], [self.y1, self.Q1]
        else:
            tried = ca.Function(f"{kind}_try", [y, col, ch], [yn, flag], SX_OPTIONS)
            inputs, kept = [y, self.lo, self.hi, self.y1, col, ch], [self.y1]
        return tried, ca.Function(f"{kind}_keep", inputs, [*kept, *self.extremes(self.y1)], SX_OPTIONS)

    def pieces(self) -> list[ca.Function]:
        """The SX pieces of the located steps (:data:`SPLIT_CALLS`), in a fixed order."""
        tangent = self.mode_step_by_column() if self.by_column else [self.mode_step(True)]
        return [*self.switched("tangent", True), *self.switched("state", False), self.split_start(),
                *self.crossing(), self.split_legs(), *tangent, self.mode_step(False), *self.tried_by_vector()]

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
    function of the ends, which keeps the located step continuous in its start (see ``crossing_steps``)."""
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
