"""Physical quantities: one pint registry, and reading a quantity from text without running it.

A quantity string is ``NUMBER [UNIT EXPRESSION]`` (``2e8 N/m``, ``3000 rpm``, ``2.1e-3 kg*m^2``,
``50 um``). The text is checked against that grammar here, with a regular expression, before any of
it reaches pint: the number is read by ``float`` and only the unit expression goes to pint's
``parse_units``, which has its own tokenizer and evaluator (``pint.pint_eval``) and never calls
Python's ``eval``. No quantity string ever reaches SymPy.

Frequencies: pint's ``Hz`` is ``1/s``, so ``3000 rpm`` would convert to 314 Hz (radians per second
under another name). Here ``Hz`` is one revolution (cycle) per second, so rpm, Hz and rad/s convert
as a drivetrain engineer expects: 3000 rpm = 50 Hz = 314.16 rad/s.
"""
from __future__ import annotations

import math
import warnings
from functools import lru_cache

import pint

from ..errors import GearsymError
from .text import GRAMMAR, MAX_LENGTH, POWER_OF_POWER, QUANTITY, shown  # noqa: F401 (shown: here too)

ureg = pint.UnitRegistry(on_redefinition="ignore")
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    ureg.define("hertz = revolution / second = Hz")
Quantity = ureg.Quantity



def parse_quantity(text: str, where: str) -> pint.Quantity:
    """The quantity ``text`` stands for, or a one-line error naming ``where``."""
    shown = repr(text if len(text) <= 60 else text[:57] + "...")
    if len(text) > MAX_LENGTH:
        raise GearsymError(f"{where}: {shown} is longer than the {MAX_LENGTH} characters a quantity may have; {GRAMMAR}")
    match = QUANTITY.fullmatch(text)
    if not match:
        raise GearsymError(f"{where}: {shown} is not a quantity; {GRAMMAR}")
    number = float(match["number"])
    if not math.isfinite(number):
        raise GearsymError(f"{where}: {shown} is not a finite number")
    unit_text = (match["unit"] or "").strip()
    if POWER_OF_POWER.search(unit_text):
        raise GearsymError(f"{where}: {shown} raises a power to a power; {GRAMMAR}")
    if unit_text.count("(") != unit_text.count(")"):
        raise GearsymError(f"{where}: {shown} has unbalanced parentheses; {GRAMMAR}")
    return Quantity(number, unit(unit_text, where, shown)) if unit_text else Quantity(number)


@lru_cache(maxsize=256)
def _units(text: str):
    return ureg.parse_units(text)


def unit(text: str, where: str, shown: str | None = None):
    """The pint unit of a unit expression (already checked against the grammar by the caller)."""
    try:
        return _units(text)
    except pint.UndefinedUnitError as exc:
        names = exc.unit_names if isinstance(exc.unit_names, (tuple, list)) else (exc.unit_names,)
        raise GearsymError(f"{where}: unknown unit {', '.join(map(repr, names))} in {shown or repr(text)}; "
                           "units are pint's (N, m, mm, um, kg, s, rpm, Hz, rad, ...)") from None
    except Exception as exc:  # pint's own syntax errors: a unit expression it cannot read
        raise GearsymError(f"{where}: cannot read the unit of {shown or repr(text)} ({exc}); {GRAMMAR}") from None


def as_quantity(value, where: str) -> pint.Quantity:
    """A quantity of this registry from a string, a number (dimensionless) or a pint Quantity (of any registry)."""
    if isinstance(value, bool):
        raise GearsymError(f"{where}: expected a quantity such as '2e8 N/m', got {value!r}")
    if isinstance(value, str):
        return parse_quantity(value, where)
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise GearsymError(f"{where}: {value!r} is not a finite number")
        return Quantity(float(value))
    if isinstance(value, pint.Quantity):
        magnitude = value.magnitude
        if not isinstance(magnitude, (int, float)) or not math.isfinite(magnitude):
            raise GearsymError(f"{where}: expected one finite number with a unit, got {value!r}")
        return value if value._REGISTRY is ureg else Quantity(float(magnitude), str(value.units))
    raise GearsymError(f"{where}: expected a quantity such as '2e8 N/m' (a string or a pint Quantity), "
                       f"got {type(value).__name__}")


def dimension_text(dimensionality) -> str:
    """'[mass] / [time] ** 2' or 'dimensionless'."""
    text = str(dimensionality)
    return text if text else "dimensionless"
