"""The error of a right-hand side whose time dependence does not repeat with the declared period.

The engine samples one period of the tables of time and repeats it; the code generator checks the tables
at the defaults, a compiled model at every other parameter vector. Both say the same thing, from names and
texts alone (the compiled model keeps its tables' texts, not SymPy).
"""
from __future__ import annotations

from ..errors import ModelError


class NotPeriodicError(ModelError):
    def __init__(self, model: str, expr: str, period: str, time: str, t0: float, a: float, b: float,
                 where: str = "at the defaults"):
        super().__init__(
            f"time enters the right-hand side through {expr}, which is not periodic with the declared period "
            f"{period} {where} ({a:.6g} at {time}={t0:.4g}, {b:.6g} one period later). The engine "
            "samples one period and repeats it: declare the true forcing period, and keep time out of functions "
            "of the state (write sin(x - t) as sin(x)cos(t) - cos(x)sin(t)).",
            model,
        )
