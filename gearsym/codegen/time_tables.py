"""Split the right-hand side into a state part, periodic tables of time, and constants.

In the gear models time enters only through k(tau) and the forcing, both
periodic with the forcing period. With a fixed step the RK4 stage times repeat
every period, so those parts are evaluated once per run at the 2N+1 half-step
times and looked up: the inner loop does no sin/cos at all. Likewise every
combination of parameters alone (-2 zeta/omega, kS beta1/omega^2) is evaluated
once per run, not at every stage.

A maximal state-free subexpression becomes a *table* entry if it depends on
time, else a *constant*. The state-free factors of a product and terms of a sum
are grouped first, so ``-2*zeta*v/omega`` is one constant times ``v``. With
``factored`` (the loops that locate the backlash crossings) a table entry's
time-free factors are a constant of their own (k(tau)/omega^2 is a constant
1/omega^2 times the table k(tau)), so that the tables depend on as few
parameters as can be: a continuation in omega then never recomputes them. The
paper's plain scheme keeps the grouped entries, whose arithmetic the committed
reproduction and the comparisons with hand-written C were computed with.
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError
from ..system import FirstOrderSystem
from .periodicity import NotPeriodicError


@dataclass(frozen=True)
class SplitRHS:
    """``rhs`` in the states, ``table_i`` (functions of time) and ``const_i`` (functions of parameters)."""

    rhs: tuple[sp.Expr, ...]
    tables: tuple[tuple[sp.Symbol, sp.Expr], ...]
    constants: tuple[tuple[sp.Symbol, sp.Expr], ...]


def split_rhs(system: FirstOrderSystem, factored: bool = False) -> SplitRHS:
    """The split of ``system``'s right-hand side; ``factored``: a table entry's time-free factors become a
    constant of their own (see the module docstring)."""
    time = system.time
    states = set(system.states)
    tables: dict[sp.Expr, sp.Symbol] = {}
    constants: dict[sp.Expr, sp.Symbol] = {}

    def holds(symbols: set, memo: dict):
        """Whether an expression holds one of ``symbols``, each node asked once (its free symbols, gathered at
        every node of a large model's rows, were most of the time)."""
        def test(e: sp.Basic) -> bool:
            hit = memo.get(e)
            if hit is None:
                hit = memo[e] = e in symbols if e.is_Symbol else any(test(a) for a in e.args)
            return hit
        return test

    timed = holds({time}, {})
    stateful = holds(states, {})

    def entry(e: sp.Expr) -> sp.Expr:
        if e.is_Number:
            return e
        if factored and e.is_Mul and timed(e):
            fixed = [a for a in e.args if not timed(a)]
            if fixed:  # k(tau)/omega^2 as const * table: a table then depends on fewer parameters
                return entry(sp.Mul(*fixed)) * entry(sp.Mul(*(a for a in e.args if timed(a))))
        book, prefix = (tables, "table") if timed(e) else (constants, "const")
        if e not in book:  # a Dummy: never equal to a user's symbol of the same name
            book[e] = sp.Dummy(f"{prefix}_{len(book)}", real=True)
        return book[e]

    def state_free(e: sp.Expr) -> bool:
        return not stateful(e)

    def condition(c):
        """A Piecewise condition: state-free ones become a 0/1 table entry or constant compared with 1/2."""
        if c in (sp.true, sp.false):
            return c
        if state_free(c):
            return sp.StrictGreaterThan(entry(sp.Piecewise((1, c), (0, True))), sp.S.Half)
        if isinstance(c, sp.core.relational.Relational):
            return c.func(visit(c.lhs), visit(c.rhs))
        return c.func(*(condition(a) for a in c.args))  # And, Or, Not

    visited: dict[sp.Expr, sp.Expr] = {}

    def visit(e: sp.Expr) -> sp.Expr:  # (each node once: a node met again gives the same, and names nothing new)
        hit = visited.get(e)
        if hit is None:
            hit = visited[e] = split_node(e)
        return hit

    def split_node(e: sp.Expr) -> sp.Expr:
        if e in states:
            return e
        if state_free(e):
            return entry(e)
        if isinstance(e, sp.Piecewise):
            return sp.Piecewise(*((visit(value), condition(cond)) for value, cond in e.args))
        if e.is_Add or e.is_Mul:
            fixed = [a for a in e.args if state_free(a)]
            rest = [visit(a) for a in e.args if not state_free(a)]
            if fixed:
                rest.append(entry(e.func(*fixed)))
            return e.func(*rest)
        if e.is_Pow and e.exp.is_Integer:  # keep integer powers for the code generator
            return sp.Pow(visit(e.base), e.exp)
        return e.func(*(visit(a) for a in e.args))

    rhs = tuple(visit(f) for f in system.rhs)
    split = SplitRHS(rhs, tuple((s, e) for e, s in tables.items()), tuple((s, e) for e, s in constants.items()))
    _check_periodic(system, split)
    return split


def _check_periodic(system: FirstOrderSystem, split: SplitRHS) -> None:
    """The tables repeat every period only if time enters periodically: check at the defaults."""
    values = {k: float(v) for k, v in system.parameters.items()}

    def numeric(expr: sp.Expr) -> sp.Expr:
        return expr.subs({s: values[s.name] for s in expr.free_symbols if s.name in values})

    period = numeric(system.period)
    if not (period.is_number and float(period) > 0 and math.isfinite(float(period))):
        raise ModelError(f"the forcing period {system.period} must be a positive, finite function of parameters",
                         system.name)
    period = float(period)
    rng = random.Random(0)
    for _, expr in split.tables:
        f = sp.lambdify(system.time, numeric(expr), "math")
        for _ in range(4):
            t0 = rng.uniform(0, period)
            a, b = f(t0), f(t0 + period)
            if not abs(a - b) <= 1e-9 * (1 + abs(a)):
                raise NotPeriodicError(system.name, str(expr), str(system.period), str(system.time), t0, a, b)
