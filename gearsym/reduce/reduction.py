"""Reduction of the equations of motion to relative coordinates.

With M the (diagonal) inertia matrix, Lagrange gives M psi'' = sum_c Q_c + Q_ext.
For q = T psi the reduced equations are q'' = T M^-1 (sum_c Q_c + Q_ext), and
they close in q because each Q_c depends on psi only through its coupling's
deflection, which T determines. We substitute psi = W [q; a] (a: the rigid
coordinates), check that every a drops out, and factor each coupling's
contribution to row i as ``-factor_ic * law_c(q)``; those factors are what the
paper calls r1^2/I1 + r2^2/I2, 1/I2, ... and become the coefficient groups.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import sympy as sp

from ..backlash import g
from ..errors import GearsymError
from ..model.drivetrain import Drivetrain, ResolvedCoupling, ResolvedDrivetrain, ResolvedForcing
from ..symbols import t
from .coordinates import Coordinate, angle_symbols, relative_coordinates, rigid_body_modes, to_symbols


class ReductionError(GearsymError):
    """The reduction found an inconsistency (a bug, or a component it cannot reduce)."""


@dataclass(frozen=True)
class CouplingTerm:
    """Row ``row`` of the reduced equations contains ``-factor * law(coupling)``."""

    row: int
    coupling: ResolvedCoupling
    factor: sp.Expr


@dataclass(frozen=True)
class ForcingTerm:
    """Row ``row`` contains ``coefficient * cos(order*omega*t + phase)`` (or the constant if order == 0)."""

    row: int
    source: ResolvedForcing
    coefficient: sp.Expr

    @property
    def key(self) -> tuple[int, sp.Expr]:
        return (self.source.order, self.source.phase)


@dataclass
class Reduction:
    """The reduced (dimensional-time) equations and everything derived on the way."""

    drivetrain: Drivetrain
    resolved: ResolvedDrivetrain
    coordinates: list[Coordinate]
    transform: sp.Matrix
    rigid_modes: list[sp.Matrix]
    coupling_terms: list[CouplingTerm] = field(default_factory=list)
    forcing_terms: list[ForcingTerm] = field(default_factory=list)

    def law(self, rc: ResolvedCoupling, time: sp.Symbol = t) -> sp.Expr:
        """The coupling's force written in its own relative coordinate x:
        ``kZ(t) g(x, eta) + cZ x'`` for a mesh, ``kS x + cS x'`` for a shaft."""
        x = self.coordinate_of(rc).of(time)
        xd = sp.diff(x, time)
        if rc.kind == "mesh":
            return self.resolved.stiffness_at(rc) * g(x, rc.backlash) + rc.damping * xd
        return rc.stiffness * x + rc.damping * xd

    def coordinate_of(self, rc: ResolvedCoupling) -> Coordinate:
        return next(c for c in self.coordinates if c.coupling is rc)

    def row_terms(self, row: int) -> list[CouplingTerm]:
        return [ct for ct in self.coupling_terms if ct.row == row]

    def row_forcing(self, row: int) -> list[ForcingTerm]:
        return [ft for ft in self.forcing_terms if ft.row == row]

    @cached_property
    def equations(self) -> list[sp.Eq]:
        """x_i'' = -sum_c factor_ic law_c + forcing_i, in the time t."""
        out = []
        for i, c in enumerate(self.coordinates):
            rhs = -sp.Add(*(ct.factor * self.law(ct.coupling) for ct in self.row_terms(i)))
            rhs += sp.Add(*(ft.coefficient * ft.source.time_function for ft in self.row_forcing(i)))
            out.append(sp.Eq(sp.diff(c.of(t), t, 2), rhs))
        return out

    @cached_property
    def rigid_body_equations(self) -> list[sp.Eq]:
        """u^T M psi'' = u^T Q_ext for each rigid mode u: the couplings drop out."""
        rd = self.resolved
        out = []
        for u in self.rigid_modes:
            lhs = sp.Add(*(u[i] * rb.inertia * sp.diff(rb.angle, t, 2) for i, rb in enumerate(rd.bodies)))
            rhs = sp.Add(*(u[i] * q for i, q in enumerate(rd.generalized_forces)))
            out.append(sp.Eq(lhs, rhs))
        return out


def _simplify_backlash_args(expr: sp.Expr) -> sp.Expr:
    return expr.replace(lambda e: isinstance(e, g), lambda e: g(sp.simplify(e.args[0]), e.args[1]))


def reduce_drivetrain(model: Drivetrain) -> Reduction:
    """Derive the reduced equations of ``model`` in relative coordinates."""
    rd = model.resolved
    coords, T = relative_coordinates(rd)
    modes = rigid_body_modes(rd)
    red = Reduction(model, rd, coords, T, modes)
    n = len(rd.bodies)
    M = rd.mass_matrix
    if M != sp.diag(*[rb.inertia for rb in rd.bodies]):
        raise ReductionError(f"unexpected inertia matrix {M}; bodies must be uncoupled rotors")
    TMinv = T * M.inv()

    # psi = W [q; a]: a are the coordinates along the rigid modes
    p, pd = angle_symbols(rd)
    q = [sp.Symbol(c.name, real=True) for c in coords]
    qd = [sp.Symbol(c.velocity_name, real=True) for c in coords]
    a = [sp.Symbol(f"_a{k}", real=True) for k in range(len(modes))]
    ad = [sp.Symbol(f"_ad{k}", real=True) for k in range(len(modes))]
    basis = T.col_join(sp.Matrix.hstack(*modes).T) if modes else T
    if basis.shape != (n, n):
        raise ReductionError(f"{len(coords)} coordinates and {len(modes)} rigid modes do not span {n} angles")
    W = sp.simplify(basis.inv())
    to_q = dict(zip(p, W * sp.Matrix(q + a))) | dict(zip(pd, W * sp.Matrix(qd + ad)))
    back = {s: c.of(t) for s, c in zip(q, coords)} | {s: sp.diff(c.of(t), t) for s, c in zip(qd, coords)}

    # the coupling forces, checked against the full Lagrange equations
    total = sp.zeros(n, 1)
    for rc in rd.couplings:
        Qc = sp.Matrix(rd.coupling_forces(rc))
        total += Qc
        for u in modes:
            if sp.simplify((u.T * Qc)[0]) != 0:
                raise ReductionError(f"{rc.name}: its forces do work in a rigid-body rotation")
        reduced = (TMinv * Qc).applyfunc(lambda e: to_symbols(e, rd, p, pd).xreplace(to_q))
        own = red.coordinate_of(rc)
        law_q = red.law(rc).xreplace({sp.diff(own.of(t), t): sp.Symbol(own.velocity_name, real=True)})
        law_q = law_q.xreplace({own.of(t): sp.Symbol(own.name, real=True)})
        for i in range(len(coords)):
            e = _simplify_backlash_args(sp.expand(reduced[i]))
            if sp.simplify(e) == 0:
                continue
            factor = sp.factor(sp.cancel(-e / law_q))
            leftover = factor.free_symbols & set(q + qd + a + ad + [t])
            if leftover or factor.has(sp.Function):
                raise ReductionError(f"{rc.name}: row {coords[i].name} does not factor as (group) x (coupling law): {e}")
            red.coupling_terms.append(CouplingTerm(i, rc, factor))
    eom_forces = [sp.expand(eq.rhs - (eq.lhs - sum(M[i, j] * sp.diff(rd.angles[j], t, 2) for j in range(n))))
                  for i, eq in enumerate(rd.equations_of_motion)]
    for i in range(n):
        if sp.simplify(eom_forces[i] - sp.expand(total[i] + rd.generalized_forces[i])) != 0:
            raise ReductionError(f"coupling forces do not add up to the equation of motion of psi_{i + 1}")

    # external torques: row i gets (T M^-1)_{i, body} * torque
    for f in rd.forcing:
        for i in range(len(coords)):
            coefficient = sp.factor(TMinv[i, f.body.index] * f.amplitude)
            if coefficient != 0:
                red.forcing_terms.append(ForcingTerm(i, f, coefficient))

    # final check: the assembled equations equal T M^-1 (Q) with psi eliminated
    for i, eq in enumerate(red.equations):
        direct = sp.expand((TMinv * (total + sp.Matrix(rd.generalized_forces)))[i])
        direct = _simplify_backlash_args(to_symbols(direct, rd, p, pd).xreplace(to_q)).xreplace(back)
        if sp.simplify(sp.expand(direct - eq.rhs)) != 0:
            raise ReductionError(f"reduced equation of {coords[i].name} does not match T M^-1 Q")
    return red
