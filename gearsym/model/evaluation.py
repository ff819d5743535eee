"""An expression's value at a point, to many digits, every shared subexpression computed once.

SymPy's own ``xreplace`` then ``evalf`` rebuilds and canonicalises the whole tree at each substitution: seconds for
the equations of a drivetrain on bearings, where the same rational weights and line-of-action coefficients recur in
every row. Here the tree is walked once per point, each distinct node's value kept (mpmath numbers at the working
precision), and a node the walk does not know (a Piecewise, an Abs) is evaluated by SymPy from its arguments'
values. A leaf without a value is an error that names it.
"""
from __future__ import annotations

from collections.abc import Mapping

import mpmath
import sympy as sp

from .backlash import g, g_slope

_UNARY = {sp.sin: mpmath.sin, sp.cos: mpmath.cos, sp.tan: mpmath.tan, sp.exp: mpmath.exp, sp.log: mpmath.log,
          sp.sinh: mpmath.sinh, sp.cosh: mpmath.cosh, sp.tanh: mpmath.tanh, sp.atan: mpmath.atan}


class PointValues:
    """Values of expressions at one point: ``leaves`` gives a number to each symbol, applied function of t and
    derivative the expressions hold (numbers, SymPy or mpmath); ``digits`` is the working precision."""

    def __init__(self, leaves: Mapping[sp.Expr, object], digits: int):
        self.digits = digits
        with mpmath.workdps(digits):
            self._known: dict[sp.Expr, mpmath.mpf] = {k: self._leaf(v) for k, v in leaves.items()}

    def _leaf(self, value) -> mpmath.mpf:
        if isinstance(value, sp.Basic):
            value = sp.N(value, self.digits)
            if not value.is_real:
                raise ValueError(f"{value} is not a real number")
            return mpmath.mpf(value)
        return mpmath.mpf(value)

    def __call__(self, expr) -> mpmath.mpf:
        with mpmath.workdps(self.digits):
            return self._value(sp.sympify(expr, strict=True))

    def _value(self, expr: sp.Expr) -> mpmath.mpf:
        known = self._known.get(expr)
        if known is not None:
            return known
        if expr.is_Number or expr.is_NumberSymbol:
            out = self._leaf(expr)
        elif expr.is_Add:
            out = mpmath.fsum(self._value(a) for a in expr.args)
        elif expr.is_Mul:
            out = mpmath.fprod(self._value(a) for a in expr.args)
        elif expr.is_Pow:
            base, exponent = expr.args
            out = self._value(base) ** (int(exponent) if exponent.is_Integer else self._value(exponent))
        elif expr.func in _UNARY:
            out = _UNARY[expr.func](self._value(expr.args[0]))
        elif isinstance(expr, (g, g_slope)):
            x, eta = (self._value(a) for a in expr.args)
            if isinstance(expr, g):
                out = x if x >= 0 else (x + eta if x <= -eta else mpmath.mpf(0))
            else:
                out = mpmath.mpf(1) if (x >= 0 or x <= -eta) else mpmath.mpf(0)
        elif expr.is_Symbol or isinstance(expr, (sp.Derivative, sp.core.function.AppliedUndef)):
            raise KeyError(f"no value for {expr}")
        else:  # (a node the walk does not know, a Piecewise, say: SymPy evaluates it at its leaves' values)
            leaves = {a: sp.Float(self._value(a), self.digits) for a in _leaves(expr)}
            out = self._leaf(expr.xreplace(leaves))
        self._known[expr] = out
        return out


def _leaves(expr: sp.Basic) -> set:
    """The symbols, applied functions and derivatives of ``expr`` (a derivative whole, not its function)."""
    out = set()
    walk = sp.preorder_traversal(expr)
    for node in walk:
        if isinstance(node, (sp.Symbol, sp.Derivative, sp.core.function.AppliedUndef)):
            out.add(node)
            walk.skip()
    return out


def inventory(exprs) -> tuple[set, set, int | None]:
    """The symbols, the applied functions of ``exprs`` (their undefined ones: k(t), psi(t)) and the least precision
    in bits of their Floats (None without one), each distinct node visited once (``atoms`` visits a subexpression
    as often as it recurs)."""
    symbols, functions, bits = set(), set(), None
    seen: set = set()
    stack = [e for e in exprs if isinstance(e, sp.Basic)]
    while stack:
        node = stack.pop()
        if node in seen:
            continue
        seen.add(node)
        if node.is_Symbol:
            symbols.add(node)
            continue
        if node.is_Float:
            bits = node._prec if bits is None else min(bits, node._prec)
        elif isinstance(node, sp.core.function.AppliedUndef):
            functions.add(node)
        stack.extend(a for a in node.args if isinstance(a, sp.Basic))
    return symbols, functions, bits
