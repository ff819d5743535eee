"""A system's parameters as a run checks them: names, values, the sign each must have.

Without SymPy: a compiled model taken from the cache (:mod:`gearsym.cached`) checks its values with
the same code as a :class:`~gearsym.system.FirstOrderSystem`.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields

from .records import record_class
from .checks import sign_violation
from .errors import GearsymError, ModelError, UnknownParameterError
from .options import Integration

#: the fields of gearsym.Integration, which a caller of the old keywords may pass as parameter values
_RUN_OPTIONS = tuple(f.name for f in fields(Integration))


@record_class
class Constraint:
    """What a parameter is physically, and so which values it may take: its sign; for a fraction of stiffness
    lost, ``below`` 1 (exclusive: at 1 the tooth pair carries nothing, beyond it pulls); for a tooth, a whole
    number from ``whole[0]`` to ``whole[1]``."""

    meaning: str  # "an inertia", "a damping ratio", ...
    zero_allowed: bool = True
    below: float | None = None
    whole: tuple[int, int] | None = None

    def violation(self, number: float) -> str | None:
        """What is wrong with ``number`` as this parameter's value ('must be positive', ...), or None."""
        if self.whole is not None:
            first, last = self.whole
            if not (number == math.floor(number) and first <= number <= last):
                return f"must be a whole number from {first} to {last}"
            return None
        if self.below is not None and not (0 <= number < self.below if self.zero_allowed else 0 < number < self.below):
            return f"must be at least 0 and less than {self.below:g}" if self.zero_allowed else \
                f"must be more than 0 and less than {self.below:g}"
        return sign_violation(number, self.zero_allowed)

    def as_list(self) -> list:
        """As JSON holds it (the start-up cache): [meaning, zero allowed, below, whole]."""
        return [self.meaning, self.zero_allowed, self.below, list(self.whole) if self.whole else None]

    @classmethod
    def from_list(cls, items) -> "Constraint":
        meaning, zero, below, whole = (list(items) + [None, None])[:4]
        return cls(str(meaning), bool(zero), None if below is None else float(below),
                   None if whole is None else (int(whole[0]), int(whole[1])))


class ParameterChecks:
    """``parameter_values`` and ``check_value`` for a class with ``name``, ``parameters`` (name -> value) and
    ``constraints`` (name -> :class:`Constraint`)."""

    name: str
    parameters: Mapping[str, float]
    constraints: Mapping[str, Constraint]

    def parameter_values(self, values: Mapping[str, float] | None = None) -> dict[str, float]:
        """Every parameter's value: the system's own, with ``values`` overriding (names, signs and
        finiteness checked)."""
        merged = dict(self.parameters)
        for name, value in (values or {}).items():
            if name not in merged:
                if name in _RUN_OPTIONS:
                    raise GearsymError(f"{name} is how to integrate, not a parameter of {self.name}: pass "
                                       f"options=gearsym.Integration({name}=...)")
                if isinstance(value, str):
                    raise GearsymError(
                        f"{self.name}: {name}={value!r} would change the model's equations; a system only takes "
                        f"parameter values: load the model with it (gearsym.load(model, {name}=...))")
                raise UnknownParameterError(name, merged, self.name)
            merged[name] = self.check_value(name, value)
        bad = [n for n, v in merged.items() if not math.isfinite(v)]
        if bad:
            raise GearsymError(f"{self.name}: parameter values must be finite numbers: "
                               + ", ".join(f"{n}={merged[n]}" for n in bad))
        return merged

    def check_value(self, name: str, value) -> float:
        """``value`` as a float, if it is a finite number with the sign parameter ``name`` must have."""
        if isinstance(value, str):
            raise GearsymError(f"{self.name}: {name}={value!r} is not a number; a formula changes the equations: "
                               f"give it when loading the model (gearsym.load(model, {name}=...))")
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise GearsymError(f"{self.name}: {name} must be a number, got {value!r}") from None
        constraint = self.constraints.get(name)
        must = constraint.violation(number) if constraint else None
        if must:
            raise ModelError(f"is {constraint.meaning} and {must}, got {number:g}", f"parameter {name!r}")
        return number
