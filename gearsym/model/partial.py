"""Partial derivatives by a plain symbol, by SymPy's own rules node by node, without its ``Derivative`` machinery.

``sp.diff`` builds a ``Derivative`` at every node it descends through and asks each argument's derivative whether
it is zero through the assumptions system: most of the time of Lagrange's equations of a drivetrain on bearings,
whose potential holds a backlash term per mesh with many degrees of freedom in it. :func:`partial` applies the rules
of SymPy's ``_eval_derivative`` (sum, product, power, function by its ``fdiff``) itself, a zero known when no argument
holds the symbol; a node of another kind is left to ``sp.diff``. The result is SymPy's expression for the same
derivative.
"""
from __future__ import annotations

from functools import reduce

import sympy as sp


def partial(expr: sp.Expr, x: sp.Symbol) -> sp.Expr:
    """d ``expr`` / d ``x`` (``x`` a plain symbol)."""
    done: dict[sp.Basic, sp.Expr] = {}

    def d(e: sp.Basic) -> sp.Expr:
        hit = done.get(e)
        if hit is not None:
            return hit
        if e == x:
            out = sp.S.One
        elif not e.args or x not in e.free_symbols:
            out = sp.S.Zero
        elif e.is_Add:
            out = e.func(*[d(a) for a in e.args])
        elif e.is_Mul:
            args = list(e.args)
            terms = []
            for i, a in enumerate(args):
                da = d(a)
                if da:
                    terms.append(reduce(lambda u, v: u * v, (args[:i] + [da] + args[i + 1:]), sp.S.One))
            out = sp.Add.fromiter(terms)
        elif e.is_Pow:
            db, de = d(e.base), d(e.exp)
            out = e * (de * sp.log(e.base) + db * e.exp / e.base)
        elif isinstance(e, sp.Function) and not isinstance(e, sp.Derivative):
            terms = []
            for i, a in enumerate(e.args, start=1):
                da = d(a)
                if da == 0:
                    continue
                try:
                    df = e.fdiff(i)
                except sp.ArgumentIndexError:
                    df = sp.Function.fdiff(e, i)
                terms.append(df * da)
            out = sp.Add(*terms)
        else:
            out = sp.diff(e, x)
        done[e] = out
        return out

    return d(sp.sympify(expr, strict=True))
