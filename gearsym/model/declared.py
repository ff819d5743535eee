"""What a model file declares: the common base of a drivetrain and a plain first-order system.

The registry finds model files and checks what they define against this class alone, so finding and
loading a model by name needs neither SymPy nor the declaration stage's modules.
"""
from __future__ import annotations


class Model:
    """A declared model (:class:`~gearsym.model.drivetrain.Drivetrain` or
    :class:`~gearsym.system.FirstOrderSystem`): it has a ``name`` and a ``title``."""

    __slots__ = ()

    name: str
    title: str

    @property
    def is_drivetrain(self) -> bool:
        """True for a drivetrain (components, a Lagrangian, units); False for a plain first-order system."""
        return False
