"""Reading a formula string into SymPy without running it as Python.

SymPy's ``sympify``/``parse_expr`` evaluate their input, so a formula such as
``__import__('os').system(...)`` would run. Here Python's ``ast`` only parses
the text; the tree is then walked, every node checked against a short grammar,
and the SymPy expression built node by node, so no string ever reaches SymPy.

The grammar: numbers (``2``, ``0.5``, ``1e-3``), names (parameters, states, the
time ``t``/``tau``/``phi``; ``pi`` is the constant), ``+ - * / **``, the
comparisons ``< <= > >= == !=`` and ``True``/``False`` (for Piecewise
conditions), and calls of the functions in :data:`FUNCTIONS` by plain name.
``^`` is refused (in Python it is not a power). A name is a function only where
it is called, so ``beta``, ``gamma``, ``E`` or ``I`` are parameters.
"""
from __future__ import annotations

import ast
import math
import operator
import sys
from collections.abc import Callable

import sympy as sp

from ..errors import ModelError
from .grammar import FUNCTION_NAMES, GRAMMAR, MAX_DEPTH, REFUSED_NODES, REFUSED_OPERATORS, syntax_tree

#: the SymPy function of each name the grammar allows (``abs`` is Python's name of Abs)
FUNCTIONS: dict[str, Callable] = {name: getattr(sp, "Abs" if name == "abs" else name) for name in FUNCTION_NAMES}
#: an exact power a**b with more bits than this would take minutes and gigabytes to compute
MAX_EXACT_BITS = 1_000_000

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
            ast.Eq: sp.Eq, ast.NotEq: sp.Ne}


def parse_formula(text: str, where: str) -> sp.Basic:
    """The SymPy expression of ``text``, with a plain ``Symbol`` for every name.

    Anything outside the grammar raises a one-line :class:`ModelError` that
    names ``where`` and what was refused.
    """
    return _Builder(text.strip(), where).build()


class _Builder:
    def __init__(self, text: str, where: str):
        self.text, self.where = text, where
        self.shown = repr(text if len(text) <= 60 else text[:57] + "...")

    def refuse(self, what: str) -> ModelError:
        return ModelError(f"the formula {self.shown} {what}; {GRAMMAR}", self.where)

    def build(self) -> sp.Basic:
        tree = syntax_tree(self.text, self.where)  # the grammar, checked before anything is built
        try:
            expr = self.node(tree, 0)
        except ModelError:
            raise
        except (TypeError, ValueError, ArithmeticError) as exc:  # SymPy refusing, e.g. sin(x, y) or (x < 1) + 1
            raise self.refuse(f"cannot be built: {exc}") from None
        self.check_numbers(expr)
        return expr

    def check_numbers(self, expr: sp.Basic) -> None:
        """Every number the formula holds (its largest parts without a name) finite and real in double precision:
        1/0, log(0), 1e400 or exp(exp(exp(exp(10)))) would reach the C as inf or nan, or not at all."""
        pending = [expr]
        while pending:
            part = pending.pop()
            if not getattr(part, "is_number", False):
                pending.extend(part.args)
                continue
            problem = _number_problem(part)
            if problem:
                kind = "is not real" if problem.endswith("is imaginary") else "is not finite"
                raise ModelError(f"the formula {self.shown} {kind}: {problem}; give a finite real value", self.where)

    def node(self, n: ast.AST, depth: int) -> sp.Basic:
        if depth > MAX_DEPTH:
            raise self.refuse(f"is nested too deeply (more than {MAX_DEPTH} levels)")
        if isinstance(n, ast.Constant):
            return self.constant(n)
        if isinstance(n, ast.Name):
            return self.name(n.id)
        if isinstance(n, ast.BinOp) and type(n.op) in _BINARY:
            return self.binary(n, depth)
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.UAdd, ast.USub)):
            operand = self.node(n.operand, depth + 1)
            return -operand if isinstance(n.op, ast.USub) else +operand
        if isinstance(n, ast.Compare):
            return self.compare(n, depth)
        if isinstance(n, ast.Call):
            return self.call(n, depth)
        op = getattr(n, "op", None)
        if type(op) in REFUSED_OPERATORS:
            raise self.refuse(f"uses the operator {REFUSED_OPERATORS[type(op)]}, which is not allowed")
        what = REFUSED_NODES.get(type(n), type(n).__name__)
        raise self.refuse(f"uses {what}, which is not allowed in a formula")

    def constant(self, n: ast.Constant) -> sp.Basic:
        value = n.value
        if isinstance(value, bool):
            return sp.true if value else sp.false
        if isinstance(value, int):
            return sp.Integer(value)
        if isinstance(value, float):
            # from the digits as written, as SymPy's parser did ('0.1' keeps the precision its digits give)
            return sp.Float(ast.get_source_segment(self.text, n).replace("_", ""))
        if isinstance(value, complex):
            raise self.refuse("uses an imaginary number, which is not allowed")
        raise self.refuse(f"uses the constant {value!r}; only numbers are allowed")

    def name(self, name: str) -> sp.Basic:
        if name.startswith("_"):
            raise self.refuse(f"uses {name!r}; a name in a formula must not start with '_'")
        return sp.pi if name == "pi" else sp.Symbol(name)

    def binary(self, n: ast.BinOp, depth: int) -> sp.Basic:
        if isinstance(n.op, ast.Pow):
            return self.power(self.node(n.left, depth + 1), self.node(n.right, depth + 1))
        # a+b+c+... nests to the left: walk that spine in a loop so that only real nesting counts as depth
        spine = []
        while isinstance(n, ast.BinOp) and type(n.op) in _BINARY and not isinstance(n.op, ast.Pow):
            spine.append(n)
            n = n.left
        out = self.node(n, depth + 1)
        for step in reversed(spine):
            out = _BINARY[type(step.op)](out, self.node(step.right, depth + 1))
        return out

    def power(self, base: sp.Basic, exponent: sp.Basic) -> sp.Basic:
        if isinstance(base, sp.Rational) and isinstance(exponent, sp.Rational):
            bits = abs(exponent.p) * max(int(base.p).bit_length(), int(base.q).bit_length())
            if bits > MAX_EXACT_BITS:
                raise self.refuse(f"asks for a power of more than {MAX_EXACT_BITS} bits, too large to compute exactly")
        return base**exponent

    def compare(self, n: ast.Compare, depth: int) -> sp.Basic:
        terms = [self.node(n.left, depth + 1)] + [self.node(c, depth + 1) for c in n.comparators]
        parts = []
        for op, left, right in zip(n.ops, terms, terms[1:]):
            if type(op) not in _COMPARE:
                raise self.refuse(f"uses the comparison {type(op).__name__}; use < <= > >= == !=")
            parts.append(_COMPARE[type(op)](left, right))
        return parts[0] if len(parts) == 1 else sp.And(*parts)  # 0 < x < 1 reads as in mathematics

    def call(self, n: ast.Call, depth: int) -> sp.Basic:
        if isinstance(n.func, ast.Attribute):
            raise self.refuse(f"uses {REFUSED_NODES[ast.Attribute]}, which is not allowed in a formula")
        if not isinstance(n.func, ast.Name):
            raise self.refuse("calls something other than a function by its name")
        name = n.func.id
        if name.startswith("_"):
            raise self.refuse(f"calls {name!r}; a name in a formula must not start with '_'")
        if name not in FUNCTIONS:
            raise ModelError(f"unknown function {name}() in the formula {self.shown}; {GRAMMAR}", self.where)
        if n.keywords:
            raise self.refuse(f"gives {name}() a keyword argument; arguments are positional")
        if name == "Piecewise":
            return sp.Piecewise(*(self.pair(a, depth + 1) for a in n.args))
        return FUNCTIONS[name](*(self.node(a, depth + 1) for a in n.args))

    def pair(self, n: ast.AST, depth: int) -> tuple[sp.Basic, sp.Basic]:
        if not (isinstance(n, ast.Tuple) and len(n.elts) == 2):
            raise self.refuse("gives Piecewise an argument that is not a (value, condition) pair")
        return self.node(n.elts[0], depth + 1), self.node(n.elts[1], depth + 1)


def _number_problem(part: sp.Basic) -> str:
    """What keeps a constant expression from being a finite real double, or ''."""
    if part.has(sp.zoo, sp.nan):
        return "it divides by zero, or takes the log of 0"
    text = str(part.evalf(4)) if part.is_Float else str(part)
    shown = text if len(text) <= 40 else text[:37] + "..."
    try:
        value = complex(part.evalf(20))
    except (OverflowError, MemoryError):
        return f"{shown} overflows (a double holds at most {sys.float_info.max:.3g})"
    except (TypeError, ValueError, ArithmeticError):
        return f"{shown} has no numeric value"
    if math.isnan(value.real) or math.isnan(value.imag):
        return f"{shown} is undefined"
    if math.isinf(value.real) or math.isinf(value.imag):
        return f"{shown} is infinite or beyond what a double holds ({sys.float_info.max:.3g})"
    if value.imag:
        return f"{shown} is imaginary"
    return ""
