"""Rigid-body modes and the relative coordinates that remove them.

Each coupling's deflection is a linear form C_c psi. The rigid-body rotation
modes are the null space of the stacked C: motions that deflect no mesh and
twist no shaft. The relative coordinates are the deflections of the couplings
that are independent of those declared before them (a spanning tree of the
couplings, in declaration order): the mesh deflection (r_a psi_a - r_b psi_b)
or the shaft twist scaled to a length (r (psi_b - psi_a)), so q = T psi with
T U = 0. In a chain or a tree every coupling is kept. A coupling whose
deflection depends on those kept before it closes a kinematic loop (a planetary
set: N planets give 2N meshes but N + 1 independent deflections); its
deflection is the combination J_c q of the coordinates with C_c = J_c T, solved
exactly, and its law acts on that combination.
"""
from __future__ import annotations

import random
from dataclasses import dataclass

import sympy as sp
from sympy.polys.constructor import construct_domain

from ..errors import ModelError
from ..model.linear_algebra import independent_rows, is_zero, nullspace, numeric_rank, pivot_columns, solve_rows
from ..model.resolved import ResolvedDrivetrain
from ..model.resolved_components import ResolvedCoupling
from ..model.symbols import t


@dataclass(frozen=True)
class Coordinate:
    """The deflection of one coupling: its name, the coupling, its definition in psi and, for a coupling that
    closes a loop, its combination of the relative coordinates (empty for a coordinate itself)."""

    name: str
    coupling: ResolvedCoupling
    definition: sp.Expr  # scale * deflection, in psi_i(t)
    combination: tuple[tuple["Coordinate", sp.Expr], ...] = ()  # (coordinate, coefficient) for a dependent one

    @property
    def kind(self) -> str:
        return self.coupling.kind

    @property
    def independent(self) -> bool:
        """True for a relative coordinate (a state), False for a deflection that closes a loop."""
        return not self.combination

    def contact(self, time: sp.Symbol) -> sp.Expr:
        """The deflection as a function of time: the coordinate x(t), or its combination of coordinates."""
        if self.independent:
            return self.of(time)
        return sp.Add(*(a * c.of(time) for c, a in self.combination))

    def in_states(self) -> tuple[sp.Expr, sp.Expr]:
        """The deflection and its rate in the state symbols (x1 + x2 - x3, v1 + v2 - v3)."""
        if self.independent:
            return sp.Symbol(self.name, real=True), sp.Symbol(self.velocity_name, real=True)
        return (sp.Add(*(a * sp.Symbol(c.name, real=True) for c, a in self.combination)),
                sp.Add(*(a * sp.Symbol(c.velocity_name, real=True) for c, a in self.combination)))

    @property
    def velocity_name(self) -> str:
        """The paper's v for x, v1 for x1; 'd<name>' otherwise."""
        return "v" + self.name[1:] if self.name.startswith("x") else "d" + self.name

    def of(self, time: sp.Symbol) -> sp.Expr:
        """The coordinate as a function, x(t) or x(tau)."""
        return sp.Function(self.name, real=True)(time)


def generic_rank(m: sp.Matrix, seed: int = 7) -> int:
    """Rank at random positive values of the symbols (the rank for almost all parameter values)."""
    return numeric_rank(m, seed)


def deflection_matrix(rd: ResolvedDrivetrain) -> sp.Matrix:
    return sp.Matrix([list(rc.row) for rc in rd.couplings])


def rigid_body_modes(rd: ResolvedDrivetrain) -> list[sp.Matrix]:
    """Basis of the motions that load no coupling (one per separately rotating sub-train)."""
    return nullspace(deflection_matrix(rd), f"{rd.model.name}: the rigid-body modes")


def relative_coordinates(rd: ResolvedDrivetrain) -> tuple[list[Coordinate], sp.Matrix]:
    """The relative coordinates (one per independent coupling) and the transform T (q = T psi), without the
    combinations of the couplings that close a loop (:func:`coupling_deflections` solves for those)."""
    coords, transform, _, _ = _coordinates(rd)
    return coords, transform


def _coordinates(rd: ResolvedDrivetrain) -> tuple[list[Coordinate], sp.Matrix, list[str], list[int]]:
    """The relative coordinates, T, every coupling's coordinate name and the indices of the couplings kept."""
    jac = deflection_matrix(rd)
    n_bodies, n_couplings = len(rd.dofs), len(rd.couplings)
    kept = independent_rows(jac)  # a spanning tree of the couplings, in declaration order
    single = n_couplings == 1
    names, seen = [], {}
    for i, rc in enumerate(rd.couplings):
        name = rc.coordinate_name if rc.kind == "bearing" or rc.coordinate_name else None
        name = name or rc.component.coordinate or ("x" if single else f"x{i + 1}")
        if not name.isidentifier() or name in ("t", "tau", "phi"):
            raise ModelError(f"coordinate name {name!r} is not a usable identifier", rc.name)
        if name in seen:
            raise ModelError(f"coordinate name {name!r} is used by {seen[name]!r} too; give each a distinct name", rc.name)
        seen[name] = rc.name
        names.append(name)
    transform = sp.Matrix([_scaled(rd.couplings[i]) for i in kept])
    assert transform.shape == (len(kept), n_bodies)
    return [Coordinate(names[i], rd.couplings[i], _definition(rd, i)) for i in kept], transform, names, kept


def _scaled(rc: ResolvedCoupling) -> list[sp.Expr]:
    return [rc.scale * c for c in rc.row]


def coupling_deflections(rd: ResolvedDrivetrain) -> tuple[list[Coordinate], sp.Matrix, list[Coordinate]]:
    """The relative coordinates, the transform T and every coupling's deflection (the coordinates themselves and
    the combinations of those that close a loop), in declaration order."""
    coords, transform, names, kept = _coordinates(rd)
    closing = [i for i in range(len(rd.couplings)) if i not in kept]
    solved = dict(zip(closing, combination_solver(transform).many(
        [sp.Matrix([_scaled(rd.couplings[i])]) for i in closing]))) if closing else {}
    deflections = []
    for i, rc in enumerate(rd.couplings):
        if i in kept:
            deflections.append(coords[kept.index(i)])
            continue
        combination = tuple((c, a) for c, a in zip(coords, solved[i]) if a != 0)
        deflections.append(Coordinate(names[i], rc, _definition(rd, i), combination))
    return coords, transform, deflections


def _definition(rd: ResolvedDrivetrain, i: int) -> sp.Expr:
    rc = rd.couplings[i]
    return sp.Add(*(rc.scale * c * a for c, a in zip(rc.row, rd.angles)))


def combination_solver(transform: sp.Matrix) -> "CombinationSolver":
    """The coefficients J with ``row = J T`` exactly, for rows in the span of T (:class:`CombinationSolver`)."""
    return CombinationSolver(transform)


class CombinationSolver:
    """``solver(row)``, or ``solver.many(rows)`` at the price of one (a fraction-free solve costs its elimination of
    T's pivot columns, whatever the number of rows): the coefficients J with ``row = J T``, solved on columns where T
    is invertible (found at generic values), then checked on every column."""

    def __init__(self, transform: sp.Matrix):
        self.transform = transform
        self.pivots = pivot_columns(transform)
        self.square = transform.extract(list(range(transform.rows)), list(self.pivots))

    def __call__(self, row: sp.Matrix) -> list[sp.Expr]:
        return self.many([row])[0]

    def many(self, rows: list[sp.Matrix]) -> list[list[sp.Expr]]:
        stacked = sp.Matrix.vstack(*rows)
        coefficients = solve_rows(self.square, stacked.extract(list(range(stacked.rows)), list(self.pivots)))
        out = []
        for k, row in enumerate(rows):
            found = coefficients.row(k).applyfunc(sp.factor)
            if not all(is_zero(e) for e in combination_residual(found, self.transform, row)):
                raise ModelError(f"the deflection {list(row)} is not a combination of the coordinates' (a bug)",
                                 "reduction")
            out.append(list(found))
        return out


def combination_residual(coefficients: sp.Matrix, transform: sp.Matrix, row: sp.Matrix) -> list[sp.Expr]:
    """``coefficients * transform - row``, computed in the field of rational functions of its symbols when they are
    plain symbols (exact, each entry cancelled: zero reads as zero), else as expressions (sines, cosines and radicals
    left for :func:`~gearsym.model.linear_algebra.is_zero`)."""
    domain, elements = construct_domain([*coefficients, *transform, *row], field=True)
    if domain.is_EX:
        return list(coefficients * transform - row)
    k, n = coefficients.cols, transform.cols
    c, m, r = elements[:k], elements[k:k + k * n], elements[k + k * n:]
    return [domain.to_sympy(sum((c[i] * m[i * n + j] for i in range(k)), domain.zero) - r[j]) for j in range(n)]


def generic_values(m: sp.Matrix, seed: int = 7) -> dict:
    """Random positive rationals for the symbols of ``m``; a symbol inside a sine or cosine (a pressure angle)
    gets a rational cosine and sine of one angle (from a Pythagorean triple), so that the values stay rational
    and cos^2 + sin^2 = 1 still holds."""
    rng = random.Random(seed)
    out = {s: sp.Rational(rng.randint(11, 97), rng.randint(11, 97)) for s in sorted(m.free_symbols, key=str)}
    angles = sorted({f.args[0] for f in m.atoms(sp.sin, sp.cos) if isinstance(f.args[0], sp.Symbol)}, key=str)
    for angle in angles:
        k = sp.Integer(rng.randint(2, 9))
        out[sp.cos(angle)] = (k**2 - 1) / (k**2 + 1)
        out[sp.sin(angle)] = 2 * k / (k**2 + 1)
    return out


def angle_symbols(rd: ResolvedDrivetrain) -> tuple[list[sp.Symbol], list[sp.Symbol]]:
    """Plain symbols standing for psi_i(t) and psi_i'(t) during the algebra."""
    p = [sp.Symbol(f"_p{i}", real=True) for i in range(len(rd.dofs))]
    pd = [sp.Symbol(f"_pd{i}", real=True) for i in range(len(rd.dofs))]
    return p, pd


def to_symbols(expr: sp.Expr, rd: ResolvedDrivetrain, p, pd) -> sp.Expr:
    """Replace psi_i'(t) and psi_i(t) by plain symbols (velocities first)."""
    sub = {sp.Derivative(a, t): s for a, s in zip(rd.angles, pd)}
    expr = expr.xreplace(sub)
    return expr.xreplace(dict(zip(rd.angles, p)))
