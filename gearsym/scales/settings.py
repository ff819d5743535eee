"""Telling physical values from nondimensional ones in what a caller passes (``--set``, keywords)."""
from __future__ import annotations

from collections.abc import Mapping

from ..errors import GearsymError
from ..units import is_quantity


def maybe_number(value):
    """A string that reads as a number is that number (``--set omega=1.5``); others are kept, stripped."""
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value.strip()
    return value


def physical_settings(nd, values: Mapping[str, object]):
    """For a reduced drivetrain ``nd`` with physical values (declared, or given in ``values``: a quantity, a
    pint Quantity or a length scale): (length scale or None, physical values, stiffness formulas); else None."""
    given = "length_scale" in values or any(is_quantity(v) for v in values.values())
    if not (given or nd.drivetrain.physical):
        return None
    functions = {f.name for f in nd.functions}
    values = {k: maybe_number(v) for k, v in values.items()}
    length_scale = values.pop("length_scale", None)
    return (length_scale, {k: v for k, v in values.items() if k not in functions},
            {k: v for k, v in values.items() if k in functions})


def require_drivetrain(model) -> None:
    """Physical values need components to give them units."""
    if not getattr(model, "is_drivetrain", False) and not hasattr(model, "functions"):
        raise GearsymError(f"{model.name}: physical values need a drivetrain model (a FirstOrderSystem has no "
                           "components to give them units)")
