"""Physical units: values with units in, the nondimensional model's values out, results carried back.

A stage between the reduction and the engine: :func:`scaling` makes a :class:`Scaling` from a reduced
drivetrain and its physical values (pint quantities); the engine stays nondimensional.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

__all__ = ["LENGTH_SCALES", "Scaling", "scaling"]


def __getattr__(name: str):
    """The scaling on first use: it loads pint's unit registry (most of a second), which the parsing of a
    quantity string (``physical.text``) and a model without units never need."""
    if name not in __all__:
        raise AttributeError(f"module 'gearsym.physical' has no attribute {name!r}")
    value = getattr(importlib.import_module("gearsym.physical.scales"), name)
    globals()[name] = value
    return value


if TYPE_CHECKING:
    from .scales import LENGTH_SCALES, Scaling, scaling
