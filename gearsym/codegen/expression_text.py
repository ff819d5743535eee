"""Expressions as text (``str`` and ``srepr``), each shared subexpression printed once.

A large model's right-hand sides hold the same subexpressions many times (the rational weights of a planetary set's
turning frame recur in every row): SymPy's printers print each occurrence again, and sort every sum's terms again,
seconds for the manifest and the code hash of Lin & Parker's set. These printers keep each compound node's text.
The text is SymPy's own, character for character: a compound node prints the same wherever it stands (only a bare
Float at the top prints otherwise than nested, and atoms are not kept).
"""
from __future__ import annotations

import sympy as sp
from sympy.printing.repr import ReprPrinter
from sympy.printing.str import StrPrinter


class _Kept:
    """The text of each compound node, printed once (mixed into a SymPy printer)."""

    def __init__(self, settings=None):
        super().__init__(settings)
        self._kept: dict[sp.Basic, str] = {}

    def _print(self, expr, **kwargs):
        if kwargs or not isinstance(expr, sp.Basic) or not expr.args:
            return super()._print(expr, **kwargs)
        text = self._kept.get(expr)
        if text is None:
            text = self._kept[expr] = super()._print(expr)
        return text


class _KeptStr(_Kept, StrPrinter):
    pass


class _KeptRepr(_Kept, ReprPrinter):
    pass


class ExpressionText:
    """``str`` and ``srepr`` of many expressions that share subexpressions (one printer each, kept across calls)."""

    def __init__(self):
        self._str, self._repr = _KeptStr(), _KeptRepr()

    def str(self, expr) -> str:
        return self._str.doprint(expr)

    def srepr(self, expr) -> str:
        return self._repr.doprint(expr)
