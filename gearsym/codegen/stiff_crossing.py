"""The located crossing step of the stiff method: :class:`~.crossing.CrossingStep` with the RODAS4 step.

The try, the root search and the legs are the RK4 scheme's (``crossing.py``); only the step on each leg is the
Rosenbrock one (:mod:`.rosenbrock`), with its tangent map the exact Jacobian of that step. The legs' tables are the
quadratic through the step's three points, for the tables' values and their rates alike (O(h^3) in a coefficient,
on the few steps per period that cross).
"""
from __future__ import annotations

import casadi as ca

from .casadi_symbols import SX_OPTIONS
from .crossing import CrossingStep
from .rosenbrock import by_vector, matrix_by_vector, rosenbrock_step


class RosenbrockCrossingStep(CrossingStep):
    """The pieces of a crossing-located RODAS4 step (the tables: values, then rates)."""

    def step(self, mode, y, Q, h, T0, Tm, T1):
        return rosenbrock_step(self.f_mode(mode), self.J_mode(mode), y, Q, h, T0, Tm, T1, self.m // 2)

    def tried(self, with_tangent: bool):
        y, Ta, Tb, Tc = self.sym.y, self.Ta, self.Tb, self.Tc
        mode = self.side(self.s_of(y, Ta, self.sym.ch))
        yn, Qn = self.step(mode, y, self.Q if with_tangent else None, self.h, Ta, Tb, Tc)
        return yn, Qn, self.crossed(yn, mode)

    def tried_by_vector(self) -> list[ca.Function]:
        y, ch, Ta = self.sym.y, self.sym.ch, self.Ta
        mode = self.side(self.s_of(y, Ta, ch))
        yn, _ = self.step(mode, y, None, self.h, Ta, self.Tb, self.Tc)
        entries, vector = by_vector(ca.jacobian(yn, y), ch)
        return [ca.Function("tangent_state", [y, self.col, ch], [yn, self.crossed(yn, mode), entries], SX_OPTIONS),
                vector]

    def mode_by_vector(self, mode, length, T0, Tm, T1):
        yn, _ = self.step(mode, self.sym.y, None, length, T0, Tm, T1)
        jacobians, q, qn, symbols = matrix_by_vector(ca.jacobian(yn, self.sym.y))
        return yn, jacobians, q, qn, symbols

    def mode_step(self, with_tangent: bool) -> ca.Function:
        y, ch = self.sym.y, self.sym.ch
        leg = ca.SX.sym("leg", self.surfaces + 1 + 3 * self.m)
        mode, length, T0, Tm, T1 = self.unpack(leg)
        yn, Qn = self.step(mode, y, self.Q if with_tangent else None, length, T0, Tm, T1)
        if with_tangent:
            return ca.Function("tangent_mode_step", [y, self.Q, leg, ch], [yn, Qn], SX_OPTIONS)
        return ca.Function("state_mode_step", [y, leg, ch], [yn], SX_OPTIONS)
