"""Rigid-body modes and the relative coordinates that remove them.

Each coupling's deflection is a linear form J_c psi. The rigid-body rotation
modes are the null space of the stacked J: motions that deflect no mesh and
twist no shaft. The relative coordinates are one per coupling, the mesh
deflection (r_a psi_a - r_b psi_b) or the shaft twist scaled to a length
(r (psi_b - psi_a)), so q = T psi with T U = 0.
"""
from __future__ import annotations

import random
from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError
from ..model.drivetrain import ResolvedCoupling, ResolvedDrivetrain
from ..symbols import t


@dataclass(frozen=True)
class Coordinate:
    """One relative coordinate: its name, the coupling it measures and its definition in psi."""

    name: str
    coupling: ResolvedCoupling
    definition: sp.Expr  # scale * deflection, in psi_i(t)

    @property
    def kind(self) -> str:
        return self.coupling.kind

    @property
    def velocity_name(self) -> str:
        """The paper's v for x, v1 for x1; 'd<name>' otherwise."""
        return "v" + self.name[1:] if self.name.startswith("x") else "d" + self.name

    def of(self, time: sp.Symbol) -> sp.Expr:
        """The coordinate as a function, x(t) or x(tau)."""
        return sp.Function(self.name, real=True)(time)


def generic_rank(m: sp.Matrix, seed: int = 7) -> int:
    """Rank at random positive values of the symbols (the rank for almost all parameter values)."""
    rng = random.Random(seed)
    subs = {s: sp.Rational(rng.randint(11, 97), rng.randint(11, 97)) for s in sorted(m.free_symbols, key=str)}
    return m.xreplace(subs).rank()


def deflection_matrix(rd: ResolvedDrivetrain) -> sp.Matrix:
    return sp.Matrix([list(rc.row) for rc in rd.couplings])


def rigid_body_modes(rd: ResolvedDrivetrain) -> list[sp.Matrix]:
    """Basis of the motions that load no coupling (one per separately rotating sub-train)."""
    modes = []
    for v in deflection_matrix(rd).nullspace(simplify=True):
        denominators = [sp.fraction(sp.together(e))[1] for e in v]
        scale = sp.lcm_list(denominators) if denominators else 1
        modes.append(sp.simplify(v * scale))
    return modes


def relative_coordinates(rd: ResolvedDrivetrain) -> tuple[list[Coordinate], sp.Matrix]:
    """One coordinate per coupling, and the transform T (q = T psi)."""
    jac = deflection_matrix(rd)
    n_bodies, n_couplings = len(rd.bodies), len(rd.couplings)
    if generic_rank(jac) < n_couplings:
        # name the couplings that close a loop: those adding no independent deflection
        closing, kept = [], []
        for i, rc in enumerate(rd.couplings):
            if generic_rank(jac.extract(kept + [i], list(range(n_bodies)))) > len(kept):
                kept.append(i)
            else:
                closing.append(rc.name)
        raise ModelError(
            f"coupling(s) {', '.join(map(repr, closing))} close a kinematic loop with the couplings declared "
            "before them; loops (e.g. planetary sets) are not supported yet: remove the redundant coupling",
            rd.model.name,
        )
    single = n_couplings == 1
    coords, seen = [], {}
    for i, rc in enumerate(rd.couplings):
        name = rc.component.coordinate or ("x" if single else f"x{i + 1}")
        if not name.isidentifier() or name in ("t", "tau", "phi"):
            raise ModelError(f"coordinate name {name!r} is not a usable identifier", rc.name)
        if name in seen:
            raise ModelError(f"coordinate name {name!r} is used by {seen[name]!r} too; give each a distinct name", rc.name)
        seen[name] = rc.name
        definition = sp.Add(*(rc.scale * c * a for c, a in zip(rc.row, rd.angles)))
        coords.append(Coordinate(name, rc, definition))
    transform = sp.Matrix([[rc.scale * c for c in rc.row] for rc in rd.couplings])
    assert transform.shape == (n_couplings, n_bodies)
    return coords, transform


def angle_symbols(rd: ResolvedDrivetrain) -> tuple[list[sp.Symbol], list[sp.Symbol]]:
    """Plain symbols standing for psi_i(t) and psi_i'(t) during the algebra."""
    p = [sp.Symbol(f"_p{i}", real=True) for i in range(len(rd.bodies))]
    pd = [sp.Symbol(f"_pd{i}", real=True) for i in range(len(rd.bodies))]
    return p, pd


def to_symbols(expr: sp.Expr, rd: ResolvedDrivetrain, p, pd) -> sp.Expr:
    """Replace psi_i'(t) and psi_i(t) by plain symbols (velocities first)."""
    sub = {sp.Derivative(a, t): s for a, s in zip(rd.angles, pd)}
    expr = expr.xreplace(sub)
    return expr.xreplace(dict(zip(rd.angles, p)))
