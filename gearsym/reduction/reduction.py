"""Reduction of the equations of motion to relative coordinates.

With M the (diagonal) inertia matrix, Lagrange gives M psi'' = sum_c Q_c + Q_ext.
For q = T psi the reduced equations are q'' = T M^-1 (sum_c Q_c + Q_ext), and
they close in q because each Q_c depends on psi only through its coupling's
deflection, which T determines (a coupling that closes a loop: through the
combination J_c q of the coordinates). We substitute psi = W [q; a] (a: the rigid
coordinates), check that every a drops out, and factor each coupling's
contribution to row i as ``-factor_ic * law_c(q)``; those factors are what the
paper calls r1^2/I1 + r2^2/I2, 1/I2, ... and become the coefficient groups.
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass, field, replace
from functools import cached_property

import mpmath
import sympy as sp
from sympy.polys.constructor import construct_domain
from sympy.polys.matrices import DomainMatrix

from ..model.backlash import g
from ..model.evaluation import PointValues, inventory
from ..model.replacing import Replacer
from ..errors import GearsymError
from ..model.drivetrain import Drivetrain
from ..model.linear_algebra import fraction_forms, numeric_rank, pivot_columns, simplified
from ..model.resolved import ResolvedDrivetrain
from ..model.resolved_components import ResolvedCoupling, ResolvedForcing
from ..model.symbols import t
from .coordinates import Coordinate, combination_solver, coupling_deflections, generic_rank, rigid_body_modes


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
    deflections: list[Coordinate] = field(default_factory=list)  # every coupling's, in declaration order
    coupling_terms: list[CouplingTerm] = field(default_factory=list)
    forcing_terms: list[ForcingTerm] = field(default_factory=list)

    def law(self, rc: ResolvedCoupling, time: sp.Symbol = t) -> sp.Expr:
        """The coupling's force written in its deflection x (its own coordinate, or the combination of
        coordinates of a coupling that closes a loop): ``kZ(t) g(x, eta) + cZ x'`` for a mesh,
        ``kS x + cS x'`` for a shaft."""
        x = self.deflection_of(rc).contact(time)
        xd = sp.diff(x, time)
        if rc.kind == "mesh":
            error = rc.in_time(rc.error).subs(t, time)  # a transmission error of shaft-order terms
            return self.resolved.stiffness_at(rc) * g(x - error, rc.backlash) + rc.damping * xd
        return rc.stiffness * x + rc.damping * xd

    def coordinate_of(self, rc: ResolvedCoupling) -> Coordinate:
        return next(c for c in self.coordinates if c.coupling is rc)

    def deflection_of(self, rc: ResolvedCoupling) -> Coordinate:
        return next(c for c in self.deflections if c.coupling is rc)

    @property
    def dependent(self) -> list[Coordinate]:
        """The deflections of the couplings that close a kinematic loop (combinations of the coordinates)."""
        return [d for d in self.deflections if not d.independent]

    #: per row, the turning frame's forces (Coriolis, centripetal) in the coordinates x_k(t), with the carrier's
    #: speed Omega_c: sum_k (a_k Omega_c x_k' + b_k Omega_c^2 x_k); empty without a turning frame
    frame_rows: list[sp.Expr] = field(default_factory=list)

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
            if self.frame_rows:
                rhs += self.frame_rows[i]
            out.append(sp.Eq(sp.diff(c.of(t), t, 2), rhs, evaluate=False))
        return out

    @cached_property
    def rigid_body_equations(self) -> list[sp.Eq]:
        """u^T M psi'' = u^T Q_ext for each rigid mode u: the couplings drop out."""
        rd = self.resolved
        out = []
        for u in self.rigid_modes:
            lhs = sp.Add(*(u[i] * rb.inertia * sp.diff(rb.angle, t, 2) for i, rb in enumerate(rd.dofs)))
            rhs = sp.Add(*(u[i] * q for i, q in enumerate(rd.generalized_forces)))
            out.append(sp.Eq(lhs, rhs, evaluate=False))
        return out


def _is_zero(expr: sp.Expr) -> bool:
    return sp.expand(expr) == 0 or sp.simplify(expr) == 0


def reduce_drivetrain(model: Drivetrain, numbers: bool = True) -> Reduction:
    """Derive the reduced equations of ``model`` in relative coordinates; ``numbers=False`` leaves the geometry's
    symbols in (the nondimensional form puts them back at its end, :func:`with_geometry`)."""
    rd = model.resolved
    coords, T, deflections = coupling_deflections(rd)
    modes = rigid_body_modes(rd)
    red = Reduction(model, rd, coords, T, modes, deflections)
    n = len(rd.dofs)
    M = rd.mass_matrix
    if M != sp.diag(*[rb.inertia for rb in rd.dofs]):
        raise ReductionError(f"unexpected inertia matrix {M}; bodies must be uncoupled rotors")
    if T.rows + len(modes) != n:
        raise ReductionError(f"{len(coords)} coordinates and {len(modes)} rigid modes do not span {n} angles")
    TMinv = T * M.inv()

    for rc in rd.couplings:
        for u in modes:
            if not _is_zero(sum(c * x for c, x in zip(rc.row, u))):
                raise ReductionError(f"{rc.name}: its forces do work in a rigid-body rotation")
        # Lagrange gives each coupling the generalized forces -C_c^T law_c(C_c psi) (checked below at random states),
        # so row i of T M^-1 Q_c = -(T M^-1 C_c^T)_i law_c, and the law is in the coordinates since C_c = J_c T
        for i in range(len(coords)):
            factor = sp.factor(sp.Add(*(TMinv[i, j] * rc.row[j] for j in range(n))) / rc.scale)
            if factor != 0:
                red.coupling_terms.append(CouplingTerm(i, rc, factor))
    frame = sp.Matrix(rd.frame_forces)
    if frame != sp.zeros(n, 1):
        red.frame_rows = _frame_rows(red, TMinv, frame)

    # external torques: row i gets (T M^-1)_{i, body} * torque
    for f in rd.forcing:
        for i in range(len(coords)):
            coefficient = sp.factor(TMinv[i, f.body.index] * f.amplitude)
            if coefficient != 0:
                red.forcing_terms.append(ForcingTerm(i, f, coefficient))

    # final check: Lagrange's equations are the couplings' laws along their rows, and the assembled equations give
    # their accelerations, at random states
    check_against_lagrange(red)
    return with_geometry(red) if numbers and rd.geometry else red


def with_geometry(red: Reduction) -> Reduction:
    """The reduction with the geometry's symbols (sines and cosines of pressure angles, radicals of planet
    positions: :meth:`ResolvedDrivetrain._with_geometry_symbols`) replaced by what they stand for, in normal form
    modulo their relations; a rank the numbers lower is an error (the generic algebra would not hold)."""
    rd = red.resolved
    geometry = rd.geometry
    generic = generic_rank(red.transform)
    if numeric_rank(red.transform.xreplace(geometry)) != generic:
        raise ReductionError(f"{red.drivetrain.name}: the geometry's numbers make the coordinates dependent")

    sub = Replacer(geometry)  # (numbers in: evaluated as they are used; the coefficients' normal form is for display only)

    coordinates, old_to_new = [], {}
    for c in red.coordinates:
        new = replace(c, definition=sub(c.definition))
        old_to_new[id(c)] = new
        coordinates.append(new)
    deflections = []
    for d in red.deflections:
        if d.independent:
            deflections.append(old_to_new[id(d)])
        else:
            deflections.append(replace(d, definition=sub(d.definition),
                                       combination=tuple((old_to_new[id(c)], sub(a)) for c, a in d.combination)))
    return Reduction(
        red.drivetrain, rd, coordinates, red.transform.applyfunc(sub), [u.applyfunc(sub) for u in red.rigid_modes],
        deflections,
        [CouplingTerm(ct.row, ct.coupling, sub(ct.factor)) for ct in red.coupling_terms],
        [ForcingTerm(ft.row, ft.source, sub(ft.coefficient)) for ft in red.forcing_terms],
        [sub(f) for f in red.frame_rows])


def sub_frame(expr: sp.Expr, geometry) -> sp.Expr:
    """``expr`` with the geometry's numbers, term by term: the coefficient of each function, derivative or backlash
    law in normal form."""
    if not expr.free_symbols & set(geometry):
        return expr
    from sympy.core.function import AppliedUndef

    collected: dict[sp.Expr, sp.Expr] = {}
    for term in sp.Add.make_args(sp.expand(expr)):
        dependent = [f for f in sp.Mul.make_args(term) if f.has(AppliedUndef) or f.has(sp.Derivative)]
        key = sp.Mul(*dependent)
        collected[key] = collected.get(key, sp.S.Zero) + term / key
    return sp.Add(*(simplified(c.xreplace(geometry)) * k for k, c in collected.items()))


def _frame_rows(red: Reduction, weights_rows: sp.Matrix, forces: sp.Matrix) -> list[sp.Expr]:
    """The frame's forces of each row, T M^-1 Q_f (``weights_rows`` T M^-1, ``forces`` Q_f), with every translation
    written in the coordinates (its combination of them; for a translation a rigid-body mode moves too, a planet's
    tangential one, the motion M-orthogonal to the rigid-body modes: the rigid coordinates are the nominal rotation
    the frame turns with)."""
    rd = red.resolved
    moving = sorted({i for f in forces for i, d in enumerate(rd.dofs) if d.motion != "rotation"
                     and f.has(d.angle)})
    weights_rows = [list(weights_rows.row(k)) for k in range(weights_rows.rows)]
    weights_of: dict[int, list[sp.Expr]] = {}
    held = [i for i in moving if any(u[i] != 0 for u in red.rigid_modes)]  # (a rigid-body mode moves it too)
    itself = {}  # dof -> the coordinate that is it (a bearing to the ground: x_sun = X_sun)
    for k in range(red.transform.rows):
        nonzero = [j for j, e in enumerate(red.transform.row(k)) if e != 0]
        if len(nonzero) == 1 and red.transform[k, nonzero[0]] == 1:
            itself[nonzero[0]] = k
    solved = [i for i in moving if i not in held and i not in itself]
    for i in moving:
        if i in itself and i not in held:
            weights_of[i] = [sp.S.One if k == itself[i] else sp.S.Zero for k in range(len(red.coordinates))]
    if solved:  # (one solve for all of them)
        targets = [sp.Matrix([[1 if j == i else 0 for j in range(red.transform.cols)]]) for i in solved]
        weights_of.update(zip(solved, combination_solver(red.transform).many(targets)))
    if held:
        weights_of.update(zip(held, translations_in_coordinates(red, held)))
    rates, positions = {}, {}
    for i in moving:  # (the weights are constants: the rate is the same combination of the coordinates' rates)
        pairs = [(w, c) for w, c in zip(weights_of[i], red.coordinates) if w != 0]
        rates[sp.Derivative(rd.dofs[i].angle, t)] = sp.Add(*(w * sp.Derivative(c.of(t), t) for w, c in pairs))
        positions[rd.dofs[i].angle] = sp.Add(*(w * c.of(t) for w, c in pairs))
    # Each row is kept as T M^-1 times the frame's force on each body, the body's translation a combination of the
    # coordinates (its weights over the rigid-body modes' Gram determinant, each denominator in its pieces): expanded,
    # the combinations' rational weights multiply out into every row (Lin & Parker's set: 10^5 characters a row, a C
    # file of megabytes gcc does not finish); kept, each combination is one subexpression the generated code computes
    # once.
    in_coordinates = Replacer({**rates, **positions})  # (a rate first: the whole derivative, not its function)
    forces = [in_coordinates(sp.factor_terms(force)) if force != 0 else force for force in forces]
    return [sp.Add(*(weight * force for weight, force in zip(weights, forces) if weight != 0 and force != 0))
            for weights in weights_rows]


def translations_in_coordinates(red: Reduction, indices: list[int]) -> list[list[sp.Expr]]:
    """For each degree of freedom of ``indices``, the weights w with dof = w . q for the motion M-orthogonal to the
    rigid-body modes (T psi = q, U^T M psi = 0): with R a right inverse of T (the inverse of T's pivot columns, in
    their rows), W = (I - U (U^T M U)^-1 U^T M) R; only the rows of R the result needs are solved for.

    Exact and without expression trees: the solve is fraction-free in the polynomial ring of the symbols (R = N / d,
    one denominator), the Gram matrix's inverse its adjugate over its determinant, so every weight is a polynomial
    over d det(U^T M U) until one cancellation at the end; the weights are written with those two as their
    denominators' pieces (:func:`~gearsym.model.linear_algebra.fraction_forms`)."""
    rd = red.resolved
    transform = red.transform
    pivots = pivot_columns(transform)
    square = transform.extract(list(range(transform.rows)), pivots)
    modes = sp.Matrix.hstack(*red.rigid_modes)
    masses = [d.inertia for d in rd.dofs]
    needed = sorted(set(indices) | {j for j in range(len(masses)) if any(modes[j, m] != 0 for m in range(modes.cols))})
    needed = [j for j in needed if j in pivots]
    targets = sp.zeros(len(needed), transform.rows)
    for k, j in enumerate(needed):
        targets[k, pivots.index(j)] = 1
    groups = [list(square), list(targets), list(modes), masses]
    ring, elements = construct_domain([e for group in groups for e in group])
    parts, at = [], 0
    for group in groups:
        parts.append(elements[at:at + len(group)])
        at += len(group)
    square_elements, target_elements, mode_elements, mass = parts
    width, cols = transform.rows, modes.cols
    square_dm = DomainMatrix([square_elements[r * width:(r + 1) * width] for r in range(width)], (width, width), ring)
    targets_dm = DomainMatrix([target_elements[r * width:(r + 1) * width] for r in range(len(needed))],
                              (len(needed), width), ring)
    numerator, denominator = square_dm.transpose().solve_den(targets_dm.transpose()) if needed else (None, ring.one)
    right = {j: row for j, row in zip(needed, numerator.transpose().to_list())} if needed else {}
    u = [mode_elements[j * cols:(j + 1) * cols] for j in range(modes.rows)]  # (row j: degree of freedom j in each mode)
    zero = [ring.zero] * width
    gram = DomainMatrix([[sum((uj[a] * mj * uj[b] for uj, mj in zip(u, mass)), ring.zero) for b in range(cols)]
                         for a in range(cols)], (cols, cols), ring)
    adjugate, determinant = gram.adj_det()
    adjugate = adjugate.to_list()
    weighted = [[sum((uj[m] * mj * right.get(j, zero)[e] for j, (uj, mj) in enumerate(zip(u, mass)) if uj[m]),
                     ring.zero) for e in range(width)] for m in range(cols)]
    field = ring.get_field()
    over = field.convert_from(denominator * determinant, ring)
    out = []
    for i in indices:
        w = [x * determinant for x in right.get(i, zero)]
        for a in range(cols):
            for b in range(cols):
                if u[i][a] and adjugate[a][b]:
                    w = [x - u[i][a] * adjugate[a][b] * y for x, y in zip(w, weighted[b])]
        out.append(fraction_forms([field.convert_from(x, ring) / over for x in w], field,
                                  [denominator, determinant] if field.is_FractionField else []))
    return out


def _law_in_angles(rd: ResolvedDrivetrain, rc: ResolvedCoupling) -> sp.Expr:
    """The coupling's law in its deflection C_c psi (a shaft's twist unscaled): what Lagrange gives."""
    d = rd.deflection(rc)
    if rc.kind == "mesh":
        return rd.stiffness_at(rc) * g(rd.contact_of(rc), rc.backlash) + rc.damping * sp.diff(d, t)
    return rc.stiffness * d + rc.damping * sp.diff(d, t)


def _without_rigid_motion(red: Reduction, vector: list, at: PointValues) -> list:
    """``vector`` less its M-orthogonal projection on the rigid-body modes (numbers, at the point ``at``)."""
    rd = red.resolved
    with mpmath.workdps(at.digits):
        m = mpmath.diag([at(d.inertia) for d in rd.dofs])
        v = mpmath.matrix(vector)
        u = mpmath.matrix([[at(e) for e in mode] for mode in red.rigid_modes]).T
        return list(v - u * mpmath.inverse(u.T * m * u) * (u.T * m * v))


#: random states at which the reduced equations are checked against Lagrange's, and the agreement asked
CHECK_POINTS, CHECK_DIGITS = 3, 30
#: digits of a model's floating-point numbers (0.1 in a model file is a double) the check does not ask to agree:
#: the two sides round such numbers' products in different orders (a transmission error 0.1 cos(...) / 4 is
#: 0.025 cos(...) on one side and 0.1/4 on the other), so they agree to the double's digits, not to 30
FLOAT_SLACK = 4
#: digits the check computes with beyond CHECK_DIGITS (sums of many terms cancel some)
GUARD_DIGITS = 20


def _check_tolerance(bits: int | None) -> mpmath.mpf:
    """The relative disagreement the check allows: 10^(8 - CHECK_DIGITS) between exact numbers; with floating-point
    numbers in the equations (a number a model file gives as a float: ``bits``, their least precision), what their
    precision holds less FLOAT_SLACK digits (1e-11 for doubles: still far below any term that is wrong)."""
    digits = CHECK_DIGITS - 8 if bits is None else min(CHECK_DIGITS - 8, int(bits * math.log10(2)) - FLOAT_SLACK)
    return mpmath.mpf(10) ** -digits


def _agree(got, expected, tolerance) -> bool:
    return abs(got - expected) <= tolerance * (1 + abs(expected))


def check_against_lagrange(red: Reduction) -> None:
    """At random angles, rates, times and parameter values (backlash contacts on both flanks and in the gap), two
    checks against Lagrange's equations of the unreduced drivetrain (its Lagrangian differentiated, nothing of the
    reduction used): their forces are the couplings' laws along their deflection rows, the frame's forces and the
    external torques, every degree of freedom; and the reduced right-hand sides are T psi'' with psi'' = M^-1 Q,
    every coordinate, every loop-closing combination and every rigid coordinate eliminated. Numbers to
    CHECK_DIGITS digits, each subexpression computed once (:class:`~gearsym.model.evaluation.PointValues`); a
    disagreement is a :class:`ReductionError` that names the row, and the coupling when one is to blame."""
    rd = red.resolved
    rng = random.Random(11)
    n = len(rd.dofs)
    lagrange = rd.lagrange_rows
    external = list(rd.generalized_forces)
    frame = list(rd.frame_forces)
    laws = [_law_in_angles(rd, rc) for rc in rd.couplings]
    reduced = [eq.rhs for eq in red.equations]
    symbols, functions, bits = inventory((*lagrange, *external, *frame, *laws, *reduced))
    symbols = (symbols - {t} - set(rd.geometry)).union(*(e.free_symbols for e in rd.geometry.values()))
    functions = {f for f in functions if f.args == (t,)} - set(rd.angles) - {c.of(t) for c in red.coordinates}
    tolerance = _check_tolerance(bits)
    digits = CHECK_DIGITS + GUARD_DIGITS
    for _ in range(CHECK_POINTS):
        values = {s: sp.Rational(rng.randint(5, 40), rng.randint(5, 20)) for s in sorted(symbols, key=str)}
        values |= {f: sp.Rational(rng.randint(5, 40), 10) for f in sorted(functions, key=str)}
        values[t] = sp.Rational(rng.randint(0, 100), 7)
        values |= {s: e.xreplace(values) for s, e in rd.geometry.items()}  # (the geometry at its numbers)
        psi = [sp.Rational(rng.randint(-60, 60), 20) for _ in range(n)]
        rate = [sp.Rational(rng.randint(-60, 60), 20) for _ in range(n)]
        at = PointValues(values, digits)
        if red.frame_rows and red.rigid_modes:  # the frame turns with the rigid coordinates: none of their motion
            psi, rate = (_without_rigid_motion(red, v, at) for v in (psi, rate))
        state = {**dict(zip(rd.angles, psi)), **{sp.Derivative(a, t): r for a, r in zip(rd.angles, rate)},
                 **{sp.Derivative(a, (t, 2)): 0 for a in rd.angles}}
        at = PointValues({**values, **state}, digits)
        with mpmath.workdps(digits):
            forces = [at(q) - at(lhs) for q, lhs in zip(external, lagrange)]  # (Lagrange's, accelerations at 0)
            law = [at(e) for e in laws]
            for i in range(n):
                assembled = at(external[i]) + at(frame[i]) - mpmath.fsum(
                    at(rc.row[i]) * law[c] for c, rc in enumerate(rd.couplings) if rc.row[i] != 0)
                if not _agree(assembled, forces[i], tolerance):
                    raise ReductionError(_which_coupling(rd, i, at, law, tolerance)
                                         or f"coupling forces do not add up to the equation of motion of "
                                            f"{rd.dofs[i].label} ({assembled} instead of {forces[i]})")
            accel = [f / at(rb.inertia) for f, rb in zip(forces, rd.dofs)]
            transform = [[at(e) for e in red.transform.row(k)] for k in range(red.transform.rows)]
            q = [mpmath.fsum(a * p for a, p in zip(row, psi)) for row in transform]
            qd = [mpmath.fsum(a * r for a, r in zip(row, rate)) for row in transform]
            coordinates = {**{c.of(t): q[k] for k, c in enumerate(red.coordinates)},
                           **{sp.Derivative(c.of(t), t): qd[k] for k, c in enumerate(red.coordinates)}}
            at = PointValues({**values, **coordinates}, digits)
            for k, (c, rhs) in enumerate(zip(red.coordinates, reduced)):
                expected = mpmath.fsum(a * x for a, x in zip(transform[k], accel))
                got = at(rhs)
                if not _agree(got, expected, tolerance):
                    raise ReductionError(f"reduced equation of {c.name} does not give Lagrange's acceleration "
                                         f"({mpmath.nstr(got, 15)} instead of {mpmath.nstr(expected, 15)})")


def _which_coupling(rd: ResolvedDrivetrain, i: int, at: PointValues, law: list, tolerance) -> str | None:
    """The first coupling whose own generalized force on degree of freedom ``i`` (Lagrange's, of its potential and
    dissipation alone) is not its law along its row, named; None if each is (derived only when the sum disagrees)."""
    for c, rc in enumerate(rd.couplings):
        lagrange = at(rd.coupling_forces(rc)[i])
        if not _agree(lagrange, -at(rc.row[i]) * law[c], tolerance):
            return f"{rc.name}: its generalized forces are not its law along its deflection row ({rd.dofs[i].label})"
    return None
