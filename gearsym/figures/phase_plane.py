"""Which two states a phase portrait draws: one rule for the point's figure (:mod:`.point`) and the attractors' and
portraits' (:mod:`.poincare`)."""
from __future__ import annotations

from collections.abc import Sequence


def phase_axes(names: Sequence[str], x: str | None = None, y: str | None = None) -> tuple[str, str]:
    """The phase plane: ``x`` (default the first state) against ``y`` (default the state after ``x``,
    its velocity in the gear models: x1 -> v1, x2 -> v2)."""
    names = list(names)
    x = x or names[0]
    if y is None and x in names:
        y = names[(names.index(x) + 1) % len(names)]
    return x, y or names[min(1, len(names) - 1)]
