"""Physical units: values with units in, the nondimensional model's values out, results carried back.

A stage between the reduction and the engine: :func:`scaling` makes a :class:`Scaling` from a reduced
drivetrain and its physical values (pint quantities); the engine stays nondimensional.
"""
from .scaling import LENGTH_SCALES, Scaling, scaling

__all__ = ["LENGTH_SCALES", "Scaling", "scaling"]
