"""How expressions are printed in a derivation: the paper's notation, in LaTeX and in plain text.

SymPy's defaults are correct but far from the paper: ``kZ`` prints as ``kZ``
(the paper writes k_Z), an angle as ``\\psi_{1}{\\left(t \\right)}`` and its
acceleration as ``\\frac{d^{2}}{d t^{2}} \\psi_{1}{\\left(t \\right)}``. The
printer here keeps SymPy's layout but uses the paper's conventions:

* generalized coordinates (the angles psi_i(t), the relative coordinates x(t),
  x(tau)) are written without their argument;
* a derivative in t is an overdot (the paper's Eq. 1), a derivative in tau is
  written out as d/dtau (the paper's Eq. 2);
* names such as ``kZ``, ``cZ2``, ``M1a`` and ``B0_x3`` get subscripts.

The LaTeX it writes avoids what GitHub's Markdown pass can mangle before
MathJax sees it: no backslash before punctuation other than the row break
``\\\\``, and no ``}_`` (which Markdown could read as an emphasis delimiter).
"""
from __future__ import annotations

import re
import textwrap
from collections.abc import Iterable, Sequence

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.printing.latex import LatexPrinter
from sympy.printing.pretty import pretty

from ..model.symbols import t, tau

#: width at which the text renderer wraps pretty-printed formulas (fixed, so output is reproducible)
TEXT_COLUMNS = 100

_LOWER_UPPER = re.compile(r"([a-z])([A-Z][A-Za-z]*\d*)")  # kZ, cZ2, kS -> k_{Z}, c_{Z2}, k_{S}
_NUMBERED_TAG = re.compile(r"([A-Za-z]+?)(\d+)([a-z]+)")  # M1a -> M_{1a}
_SUFFIXED = re.compile(r"([A-Za-z]+\d+)_([A-Za-z][A-Za-z0-9]*)")  # B0_x3 -> B_{0}^{(x_{3})}
_SUBSCRIPTED = re.compile(r"(\\?[A-Za-z]+)_\{([^{}]*)\}")  # \psi_{1} -> (\psi, 1)


def latex_name(name: str) -> str:
    """LaTeX for a parameter, coordinate or function name, in the paper's style."""
    m = _LOWER_UPPER.fullmatch(name)
    if m:
        return f"{m[1]}_{{{m[2]}}}"
    m = _NUMBERED_TAG.fullmatch(name)
    if m:
        return f"{sp.latex(sp.Symbol(m[1]))}_{{{m[2]}{m[3]}}}"
    m = _SUFFIXED.fullmatch(name)
    if m:
        return f"{latex_name(m[1])}^{{({latex_name(m[2])})}}"
    return sp.latex(sp.Symbol(name))


class DerivationLatexPrinter(LatexPrinter):
    """SymPy's LaTeX printer with the paper's notation (see the module docstring).

    ``bare`` names the applied functions (generalized coordinates) printed
    without their time argument.
    """

    printmethod = "_latex"

    def __init__(self, bare: Iterable[str] = (), settings: dict | None = None):
        super().__init__(settings or {})
        self.bare = frozenset(bare)

    def _print_Symbol(self, expr: sp.Symbol, style: str = "plain") -> str:
        return latex_name(expr.name)

    def _print_Function(self, expr: sp.Function, exp: str | None = None) -> str:
        if not isinstance(expr, AppliedUndef):
            return super()._print_Function(expr, exp)
        name = latex_name(expr.func.__name__)
        if expr.func.__name__ in self.bare and expr.args in ((t,), (tau,)):
            body = name
        else:
            args = ", ".join(self._print(a) for a in expr.args)
            body = rf"{name}\left({args}\right)"
        return body if exp is None else rf"{body}^{{{exp}}}"

    def _print_Derivative(self, expr: sp.Derivative) -> str:
        f = expr.expr
        if not (isinstance(f, AppliedUndef) and len(expr.variable_count) == 1 and len(f.args) == 1):
            return super()._print_Derivative(expr)
        var, order = expr.variable_count[0]
        if f.args[0] != var:
            return super()._print_Derivative(expr)
        base = self._print(f)
        if var == t and order in (1, 2):
            # \dot{\psi_{1}}, not \dot{\psi}_{1}: "}_" could open Markdown emphasis
            return rf"\{'d' * order}ot{{{base}}}"
        v = self._print(var)
        if order == 1:
            return rf"\frac{{d {base}}}{{d {v}}}"
        return rf"\frac{{d^{{{order}}} {base}}}{{d {v}^{{{order}}}}}"


def to_latex(expr: sp.Basic, bare: Iterable[str] = ()) -> str:
    """LaTeX of ``expr`` with the derivation's conventions."""
    return DerivationLatexPrinter(bare).doprint(expr)


def sum_latex(leading: sp.Expr, rest: sp.Expr, bare: Iterable[str] = ()) -> str:
    """``leading + rest`` with ``leading`` written first (SymPy would sort the terms)."""
    head = to_latex(leading, bare)
    if rest == 0:
        return head
    tail = to_latex(rest, bare)
    return f"{head} {tail}" if tail.startswith("-") else f"{head} + {tail}"


def equation_latex(eq: sp.Eq, leading: sp.Expr | None = None, bare: Iterable[str] = ()) -> tuple[str, str]:
    """(lhs, rhs) LaTeX of an equation; ``leading`` (a term of the lhs) is written first."""
    lhs = eq.lhs
    if leading is not None and leading in sp.Add.make_args(lhs):
        left = sum_latex(leading, lhs - leading, bare)
    else:
        left = to_latex(lhs, bare)
    return left, to_latex(eq.rhs, bare)


def leading_derivative(expr: sp.Expr, order: int = 2) -> sp.Expr | None:
    """The term of ``expr`` holding a derivative of that order (to print it first), if any."""
    for term in sp.Add.make_args(expr):
        if any(sum(n for _, n in d.variable_count) == order for d in term.atoms(sp.Derivative)):
            return term
    return None


def aligned(rows: Sequence[tuple[str, str]], relation: str = "=") -> str:
    r"""An ``aligned`` environment, one row per line, each ``\\`` followed by one line break."""
    lines = [rf"{lhs} &{relation} {rhs}" for lhs, rhs in rows]
    return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"


def matrix_latex(m: sp.Matrix, bare: Iterable[str] = ()) -> str:
    r"""A ``bmatrix``, one row per line (a row never starts with a sign: see :func:`guard_line`)."""
    rows = [" & ".join(to_latex(m[i, j], bare) for j in range(m.cols)) for i in range(m.rows)]
    return "\\begin{bmatrix}\n" + " \\\\\n".join(guard_line(r) for r in rows) + "\n\\end{bmatrix}"


def guard_line(line: str) -> str:
    """Prefix ``{}`` to a line that Markdown could read as a list item or heading underline."""
    return "{}" + line if re.match(r"\s*([-+*=#>]|\d+[.)])", line) else line


# ------------------------------------------------------------------- plain text
def to_text(expr: sp.Basic, order: str | None = None) -> str:
    """Unicode pretty print for a terminal, at most :data:`TEXT_COLUMNS` wide where possible.

    A one-line result is wrapped between terms (SymPy's own wrapping would cut
    numbers in two); a two-dimensional one is wrapped by SymPy.
    """
    flat = pretty(expr, use_unicode=True, wrap_line=False, order=order)
    if max((len(line) for line in flat.splitlines()), default=0) <= TEXT_COLUMNS:
        return flat
    if "\n" not in flat:
        return textwrap.fill(flat, TEXT_COLUMNS, subsequent_indent="    ", break_long_words=False,
                             break_on_hyphens=False)
    return pretty(expr, use_unicode=True, num_columns=TEXT_COLUMNS, order=order)


def equation_text(eq: sp.Eq) -> str:
    """An equation with the highest derivative first on the left (as :func:`equation_latex`)."""
    lead = leading_derivative(eq.lhs)
    if lead is None or eq.lhs == lead:
        return to_text(eq)
    rest = [a for a in sp.Add.make_args(eq.lhs) if a != lead]
    return to_text(sp.Eq(sp.Add(lead, *rest, evaluate=False), eq.rhs, evaluate=False), order="none")


def to_str(expr: sp.Basic) -> str:
    """One-line SymPy string (what ``sympy.sympify`` reads back)."""
    return str(expr)


def number(value: float) -> str:
    """A parameter value without float-repr noise: 12 significant digits (8/3 -> 2.66666666667)."""
    return format(float(value), ".12g")
