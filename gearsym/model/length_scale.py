"""The length unit a model with physical values is computed in: what may be declared, checked where it is."""
from __future__ import annotations

from ..errors import GearsymError
from ..units import Measure, measure

#: the length units named by a rule: the first mesh's static deflection, or half its backlash
LENGTH_SCALES = ("static", "backlash")


def check_length_scale(scale, where: str) -> str | Measure:
    """``"static"``, ``"backlash"`` or a positive length (a :class:`~gearsym.units.Measure` in m)."""
    if isinstance(scale, str) and scale.strip() in LENGTH_SCALES:
        return scale.strip()
    try:
        value = measure(scale, where)
    except GearsymError:
        value = None
    if value is None or value.dims != (0.0, 1.0, 0.0) or not value.si > 0:
        raise GearsymError(f"{where}: the length scale is 'static' (the static deflection), 'backlash' (half "
                           f"the backlash) or a positive length such as '1 um', got {scale!r}")
    return value
