"""Mesh orders from tooth counts: how often each mesh's teeth pass per period of the first mesh.

A train's steady rotation is fixed by its kinematics: on a mesh the two gears roll on each other (``Z_a w_a = Z_b
w_b`` relative to a carrier: the base radii are in the ratio of the teeth), on a shaft both ends turn together.
With every mesh's tooth counts known and one rigid-body mode, the speed of every gear is a rational multiple of
the first's, so every mesh frequency is a rational multiple of the first mesh's: its *order*, exactly, from the
teeth alone (``19 * 23/61`` over ``23`` for the second stage of a 23/61, 19/47 gearbox: ``19/61``). A mesh that
declares no order gets that one; one that declares an order the teeth contradict is refused, with the order to
write (or to leave out). Without tooth counts (a nondimensional model) an undeclared order is 1.
"""
from __future__ import annotations

import functools
from dataclasses import replace
from typing import Optional

import sympy as sp

from ..errors import ModelError
from .symbols import omega, t
from .resolved_components import ResolvedCoupling


def order_text(order: sp.Expr) -> str:
    """How to write ``order`` in a model file: ``sp.Rational(19, 61)``, or a whole number."""
    order = sp.Rational(order)
    return str(order.p) if order.q == 1 else f"sp.Rational({order.p}, {order.q})"


class MeshOrders:
    """The orders of a resolved drivetrain's meshes, from their tooth counts (a base of ResolvedDrivetrain), and
    the periods they make (known from the declaration, before the equations are derived; found once: the
    reduced model's periods and every run's count of cycles read them)."""

    @functools.cached_property
    def forcing_period(self) -> sp.Expr:
        """The forcing period in tau: one mesh period of the first mesh (2 pi / its order; 2 pi without a mesh)."""
        meshes = [rc.order for rc in self.couplings if rc.kind == "mesh"]
        return 2 * sp.pi / meshes[0] if meshes else 2 * sp.pi

    @functools.cached_property
    def period(self) -> sp.Expr:
        """The period the drivetrain repeats on, in tau: 2 pi / the greatest common divisor of every frequency in
        it (every mesh's order, the torques' harmonics and the shaft-order terms' frequencies)."""
        freqs = [rc.order for rc in self.couplings if rc.kind == "mesh"]
        freqs += [sp.Integer(f.order) for f in self.forcing if f.order]
        freqs += [f for rc in self.couplings for f in rc.shaft_frequencies]
        return 2 * sp.pi / functools.reduce(sp.gcd, freqs, sp.S.Zero) if freqs else 2 * sp.pi

    @functools.cached_property
    def cycles(self) -> int:
        """Forcing periods in one :attr:`period`: 1 for a single pair."""
        return int(sp.nsimplify(self.period / self.forcing_period))

    def _teeth_motion(self) -> Optional[list[sp.Expr]]:
        """The steady rotation with the radii replaced by the tooth counts (exact rationals), or None: a mesh
        without both tooth counts, or not one rigid-body mode (a differential's speeds are not fixed by teeth)."""
        rows = []
        for rc in self.couplings:
            if rc.kind in ("shaft", "bearing"):  # (a bearing holds its centre still in the steady rotation)
                rows.append(list(rc.row))
                continue
            teeth = [end.body.tooth_count for end in (rc.a, rc.b)]
            if any(not isinstance(z, int) or isinstance(z, bool) or z < 1 for z in teeth):
                return None
            sign = 1 if any(getattr(end.body, "internal", False) for end in (rc.a, rc.b)) else -1
            rows.append([teeth[0] * a + sign * teeth[1] * b for a, b in zip(*rc.turning)])
        modes = sp.Matrix(rows).nullspace()
        return list(modes[0]) if len(modes) == 1 else None

    def _mesh_rate(self, rc: ResolvedCoupling, motion: list[sp.Expr]) -> sp.Expr:
        """Teeth passing per unit of ``motion`` (the driving gear's teeth times its speed relative to a carrier)."""
        return abs(rc.a.body.tooth_count * sum(e * u for e, u in zip(rc.turning[0], motion)))

    def _with_orders(self, couplings: list[ResolvedCoupling]) -> list[ResolvedCoupling]:
        """``couplings`` with every mesh's order derived from the teeth (see the module's docstring), checked
        against any order declared."""
        meshes = [rc for rc in couplings if rc.kind == "mesh"]
        if not meshes:
            return couplings
        motion = self._teeth_motion()
        if motion is None or any(self._mesh_rate(rc, motion) == 0 for rc in meshes):
            return [self._order_given(rc, sp.S.One) if rc.kind == "mesh" else rc for rc in couplings]
        reference = meshes[0]
        base = self._declared_order(reference) or sp.S.One
        unit = self._mesh_rate(reference, motion) / base
        out = []
        for rc in couplings:
            if rc.kind == "mesh":
                rc = self._order_given(rc, sp.nsimplify(self._mesh_rate(rc, motion) / unit))
            out.append(rc)
        return out

    @staticmethod
    def _declared_order(rc: ResolvedCoupling) -> Optional[sp.Expr]:
        return None if rc.component.order is None else rc.order

    def _order_given(self, rc: ResolvedCoupling, derived: sp.Expr) -> ResolvedCoupling:
        """``rc`` with the order ``derived`` (from the teeth, or 1 without them), or its declared one if that
        agrees; a declared order that the teeth contradict is an error that says what to write."""
        declared = self._declared_order(rc)
        if declared is None:
            return replace(rc, order=derived, mesh_phase=rc.mesh_phase + derived * omega * t)
        if declared != derived and rc.a.body.tooth_count and rc.b.body.tooth_count:
            raise ModelError(
                f"is declared with order {order_text(declared)} of the forcing frequency, but its tooth counts "
                f"({rc.a.body.tooth_count}/{rc.b.body.tooth_count}, with those of the meshes before it) give "
                f"{order_text(derived)}: leave order= out (it is derived from the teeth) or write "
                f"order={order_text(derived)}", f"Mesh {rc.name!r}")
        return rc
