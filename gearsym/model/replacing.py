"""SymPy's ``xreplace`` with each distinct subexpression rebuilt once.

``expr.xreplace(rule)`` walks the tree and rebuilds every node on the way to a replaced one, a subexpression
met twice twice: the rows of a planetary set on bearings hold the same rational weights and line-of-action
coefficients many times, and rebuilding them was a good part of its reduction. A :class:`Replacer` keeps what each
node became, across all the expressions it is given; the result is ``xreplace``'s, node for node.
"""
from __future__ import annotations

from collections.abc import Mapping

import sympy as sp


class Replacer:
    """``expr.xreplace(rule)`` for many expressions, each distinct node replaced once."""

    def __init__(self, rule: Mapping):
        self.rule = dict(rule)
        self._done: dict[sp.Basic, sp.Basic] = {}

    def __call__(self, expr):
        if not self.rule or not isinstance(expr, sp.Basic):
            return expr
        return self._replace(expr)

    def _replace(self, node: sp.Basic) -> sp.Basic:
        done = self._done.get(node)
        if done is not None:
            return done
        if node in self.rule:
            out = self.rule[node]
        elif not node.args:
            out = node
        else:
            args = tuple(self._replace(a) if isinstance(a, sp.Basic) else a for a in node.args)
            out = node.func(*args) if any(a is not b for a, b in zip(args, node.args)) else node
        self._done[node] = out
        return out
