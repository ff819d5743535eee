"""The grammar of a quantity string, checked before any of it reaches pint (and without importing pint).

``NUMBER [UNIT]``: a decimal number, then a unit expression that starts with a unit name (or a
parenthesis) and is made of unit names, ``*``, ``/``, whole powers (``**2``, ``^-1``), parentheses
and spaces: ``2e8 N/m``, ``3000rpm``, ``2.1e-3 kg*m^2``. ``2*k_a`` or ``0.5*cos(tau)`` are formulas,
not quantities (the unit would start with ``*``).
"""
from __future__ import annotations

import re

#: how long a quantity string may be (a unit expression is a few names, not a program)
MAX_LENGTH = 120
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_NAME = r"[A-Za-zµμΩ°][A-Za-z0-9µμΩ_]*"
_POWER = r"(?:\*\*|\^)\s*-?\d{1,2}"
_UNIT = rf"(?:{_NAME}|\()(?:{_NAME}|\(|\)|{_POWER}|\*|/|\s)*"
QUANTITY = re.compile(rf"\s*(?P<number>{_NUMBER})\s*(?P<unit>{_UNIT})?\s*")
#: a power of a power (m**10**10): no unit needs one, and pint would compute it
POWER_OF_POWER = re.compile(rf"{_POWER}\s*(?:\*\*|\^)")
GRAMMAR = ("a quantity is a number and a unit made of unit names, * / ** ^ (whole powers) and parentheses, "
           "e.g. '2e8 N/m', '3000 rpm', '2.1e-3 kg*m^2', '50 um'")


def looks_like_quantity(text: str) -> bool:
    """True if ``text`` is a number followed by a unit (``--set kZ='2e8 N/m'`` is a quantity, not a formula)."""
    match = QUANTITY.fullmatch(text) if len(text) <= MAX_LENGTH else None
    return bool(match and (match["unit"] or "").strip())


def shown(q, digits: int = 6) -> str:
    """A quantity as a person reads it: '2e+08 N / m', '3000 rpm' (short unit symbols; a pint Quantity or a
    :class:`~gearsym.physical.point.Measured`)."""
    unit_text = f"{q.units:~P}" if not q.dimensionless or str(q.units) != "dimensionless" else ""
    return f"{q.magnitude:.{digits}g} {unit_text}".strip()
