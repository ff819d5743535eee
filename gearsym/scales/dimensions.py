"""Evaluating a parameter expression on physical values in SI, its dimension checked at every + and function.

A value is a :class:`~gearsym.units.Measure`: an SI number and the exponents of mass, length and time.
Products add exponents, whole or rational powers scale them, sums need equal ones, and a function (cos,
sqrt of a ratio, ...) takes dimensionless arguments. No unit library is needed inside: the units were
turned into SI at the edge (:mod:`gearsym.units`).
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import sympy as sp

from ..errors import GearsymError
from ..units import Measure, dimension_text

NONE = (0.0, 0.0, 0.0)


def evaluate(expr: sp.Expr, values: Mapping[str, Measure], where: str) -> Measure:
    """``expr`` with every parameter a physical value: a :class:`Measure` (``given`` is the SI number)."""
    si, dims = _walk(expr, values, where)
    return Measure(si, dims, si, "")


def _walk(expr: sp.Expr, values: Mapping[str, Measure], where: str) -> tuple[float, tuple[float, float, float]]:
    if expr.is_Number or isinstance(expr, sp.NumberSymbol):
        return float(expr), NONE
    if isinstance(expr, sp.Symbol):
        if expr.name not in values:
            raise GearsymError(f"{where}: no physical value for {expr.name}")
        value = values[expr.name]
        return value.si, value.dims
    args = [_walk(a, values, where) for a in expr.args]
    if expr.is_Add:
        dims = args[0][1]
        for a in args[1:]:
            if not _same(a[1], dims):
                raise GearsymError(f"{where}: inconsistent dimensions in {expr}: {dimension_text(dims)} + "
                                   f"{dimension_text(a[1])}")
        return math.fsum(a[0] for a in args), dims
    if expr.is_Mul:
        si, dims = 1.0, NONE
        for a in args:
            si *= a[0]
            dims = tuple(x + y for x, y in zip(dims, a[1]))
        return si, dims
    if expr.is_Pow and expr.exp.is_Number:
        (base, dims), power = args[0], float(expr.exp)
        try:
            return base ** power, tuple(d * power for d in dims)
        except (OverflowError, ZeroDivisionError):
            raise GearsymError(f"{where}: {expr} cannot be evaluated at these values (a division by zero or an "
                               "overflow)") from None
    if isinstance(expr, sp.Function) and all(_same(a[1], NONE) for a in args):
        return float(expr.func(*(sp.Float(a[0]) for a in args))), NONE
    raise GearsymError(f"{where}: cannot evaluate {expr} with units (a function of a dimensional value?)")


def _same(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return all(abs(x - y) < 1e-12 for x, y in zip(a, b))


def same_dimension(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    """Whether two exponent triples are the same dimension."""
    return _same(a, b)
