"""What a column measures: a state, a derivative of one (``x_dot``, ``x_ddot``) or a declared combination, as an
expression of the model's states and derivative placeholders, and that expression as h(tau, y, p) of the system."""
from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache

import sympy as sp

from ..errors import GearsymError, suggest
from ..model.expressions import to_expr
from ..system import FirstOrderSystem
from .columns import PHYSICAL_TIME, RECORD

#: the suffixes of a state's time derivatives as channel names, and their order
DERIVATIVES = {"_dot": 1, "_ddot": 2}
CHANNELS_HELP = ("a state (x), its time derivative (x_dot) or second derivative (x_ddot, an accelerometer), a body "
                 "centre's acceleration on its bearing (a_pinion_y, a_sun_x, a_planet1_radial), or a combination "
                 "declared with channels={name: formula} (--channel NAME=FORMULA)")
#: the prefix of a body centre's acceleration as a channel name (a drivetrain on bearings)
ACCELERATION = "a_"


def channel_symbols(system: FirstOrderSystem) -> dict[str, sp.Symbol]:
    """The names a channel may use: every state, and the placeholder of each state's derivatives
    (``x_dot``, ``x_ddot``: dx/dtau, d2x/dtau2), which :func:`channel_expression` resolves."""
    out = {s.name: s for s in system.states}
    for s in system.states:
        out.update({s.name + suffix: sp.Symbol(s.name + suffix, real=True) for suffix in DERIVATIVES})
    for name, expr in getattr(system, "translations", {}).items():  # (linear in the positions: their x_ddot)
        out[ACCELERATION + name] = expr.xreplace({s: out[s.name + "_ddot"] for s in system.states})
    return out


def channel_expression(channel: sp.Expr, system: FirstOrderSystem) -> sp.Expr:
    """What ``channel`` (states and derivative placeholders) is as h(tau, y, p) of ``system``:
    x_dot = f_x, x_ddot = df_x/dtau along the flow (= f_v for x' = v)."""
    return _channel_expression(channel, system.time, system.states, system.rhs)


@lru_cache(maxsize=256)
def _channel_expression(channel: sp.Expr, time: sp.Symbol, states: tuple, rhs: tuple) -> sp.Expr:
    rates = dict(zip(states, rhs))

    def derivative(expr: sp.Expr, order: int) -> sp.Expr:
        for _ in range(order):
            expr = sp.diff(expr, time) + sum(sp.diff(expr, s) * rates[s] for s in states)
        return expr

    by_name = {s.name: s for s in states}
    used = {s.name for s in channel.free_symbols}
    for s in states:
        for suffix, order in DERIVATIVES.items():
            if s.name + suffix in used:
                by_name[s.name + suffix] = derivative(s, order)
    return channel.xreplace({s: by_name[s.name] for s in channel.free_symbols if s.name in by_name})


def declared_channels(system: FirstOrderSystem, channels: Mapping[str, str]) -> dict[str, sp.Expr]:
    """Each declared combination as an expression of states and derivative placeholders (tau units)."""
    names = channel_symbols(system)
    out = {}
    for name, formula in channels.items():
        where = f"channel {name}"
        if not str(name).isidentifier():
            raise GearsymError(f"{where}: a channel name must be a column name like acc or a1 (letters, digits, _)")
        if name in names or name in system.parameters or name in (RECORD, PHYSICAL_TIME, system.time.name):
            raise GearsymError(f"{where}: the name is already a state, derivative, parameter or time column; "
                               "name the combination otherwise")
        expr = to_expr(formula, where, {**names, system.time.name: system.time})
        unknown = sorted(s.name for s in expr.free_symbols
                         if s not in names.values() and s != system.time and s.name not in system.parameters)
        if unknown:
            known = ", ".join(names)
            raise GearsymError(f"{where}: unknown name {unknown[0]}.{suggest(unknown[0], list(names))} A channel "
                               f"combines {known}, the time {system.time.name} and the parameters")
        out[name] = expr
    return out


def in_file_units(expr: sp.Expr, system: FirstOrderSystem, scale: float) -> sp.Expr:
    """A channel of a file whose time is t (tau = scale t): derivatives per unit t, d^k/dt^k = scale^k d^k/dtau^k."""
    if scale == 1.0:
        return expr
    mapping = {}
    for s in system.states:
        for suffix, order in DERIVATIVES.items():
            mapping[sp.Symbol(s.name + suffix, real=True)] = sp.Float(scale) ** order * sp.Symbol(s.name + suffix,
                                                                                                     real=True)
    return expr.xreplace(mapping)

