"""The Lagrangian of a resolved drivetrain and its equations of motion (the ``form_*`` half of the stage).

:class:`LagrangianForms` is a base of :class:`~gearsym.model.resolved.ResolvedDrivetrain`: from its bodies'
angles and its couplings' deflection rows it forms the kinetic and potential energies, the Rayleigh
dissipation, the generalized forces of the external torques, and Lagrange's equations, one per body.
"""
from __future__ import annotations

from functools import cached_property

import sympy as sp

from .backlash import G
from .partial import partial
from .symbols import t
from .resolved_components import ResolvedCoupling



class LagrangianForms:
    """Energies and equations of motion of a drivetrain whose ``bodies``, ``couplings`` and ``forcing`` are
    resolved (the attributes :class:`~gearsym.model.resolved.ResolvedDrivetrain` sets)."""

    @property
    def angles(self) -> list[sp.Expr]:
        """Every degree of freedom as a function of t: the bodies' angles, then their centres' translations."""
        return [rb.angle for rb in self.dofs]

    def deflection(self, rc: ResolvedCoupling) -> sp.Expr:
        """Mesh deflection r_a psi_a - r_b psi_b, or shaft twist psi_b - psi_a."""
        return sum((c * q for c, q in zip(rc.row, self.angles)), sp.S.Zero)

    def stiffness_at(self, rc: ResolvedCoupling) -> sp.Expr:
        """The mesh stiffness as a function of time, kZ(t), kept opaque so equations stay readable.

        Its definition is :meth:`stiffness_definition`; a shaft's stiffness is constant.
        """
        if rc.kind == "shaft":
            return rc.stiffness
        shared = sum(1 for other in self.couplings if other.kind == "mesh" and other.stiffness == rc.stiffness) > 1
        plain = isinstance(rc.stiffness, sp.Symbol) and not shared
        base = rc.stiffness.name if isinstance(rc.stiffness, sp.Symbol) else "kZ"
        return sp.Function(base if plain else f"{base}_{rc.name}", real=True)(t)

    def stiffness_definition(self, rc: ResolvedCoupling) -> sp.Expr:
        """kZ(t) = kZ * k(phi(t)) with the declared variation k and mesh phase phi; times (1 - loss(phi(t))) where
        shaft-order terms take stiffness away (a tooth fault)."""
        return rc.stiffness * rc.variation_at(rc.mesh_phase)

    def contact_of(self, rc: ResolvedCoupling) -> sp.Expr:
        """What the mesh's backlash acts on: the deflection, less the transmission error of shaft-order terms."""
        return self.deflection(rc) - rc.in_time(rc.error)

    def potential_of(self, rc: ResolvedCoupling) -> sp.Expr:
        d = self.deflection(rc)
        if rc.kind == "mesh":
            return self.stiffness_at(rc) * G(self.contact_of(rc), rc.backlash)
        return rc.stiffness * d**2 / 2

    def dissipation_of(self, rc: ResolvedCoupling) -> sp.Expr:
        return rc.damping * sp.diff(self.deflection(rc), t) ** 2 / 2

    @cached_property
    def kinetic_energy(self) -> sp.Expr:
        own = sum((rb.inertia * sp.diff(rb.angle, t) ** 2 / 2 for rb in self.dofs), sp.S.Zero)
        return own + self.frame_energy()

    @cached_property
    def potential_energy(self) -> sp.Expr:
        return sum((self.potential_of(rc) for rc in self.couplings), sp.S.Zero)

    @cached_property
    def dissipation(self) -> sp.Expr:
        return sum((self.dissipation_of(rc) for rc in self.couplings), sp.S.Zero)

    @cached_property
    def generalized_forces(self) -> list[sp.Expr]:
        """Q_i from the virtual work of the external torques, delta W = sum M_j delta psi_j."""
        q = [sp.S.Zero] * len(self.dofs)
        for f in self.forcing:
            q[f.body.index] += f.amplitude * f.time_function
        return q

    @cached_property
    def _symbols(self) -> tuple[dict, dict]:
        """Plain symbols for every psi_i(t), psi_i'(t) and psi_i''(t) (keys in that order), and the way back.
        Lagrange's derivatives are taken with respect to them: SymPy differentiates by a function of t through a
        dummy it substitutes into the whole expression at every call (seconds for a drivetrain on bearings)."""
        to, back = {}, {}
        for i, q in enumerate(self.angles):
            p, pd, pdd = (sp.Dummy(f"{kind}{i}", real=True) for kind in ("q", "qd", "qdd"))
            to[sp.Derivative(q, (t, 2))], to[sp.Derivative(q, t)], to[q] = pdd, pd, p
            back.update({p: q, pd: sp.Derivative(q, t), pdd: sp.Derivative(q, (t, 2))})
        return to, back

    def _in_symbols(self, expr: sp.Expr) -> sp.Expr:
        to, _ = self._symbols  # (derivatives first: psi'(t) holds psi(t))
        return expr.xreplace({k: v for k, v in to.items() if isinstance(k, sp.Derivative)}).xreplace(
            {q: to[q] for q in self.angles})

    def lagrange_lhs(self, lagrangian: sp.Expr, dissipation: sp.Expr) -> list[sp.Expr]:
        """d/dt dL/dpsi' - dL/dpsi + dR/dpsi' for each body; d/dt by the chain rule over the positions, the rates
        and t itself."""
        to, back = self._symbols
        positions = [to[q] for q in self.angles]
        rates = [to[sp.Derivative(q, t)] for q in self.angles]
        accelerations = [to[sp.Derivative(q, (t, 2))] for q in self.angles]
        terms_l = sp.Add.make_args(self._in_symbols(sp.expand(lagrangian, deep=False, mul=False)))
        terms_r = sp.Add.make_args(self._in_symbols(dissipation))
        out = []
        for q, qd in zip(positions, rates):
            # (only the terms that hold q: the others differentiate to zero, and a drivetrain on bearings has many)
            lag = sp.Add(*(e for e in terms_l if e.has(q) or e.has(qd)))
            dis = sp.Add(*(e for e in terms_r if e.has(q) or e.has(qd)))
            momentum = partial(lag, qd)
            rate_of_momentum = partial(momentum, t) + sp.Add(*(
                partial(momentum, x) * xd for x, xd in zip(positions + rates, rates + accelerations) if momentum.has(x)))
            out.append((rate_of_momentum - partial(lag, q) + partial(dis, qd)).xreplace(back))
        return out

    @cached_property
    def lagrange_rows(self) -> list[sp.Expr]:
        """The left-hand sides of Lagrange's equations as the derivatives give them (what a check evaluates)."""
        return self.lagrange_lhs(self.kinetic_energy - self.potential_energy, self.dissipation)

    @cached_property
    def equations_of_motion(self) -> list[sp.Eq]:
        """Lagrange's equations, each term's common factors taken out (for reading)."""
        lhs = [sp.Add(*(sp.factor_terms(term) for term in sp.Add.make_args(row))) for row in self.lagrange_rows]
        return [sp.Eq(l, r, evaluate=False) for l, r in zip(lhs, self.generalized_forces)]

    @cached_property
    def frame_forces(self) -> list[sp.Expr]:
        """Generalized forces of the turning frame (Coriolis and centripetal): -(d/dt dT_f/dq' - dT_f/dq)."""
        energy = self.frame_energy()
        if energy == 0:
            return [sp.S.Zero] * len(self.dofs)
        return [-sp.expand(e) for e in self.lagrange_lhs(energy, sp.S.Zero)]

    def coupling_forces(self, rc: ResolvedCoupling) -> list[sp.Expr]:
        """Generalized forces of one coupling alone: -(dV_c/dpsi + dR_c/dpsi')."""
        return [-e for e in self.lagrange_lhs(-self.potential_of(rc), self.dissipation_of(rc))]

    @cached_property
    def mass_matrix(self) -> sp.Matrix:
        """d^2 T / dpsi_i' dpsi_j': the coefficients of the accelerations in Lagrange's equations (neither the
        potential nor the dissipation holds one)."""
        to, back = self._symbols
        rates = [to[sp.Derivative(q, t)] for q in self.angles]
        energy = self._in_symbols(self.kinetic_energy)
        n = len(rates)
        out = sp.zeros(n, n)
        for i, a in enumerate(rates):
            first = partial(energy, a)
            for j, b in enumerate(rates):
                if first.has(b):  # (most pairs of a drivetrain's rates share no term)
                    out[i, j] = partial(first, b).xreplace(back)
        return out
