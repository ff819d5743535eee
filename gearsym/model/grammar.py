"""The grammar of a formula, checked on Python's syntax tree alone (no SymPy): what may be written.

:mod:`.formula` builds the SymPy expression of a formula that passes; the command line checks one here
before any work starts (and before SymPy is loaded: a run of a cached model never loads it).
"""
from __future__ import annotations

import ast

from ..errors import ModelError

#: functions a formula may call: those the code generator translates (``abs`` is Python's name of Abs)
FUNCTION_NAMES = ("sin", "cos", "tan", "exp", "log", "sqrt", "sinh", "cosh", "tanh", "asin", "acos", "atan",
                  "atan2", "Abs", "abs", "sign", "floor", "ceiling", "erf", "Min", "Max", "Heaviside", "Piecewise",
                  "And", "Or", "Not")
GRAMMAR = ("a formula may use numbers, names of parameters and states, t, tau, phi, pi, + - * / **, "
           f"comparisons, and the functions {', '.join(FUNCTION_NAMES)}")
MAX_LENGTH = 10_000
MAX_DEPTH = 100

ARITHMETIC = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)
COMPARISONS = (ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Eq, ast.NotEq)
REFUSED_OPERATORS = {
    ast.BitXor: "'^' (write powers as **)", ast.Mod: "'%'", ast.FloorDiv: "'//' (use floor(a/b))",
    ast.MatMult: "'@'", ast.LShift: "'<<'", ast.RShift: "'>>'", ast.BitAnd: "'&' (use And(a, b))",
    ast.BitOr: "'|' (use Or(a, b))", ast.Invert: "'~' (use Not(a))", ast.Not: "'not' (use Not(a))",
    ast.And: "'and' (use And(a, b))", ast.Or: "'or' (use Or(a, b))",
}
REFUSED_NODES = {
    ast.Attribute: "attribute access (.)", ast.Subscript: "subscripts ([])", ast.Lambda: "lambda",
    ast.Tuple: "a tuple (only a Piecewise takes (value, condition) pairs)", ast.List: "a list",
    ast.Dict: "a dict", ast.Set: "a set", ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension", ast.GeneratorExp: "a comprehension", ast.JoinedStr: "an f-string",
    ast.IfExp: "'if ... else' (use Piecewise)", ast.NamedExpr: "':='", ast.Starred: "'*' unpacking",
}


def shown(text: str) -> str:
    return repr(text if len(text) <= 60 else text[:57] + "...")


def refusal(text: str, what: str, where: str) -> ModelError:
    return ModelError(f"the formula {shown(text)} {what}; {GRAMMAR}", where)


def syntax_tree(text: str, where: str) -> ast.expr:
    """The checked syntax tree of ``text``: a one-line :class:`ModelError` for anything outside the grammar."""
    if not text:
        raise ModelError("empty formula; give a number, a parameter name or a formula", where)
    if len(text) > MAX_LENGTH:
        raise refusal(text, f"has {len(text)} characters, more than the {MAX_LENGTH} a formula may have", where)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        if "nested parentheses" in str(exc):
            raise refusal(text, f"is nested too deeply (more than {MAX_DEPTH} levels)", where) from None
        raise refusal(text, f"is not a formula ({exc.msg})", where) from None
    except (RecursionError, MemoryError):
        raise refusal(text, "is nested too deeply for Python's parser", where) from None
    _check(tree.body, 0, text, where)
    return tree.body


def _check(n: ast.AST, depth: int, text: str, where: str) -> None:
    """Every node against the grammar; sums and products that nest to the left count as one level."""
    stack = [(n, depth)]
    while stack:
        n, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise refusal(text, f"is nested too deeply (more than {MAX_DEPTH} levels)", where)
        if isinstance(n, ast.Constant):
            if isinstance(n.value, complex):
                raise refusal(text, "uses an imaginary number, which is not allowed", where)
            if not isinstance(n.value, (bool, int, float)):
                raise refusal(text, f"uses the constant {n.value!r}; only numbers are allowed", where)
        elif isinstance(n, ast.Name):
            if n.id.startswith("_"):
                raise refusal(text, f"uses {n.id!r}; a name in a formula must not start with '_'", where)
        elif isinstance(n, ast.BinOp) and isinstance(n.op, ARITHMETIC):
            left_depth = depth if not isinstance(n.op, ast.Pow) else depth + 1
            stack += [(n.left, left_depth), (n.right, depth + 1)]
        elif isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.UAdd, ast.USub)):
            stack.append((n.operand, depth + 1))
        elif isinstance(n, ast.Compare):
            for op in n.ops:
                if not isinstance(op, COMPARISONS):
                    raise refusal(text, f"uses the comparison {type(op).__name__}; use < <= > >= == !=", where)
            stack += [(c, depth + 1) for c in (n.left, *n.comparators)]
        elif isinstance(n, ast.Call):
            stack += _call(n, depth, text, where)
        else:
            op = getattr(n, "op", None)
            if type(op) in REFUSED_OPERATORS:
                raise refusal(text, f"uses the operator {REFUSED_OPERATORS[type(op)]}, which is not allowed", where)
            what = REFUSED_NODES.get(type(n), type(n).__name__)
            raise refusal(text, f"uses {what}, which is not allowed in a formula", where)


def _call(n: ast.Call, depth: int, text: str, where: str) -> list:
    if isinstance(n.func, ast.Attribute):
        raise refusal(text, f"uses {REFUSED_NODES[ast.Attribute]}, which is not allowed in a formula", where)
    if not isinstance(n.func, ast.Name):
        raise refusal(text, "calls something other than a function by its name", where)
    name = n.func.id
    if name.startswith("_"):
        raise refusal(text, f"calls {name!r}; a name in a formula must not start with '_'", where)
    if name not in FUNCTION_NAMES:
        raise ModelError(f"unknown function {name}() in the formula {shown(text)}; {GRAMMAR}", where)
    if n.keywords:
        raise refusal(text, f"gives {name}() a keyword argument; arguments are positional", where)
    if name != "Piecewise":
        return [(a, depth + 1) for a in n.args]
    out = []
    for a in n.args:
        if not (isinstance(a, ast.Tuple) and len(a.elts) == 2):
            raise refusal(text, "gives Piecewise an argument that is not a (value, condition) pair", where)
        out += [(a.elts[0], depth + 2), (a.elts[1], depth + 2)]
    return out


def check_formula(text: str, where: str) -> None:
    """A one-line error if ``text`` is not a formula of the grammar (nothing is built, SymPy is not needed)."""
    syntax_tree(text.strip(), where)


def canonical_formula(text: str, where: str) -> str:
    """``text`` checked against the grammar (as :func:`check_formula`, without SymPy) and written without its
    spaces: one spelling per formula, so that ``1 + 0.2*cos(tau)`` and ``1+0.2*cos(tau)`` are the same model to
    the start-up cache, whose key hashes the text. Its digits stay as written (a float is built from its digits);
    a text whose compact spelling would read as another tree keeps its spaces."""
    tree = syntax_tree(text.strip(), where)
    compact = "".join(text.split())
    try:
        same = ast.dump(ast.parse(compact, mode="eval").body) == ast.dump(tree)
    except SyntaxError:
        same = False
    return compact if same else text.strip()
