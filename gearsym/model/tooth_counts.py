"""The tooth counts a user gives a model that declares none (``--teeth Z1,Z2``, ``teeth=(Z1, Z2)``), read once
where they enter into a :class:`ToothCounts`, without SymPy: the command line checks them before any work starts."""
from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from ..errors import GearsymError


class ToothCounts(NamedTuple):
    """The tooth counts of the first mesh's pinion (its driving gear) and wheel."""

    pinion: int
    wheel: int

    @classmethod
    def of(cls, value) -> "ToothCounts | None":
        """``"20,53"``, ``(20, 53)``, a ToothCounts or None -> ToothCounts(20, 53) or None, with a one-line error
        for anything else."""
        if value is None or isinstance(value, cls):
            return value
        counts: list = []
        if isinstance(value, str):
            try:
                counts = [int(p.strip()) for p in value.split(",")]
            except ValueError:
                counts = []
        elif isinstance(value, Sequence) and all(isinstance(v, int) and not isinstance(v, bool) for v in value):
            counts = list(value)
        if len(counts) != 2 or min(counts) < 3:
            raise GearsymError(f"--teeth {value!r}: give the tooth counts of the first mesh's pinion and wheel, two "
                               "whole numbers of at least 3, e.g. --teeth 20,53 (teeth=(20, 53) in Python)")
        return cls(counts[0], counts[1])
