"""Small argument checks shared by the engine and the analyses."""
from __future__ import annotations

import math
import operator

import numpy as np

from .errors import GearsymError, suggest


def whole_number(value, what: str, minimum: int = 0) -> int:
    """``value`` as an int (any integer type: int, numpy.int64, ...) of at least ``minimum``, or a clear error."""
    try:
        count = operator.index(value)
    except TypeError:
        raise GearsymError(f"{what} must be a whole number, got {value!r}") from None
    if count < minimum:
        raise GearsymError(f"{what} must be at least {minimum}, got {count}")
    return count


def json_safe(x):
    """JSON-safe: numpy scalars to Python, NaN and infinities to None, tuples to lists."""
    if isinstance(x, dict):
        return {str(k): json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return [json_safe(v) for v in x.tolist()]
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer, int)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.str_):
        return str(x)
    return x


def chosen_coordinate(name: str | None, coordinates, plot) -> str | None:
    """``--coordinate name`` checked: it chooses what ``--plot`` draws, so it needs ``plot``, and it must be one of
    ``coordinates``. None stays None (the plot's default, the first coordinate)."""
    if name is None:
        return None
    if not plot:
        raise GearsymError(f"--coordinate {name} chooses what --plot draws; add --plot FILE.png")
    if name not in coordinates:
        raise GearsymError(f"--coordinate {name}: no such coordinate.{suggest(name, coordinates)} "
                           f"The coordinates are {', '.join(coordinates)}")
    return name
