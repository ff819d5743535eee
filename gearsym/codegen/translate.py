"""SymPy expressions to CasADi SX, including the backlash functions.

The translation walks SymPy's tree in its canonical argument order, so the
same expression always gives the same SX graph and therefore the same C.

g(x, eta) becomes ``(x >= 0 ? x : 0) + (x <= -eta ? x + eta : 0)``: the three
branches as two selects, which gcc -O3 compiles to compare-and-jump (branches the
CPU predicts: a step rarely changes side), and CasADi differentiates them to the
exact slope (1 in contact, 0 in the gap) for the variational equations. Sums and
products are combined shallowest first (``_shallow_first``), which keeps the
per-step dependency chain short.
"""
from __future__ import annotations

import numbers
from functools import lru_cache
from collections.abc import Mapping

import casadi as ca
import sympy as sp

from ..model.backlash import G, g, g_slope
from ..errors import ModelError


def _backlash(x, eta):
    return ca.if_else(x >= 0, x, 0) + ca.if_else(x <= -eta, x + eta, 0)


def _backlash_slope(x, eta):
    # nested, not a sum: with eta = 0 both sides hold at x = 0, where the slope is 1, not 2 (a linearisation at a
    # static deflection of 0, Mathieu's case, sits exactly there)
    return ca.if_else(x >= 0, 1, ca.if_else(x <= -eta, 1, 0))


def _backlash_potential(x, eta):
    return ca.if_else(x >= 0, x * x / 2, 0) + ca.if_else(x <= -eta, (x + eta) * (x + eta) / 2, 0)


def select_min(a, b):
    """min(a, b) as a select (a NaN in ``a`` keeps ``b``)."""
    return ca.if_else(a < b, a, b)


def select_max(a, b):
    return ca.if_else(a > b, a, b)


_FUNCTIONS = {
    sp.sin: ca.sin, sp.cos: ca.cos, sp.tan: ca.tan, sp.exp: ca.exp, sp.log: ca.log,
    sp.sinh: ca.sinh, sp.cosh: ca.cosh, sp.tanh: ca.tanh, sp.asin: ca.asin, sp.acos: ca.acos,
    sp.atan: ca.atan, sp.atan2: ca.atan2, sp.Abs: ca.fabs, sp.sign: ca.sign, sp.floor: ca.floor,
    sp.ceiling: ca.ceil, sp.erf: ca.erf,
    g: _backlash, g_slope: _backlash_slope, G: _backlash_potential,
}


class _Translator:
    def __init__(self, symbols: Mapping[sp.Symbol, ca.SX], where: str):
        self.symbols = dict(symbols)
        self.where = where
        self.memo: dict[sp.Basic, ca.SX] = {}

    def __call__(self, expr: sp.Basic) -> ca.SX:
        hit = self.memo.get(expr)
        if hit is None:
            hit = self.memo[expr] = self._translate(expr)
        return hit

    def _translate(self, e: sp.Basic):
        if e.is_Symbol:
            if e in self.symbols:
                return self.symbols[e]
            raise ModelError(f"symbol {e} has no value in the generated code", self.where)
        if e is sp.true:
            return ca.SX(1)
        if e is sp.false:
            return ca.SX(0)
        if e.is_Number or e.is_NumberSymbol:
            if e.is_real is False:
                raise ModelError(f"complex constant {e} cannot be evaluated in real arithmetic", self.where)
            return ca.SX(float(e))
        if e.is_Add:
            terms = _shallow_first(e.args)
            out = self(terms[0])
            for a in terms[1:]:
                out = out + self(a)
            return out
        if e.is_Mul:
            factors = _shallow_first(e.args)
            out = self(factors[0])
            for a in factors[1:]:
                out = out * self(a)
            return out
        if e.is_Pow:
            base, exp = e.args
            if exp == sp.S.Half:
                return ca.sqrt(self(base))
            if exp == -1:
                return 1 / self(base)
            if exp.is_Integer:
                n = int(exp)
                b = self(base)
                power = b * b if abs(n) == 2 else ca.constpow(b, abs(n))
                return power if n > 0 else 1 / power
            return self(base) ** self(exp)
        if isinstance(e, sp.Piecewise):
            out = None
            for value, cond in reversed(e.args):
                v = self(value)
                out = v if out is None else ca.if_else(self(cond), v, out)
            return out
        if isinstance(e, sp.Heaviside):
            x = self(e.args[0])
            at_zero = self(e.args[1]) if len(e.args) > 1 else ca.SX(0.5)
            return ca.if_else(x == 0, at_zero, ca.if_else(x > 0, 1, 0))
        if isinstance(e, (sp.Min, sp.Max)):
            op = ca.fmin if isinstance(e, sp.Min) else ca.fmax
            out = self(e.args[0])
            for a in e.args[1:]:
                out = op(out, self(a))
            return out
        if isinstance(e, sp.core.relational.Relational):
            a, b = self(e.lhs), self(e.rhs)
            ops = {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b, "==": a == b, "!=": a != b}
            return ops[e.rel_op]
        if isinstance(e, sp.And):
            out = self(e.args[0])
            for a in e.args[1:]:
                out = ca.logic_and(out, self(a))
            return out
        if isinstance(e, sp.Or):
            out = self(e.args[0])
            for a in e.args[1:]:
                out = ca.logic_or(out, self(a))
            return out
        if isinstance(e, sp.Not):
            return ca.logic_not(self(e.args[0]))
        func = _FUNCTIONS.get(e.func)
        if func is not None:
            return func(*(self(a) for a in e.args))
        raise ModelError(
            f"cannot generate code for {e.func.__name__} in {e}; supported: arithmetic, powers, "
            f"{', '.join(sorted(f.__name__ for f in _FUNCTIONS))}, Piecewise, Min, Max, Heaviside",
            self.where,
        )


@lru_cache(maxsize=4096)
def _depth(e: sp.Basic) -> int:
    return 1 + max(map(_depth, e.args)) if e.args else 0


def _shallow_first(args) -> list:
    """The terms of a sum (factors of a product) in the order they are combined: the shallowest first
    (SymPy's canonical order among equals), so that the deepest, in a model the one through the
    backlash of the state, enters last, once: the chain from one RK4 stage's state to the next is
    then one multiply-add after it rather than a multiply and two adds (measured: ~10 % per step on
    the one-stage model, whose step is latency-bound)."""
    return sorted(args, key=_depth)


def to_casadi(exprs, symbols: Mapping[sp.Symbol, ca.SX], where: str = "") -> list[ca.SX]:
    """Translate SymPy expressions with ``symbols`` mapped to SX symbols (one memo for all)."""
    tr = _Translator(symbols, where)
    return [tr(_as_sympy(e, where)) for e in exprs]


def _as_sympy(e, where: str) -> sp.Basic:
    """SymPy objects and Python numbers only: a string would need parsing (gearsym.model.expressions.to_expr)."""
    if isinstance(e, sp.Basic):
        return e
    if isinstance(e, numbers.Integral) and not isinstance(e, bool):
        return sp.Integer(int(e))
    if isinstance(e, numbers.Real):
        return sp.Float(float(e))
    raise ModelError(f"cannot generate code for {e!r} ({type(e).__name__}); expected a SymPy expression", where)
