"""Turning what a user writes (a name, a number, a formula) into SymPy expressions.

Formula strings are read by :mod:`gearsym.model.formula`, which never runs
them as Python. Every name in a formula becomes the canonical parameter symbol,
except the reserved ``t``, ``tau`` and ``phi``; calls of functions outside the
allowed ones are rejected with the name of the component that used them.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Union

import sympy as sp
from sympy.core.function import AppliedUndef

from ..errors import ModelError
from .symbols import RESERVED, parameter_symbol
from .formula import parse_formula

ExprLike = Union[str, int, float, sp.Expr]


def to_expr(value: ExprLike, where: str, extra: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """Parse ``value`` into a SymPy expression of canonical symbols.

    ``extra`` maps further names (the states and time of a first-order system) to their symbols.
    """
    if isinstance(value, bool) or value is None:
        raise ModelError(f"expected a number, a parameter name or a formula, got {value!r}", where)
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            raise ModelError(f"{value!r} is not a finite number; give a finite value", where)
        return sp.nsimplify(value) if isinstance(value, int) else sp.Float(value)
    if isinstance(value, str):
        expr = parse_formula(value, where)
    elif isinstance(value, sp.Basic):
        expr = value
    else:
        raise ModelError(f"expected a number, a parameter name or a formula, got {type(value).__name__}", where)
    return canonicalize(expr, where, extra)


def canonicalize(expr: sp.Expr, where: str, extra: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """Replace every symbol by its canonical twin (same name, same assumptions everywhere)."""
    extra = dict(extra or {})
    unknown_calls = sorted({type(f).__name__ for f in expr.atoms(AppliedUndef)} - set(extra))
    if unknown_calls:
        raise ModelError(
            f"unknown function(s) {', '.join(unknown_calls)} in {expr}; use SymPy functions "
            "such as cos, sin, exp, Abs, Piecewise",
            where,
        )
    mapping = {}
    for s in expr.free_symbols:
        name = s.name
        mapping[s] = extra.get(name) or RESERVED.get(name) or parameter_symbol(name)
    return expr.xreplace(mapping)


def parameter_names(expr: sp.Expr) -> set[str]:
    """Names of the parameters in ``expr`` (everything but the reserved time/phase symbols)."""
    return {s.name for s in expr.free_symbols if s.name not in RESERVED}


