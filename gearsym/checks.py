"""Small argument checks shared by the engine and the analyses."""
from __future__ import annotations

import operator

from .errors import GearsymError


def whole_number(value, what: str, minimum: int = 0) -> int:
    """``value`` as an int (any integer type: int, numpy.int64, ...) of at least ``minimum``, or a clear error."""
    try:
        count = operator.index(value)
    except TypeError:
        raise GearsymError(f"{what} must be a whole number, got {value!r}") from None
    if count < minimum:
        raise GearsymError(f"{what} must be at least {minimum}, got {count}")
    return count
