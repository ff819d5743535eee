"""Exact linear algebra on the kinematics' matrices, fast enough for gears on bearings.

A drivetrain's deflection rows are linear forms in its degrees of freedom whose coefficients are radii and, for
gears that translate, the sines and cosines of pressure angles and planet positions (``sqrt(3)/2``, nested
radicals for five planets). SymPy's own row reduction simplifies every such entry at every step and takes
minutes on Lin & Parker's 18 degrees of freedom. Here each sine and cosine of a parameter and each radical
becomes a generator of a field of rational functions (SymPy's ``DomainMatrix``, sparse polynomials), the
algebra runs there, and the results are written back in normal form modulo the generators' relations
(``cos^2 + sin^2 = 1``, ``sqrt(3)^2 = 3``: a Groebner basis), so that what is zero reads as zero. The algebra
over independent generators is exact; the relations can only lower a rank, so every rank is also checked at the
actual numbers (40 digits, random rational values for the parameters) and a disagreement is an error.
"""
from __future__ import annotations

import random
from functools import cached_property

import mpmath
import numpy as np
import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..errors import GearsymError

#: digits of the numeric rank check, and the relative size below which a pivot counts as zero
DIGITS, TINY = 40, mpmath.mpf(10) ** -28


class Generators:
    """The sines and cosines of parameters and the radicals of some expressions, each with a stand-in symbol,
    and the relations between the stand-ins."""

    def __init__(self, exprs):
        self.of: dict[sp.Expr, sp.Dummy] = {}
        for e in exprs:
            self._walk(sp.sympify(e, strict=True))
        self.back = {d: e for e, d in self.of.items()}

    def _walk(self, e: sp.Expr) -> None:
        if isinstance(e, (sp.sin, sp.cos)) and (e.args[0].free_symbols or not (e.args[0] / sp.pi).is_Rational):
            angle = e.args[0]
            self.of.setdefault(sp.sin(angle), sp.Dummy("g"))
            self.of.setdefault(sp.cos(angle), sp.Dummy("g"))
            return
        if isinstance(e, sp.Pow) and e.base.is_number and not e.exp.is_Integer:
            self._walk(e.base)
            self.of.setdefault(e, sp.Dummy("g"))
            return
        if e.is_number and not e.is_Rational and not e.args:
            raise GearsymError(f"the kinematics hold the number {e}, which exact algebra cannot take; declare angles "
                               "as multiples of pi or as parameters")
        for a in e.args:
            self._walk(a)

    def to(self, e):
        return e.xreplace(self.of) if self.of else e

    def from_(self, e):
        return e.xreplace(self.back) if self.of else e

    @cached_property
    def relations(self) -> list[tuple[sp.Dummy, sp.Expr]]:
        """(generator, relation) with the generator's highest power leading, outer radicals before the inner
        ones their relation holds (a triangular set: reducing in this order gives a normal form)."""
        out = []
        for e, g in self.of.items():
            if isinstance(e, sp.sin):
                out.append((g, g**2 + self.of[sp.cos(e.args[0])] ** 2 - 1))
            elif isinstance(e, sp.Pow):
                p, q = sp.fraction(e.exp)
                out.append((g, g**q - self.to(e.base) ** p))
        return sorted(out, key=lambda pair: pair[0].dummy_index, reverse=True)

    def reduce(self, poly: sp.Expr) -> sp.Expr:
        for g, relation in self.relations:
            if poly.has(g):
                poly = sp.rem(poly, relation, g)
        return sp.expand(poly)

    def normal(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` with its generators' relations applied: numerator and denominator reduced."""
        expr = self.to(sp.sympify(expr, strict=True))
        if not self.relations or not (expr.free_symbols & set(self.back)):
            return self.from_(sp.cancel(expr))
        num, den = sp.fraction(sp.cancel(sp.together(expr)))
        num, den = self.reduce(num), self.reduce(den)
        if den == 0:
            raise GearsymError(f"a pivot of the kinematics vanishes at the geometry's actual numbers: {expr}")
        return self.from_(sp.cancel(num / den))


def _at_generic_values(m: sp.Matrix, seed: int) -> list[list[mpmath.mpf]]:
    """``m`` at random rational values of its parameters and the actual values of its numbers (DIGITS digits)."""
    rng = random.Random(seed)
    values = {s: sp.Rational(rng.randint(11, 97), rng.randint(11, 97)) for s in sorted(m.free_symbols, key=str)}
    with mpmath.workdps(DIGITS):
        return [[mpmath.mpf(sp.N(e.xreplace(values), DIGITS)) if e != 0 else mpmath.mpf(0) for e in m.row(i)]
                for i in range(m.rows)]


def numeric_rank(m: sp.Matrix, seed: int = 7) -> int:
    """The rank of ``m`` at random rational values of its parameters and the actual values of its numbers
    (Gaussian elimination with partial pivoting, 40 digits)."""
    return len(independent_rows(m, seed))


def independent_rows(m: sp.Matrix, seed: int = 7, base: int | None = None) -> list[int]:
    """The rows of ``m``, in order, that are independent of the rows before them, at random rational values of its
    parameters and the actual values of its numbers (40 digits; each row reduced by those kept, pivoting on its
    largest entry). ``m`` is evaluated once: a rank asked row by row of the same matrix costs one elimination.
    With ``base``, the rows from ``base`` on are each reduced by the first ``base`` rows' only (not by each other)."""
    rows = _at_generic_values(m, seed)
    with mpmath.workdps(DIGITS):
        scale = max((abs(x) for r in rows for x in r), default=mpmath.mpf(0))
        kept: list[int] = []
        basis: list[tuple[int, list]] = []
        for i, row in enumerate(rows):
            for pivot, b in basis:
                f = row[pivot] / b[pivot]
                if f != 0:
                    row = [a - f * c for a, c in zip(row, b)]
            pivot = max(range(len(row)), key=lambda k: abs(row[k]), default=None)
            if pivot is not None and abs(row[pivot]) > TINY * scale:
                if base is None or i < base:
                    basis.append((pivot, row))
                kept.append(i)
        return kept


def outside_span(m: sp.Matrix, rows: list[sp.Matrix], seed: int = 7) -> list[bool]:
    """For each of ``rows``, whether it is independent of the rows of ``m`` at generic values (as
    :func:`independent_rows`; ``m`` evaluated once for all of them)."""
    both = independent_rows(sp.Matrix.vstack(m, *rows), seed, base=m.rows)
    return [m.rows + k in both for k in range(len(rows))]


def pivot_columns(m: sp.Matrix) -> list[int]:
    """The pivot columns of ``m``'s row echelon form at generic values (the first independent columns)."""
    return independent_rows(m.T)[:m.rows]


def nullspace(m: sp.Matrix, what: str) -> list[sp.Matrix]:
    """A basis of the null space of ``m``, exact, each vector scaled to polynomial entries without common factor
    (fraction-free elimination in the polynomial ring: no rational-function gcd at every step)."""
    if m.rows == 0:
        return [sp.eye(m.cols)[:, j] for j in range(m.cols)]
    gens = Generators(m)
    dm = DomainMatrix.from_Matrix(gens.to(m))
    basis = dm.nullspace()
    if not gens.of and basis.domain.is_PolynomialRing:
        return _checked_nullspace(m, what, [_without_common_factor(row, basis.domain) for row in basis.to_list()])
    basis = basis.to_Matrix()
    vectors = []
    for i in range(basis.rows):
        entries = [sp.cancel(gens.normal(gens.from_(e))) if gens.of else sp.cancel(e) for e in basis.row(i)]
        denominators = [sp.fraction(sp.together(e))[1] for e in entries]
        scale = sp.lcm_list(denominators) if denominators else 1
        entries = [sp.expand(e * scale) for e in entries]
        common = sp.gcd_list([e for e in entries if e != 0])
        vectors.append(sp.Matrix([sp.factor(sp.cancel(e / common)) for e in entries]))
    return _checked_nullspace(m, what, vectors)


def _without_common_factor(row: list, ring) -> sp.Matrix:
    """A null vector of polynomials (``ring``'s elements) divided by their gcd (SymPy's, as for expressions), each
    entry factored: the division exact in the ring (expressions' cancel takes their gcd again, term by term)."""
    scale = sp.lcm_list([sp.Integer(int(e.clear_denoms()[0])) for e in row if e] or [1])  # (rational coefficients)
    row = [e * ring.convert(scale) for e in row]
    common = sp.gcd_list([ring.to_sympy(e) for e in row if e])
    divisor = ring.from_sympy(common)
    return sp.Matrix([sp.factor(ring.to_sympy(ring.exquo(e, divisor))) if e else sp.S.Zero for e in row])


def _checked_nullspace(m: sp.Matrix, what: str, vectors: list[sp.Matrix]) -> list[sp.Matrix]:
    expected = m.cols - numeric_rank(m)
    if expected != len(vectors):
        raise GearsymError(f"{what}: the exact null space ({len(vectors)}) and the numeric one ({expected}) disagree "
                           "(a relation between the geometry's numbers)")
    return vectors


def solve_rows(matrix: sp.Matrix, rows: sp.Matrix) -> sp.Matrix:
    """X with ``X matrix = rows`` (``matrix`` square and invertible), exact (fraction-free, then each entry's
    numerator and denominator cancelled)."""
    both = sp.Matrix.vstack(matrix, rows)
    gens = Generators(both)
    dm = DomainMatrix.from_Matrix(gens.to(both))
    n = matrix.rows
    a = dm[:n, :].transpose()
    b = dm[n:, :].transpose()
    numerator, denominator = a.solve_den(b)
    if gens.of:
        x = numerator.to_Matrix().T / dm.domain.to_sympy(denominator)
        return x.applyfunc(lambda e: gens.normal(gens.from_(e)))
    # (each entry cancelled in the field of fractions of the domain: SymPy's cancel on expressions converts every
    # entry to polynomials and back, several times slower)
    field = dm.domain.get_field()
    return (numerator.convert_to(field) / field.convert_from(denominator, dm.domain)).to_Matrix().T


def fraction_forms(elements, domain, known=()) -> list[sp.Expr]:
    """Elements of ``domain`` (rational numbers, or a field of rational functions: exact arithmetic without
    expression trees) as compact expressions: each numerator its rational and monomial content times a primitive
    polynomial, each denominator the product of the irreducible factors of the ``known`` polynomials it holds (the
    few pieces a linear solve builds its denominators from: factoring each entry's denominator whole costs seconds),
    anything left factored."""
    if not domain.is_FractionField:
        return [sp.factor(domain.to_sympy(e)) for e in elements]
    ring = domain.get_ring().ring
    pieces = []
    for p in known:
        pieces += [f for f, _ in p.factor_list()[1] if f.degree() > 0 and f not in pieces]
    written: dict = {}

    def denominator(p) -> sp.Expr:
        if p not in written:
            content, rest = p.primitive()
            factors = []
            for f in pieces:
                power = 0
                while rest.degree() > 0:
                    quotient, remainder = rest.div(f)
                    if remainder:
                        break
                    rest, power = quotient, power + 1
                if power:
                    factors.append(f.as_expr() ** power)
            left = sp.factor(rest.as_expr()) if rest.degree() > 0 else rest.as_expr()
            written[p] = sp.Mul(ring.domain.to_sympy(content), left, *factors)
        return written[p]

    out = []
    for e in elements:
        if not e:
            out.append(sp.S.Zero)
            continue
        content, numerator = e.numer.primitive()
        if numerator.LC < 0:
            content, numerator = -content, -numerator
        terms = numerator.terms()
        monomial = tuple(min(m[i] for m, _ in terms) for i in range(ring.ngens))
        numerator = ring({tuple(a - b for a, b in zip(m, monomial)): c for m, c in terms})
        out.append(sp.Mul(ring.domain.to_sympy(content), *(x**k for x, k in zip(ring.symbols, monomial)),
                          numerator.as_expr()) / denominator(e.denom))
    return out


def is_zero(expr: sp.Expr) -> bool:
    """Whether ``expr`` is zero, its sines, cosines and radicals' relations applied."""
    return Generators([expr]).normal(expr) == 0


def numeric_nullspace(m: sp.Matrix, tolerance: float = 1e-9) -> list[list[float]]:
    """A basis of the null space of a matrix of numbers, in floats (singular values below ``tolerance`` times the
    largest count as zero)."""
    a = np.array(m.evalf(20).tolist(), dtype=float)
    if a.size == 0:
        return [list(row) for row in np.eye(m.cols)]
    _, singular, vt = np.linalg.svd(a)
    top = singular[0] if singular.size else 0.0
    rank = int(np.sum(singular > tolerance * top)) if top > 0 else 0
    return [list(v) for v in vt[rank:]]


def named_generators(exprs) -> dict[sp.Expr, sp.Symbol]:
    """The sines and cosines of parameters and the radicals of ``exprs``, each with a readable symbol standing for
    it (``cos_alpha_s``, ``sqrt_3``): the geometry's numbers as the symbolic stages carry them."""
    out: dict[sp.Expr, sp.Symbol] = {}
    radicals = 0
    for atom in Generators(exprs).of:
        if isinstance(atom, (sp.sin, sp.cos)):
            name = f"{type(atom).__name__}_{atom.args[0]}"
            name = name if name.isidentifier() else f"{type(atom).__name__}_{len(out)}"
        elif isinstance(atom, sp.Pow) and atom.base.is_Integer and atom.exp == sp.S.Half:
            name = f"sqrt_{atom.base}"
        else:
            radicals += 1
            name = f"root_{radicals}"
        out[atom] = sp.Symbol(name, real=True)
    return out


def simplified(expr: sp.Expr) -> sp.Expr:
    """``expr`` in normal form modulo its sines', cosines' and radicals' relations."""
    return Generators([expr]).normal(expr)
